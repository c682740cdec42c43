#pragma once
// Metrics as JSON objects, with the keys that `eval --json` and every run's summary.json share.

#include <nlohmann/json.hpp>

#include "scanmatch/eval/metrics.hpp"

namespace scanmatch {

/// poses, rmse_m, mean_m, median_m, max_m, final_drift_m, path_length_m, rmse_percent_of_path,
/// scale (of the alignment).
inline nlohmann::ordered_json ate_json(const AteResult& ate) {
  return {{"poses", ate.poses},
          {"rmse_m", ate.rmse},
          {"mean_m", ate.mean},
          {"median_m", ate.median},
          {"max_m", ate.max},
          {"final_drift_m", ate.final_drift},
          {"path_length_m", ate.path_length},
          {"rmse_percent_of_path", ate.rmse_percent_of_path},
          {"scale", ate.alignment.scale}};
}

}  // namespace scanmatch
