#include <fmt/format.h>

#include <functional>

#include "scanmatch/benchmark/benchmark.hpp"

namespace scanmatch {
namespace {

std::string percent(double v) {
  return fmt::format("{:.3f}", v);
}

// Frames a method could not register and bridged with the motion prior: its accuracy figure
// then says little (a still sensor "stays" where every frame is bridged).
std::string bridged_note(const BenchmarkCell& c) {
  return c.run.bridged_frames > 0 ? fmt::format(" ({} bridged)", c.run.bridged_frames) : "";
}

}  // namespace

std::vector<ResultTable> benchmark_tables(const std::vector<BenchmarkSequence>& results,
                                          const std::vector<BenchmarkVariant>& vs,
                                          const std::vector<std::string>& methods) {
  const auto cell_text = [](const BenchmarkCell* c,
                            const std::function<std::string(const BenchmarkCell&)>& f) {
    if (!c) return std::string("");
    return c->ok ? f(*c) : std::string(c->not_built ? "not built" : "failed");
  };
  const auto find = [](const BenchmarkSequence& r, const std::string& v) -> const BenchmarkCell* {
    const auto it = r.cells.find(v);
    return it == r.cells.end() ? nullptr : &it->second;
  };
  std::vector<ResultTable> tables;
  std::vector<std::string> header = {"sequence"};
  header.insert(header.end(), methods.begin(), methods.end());

  ResultTable ate{"ATE RMSE, % of path length (CTF-ICP Table 2)",
                  "No alignment: both trajectories start at the identity.",
                  header,
                  {}};
  ResultTable fps{"Frames per second, single thread (CTF-ICP Table 4)",
                  "Pipeline time only (reading or simulating frames excluded).",
                  header,
                  {}};
  ResultTable kitti{"KITTI drift: translation % / rotation deg per 100 m",
                    "Devkit definition: segments of 100 to 800 m that the path allows.",
                    header,
                    {}};
  ResultTable still{"Still sensor: final / maximum drift (m)", "", header, {}};
  for (const auto& r : results) {
    std::vector<std::string> a{r.name}, f{r.name}, k{r.name}, s{r.name};
    for (const auto& m : methods) {
      const BenchmarkCell* c = find(r, m);
      a.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return percent(x.ate.rmse_percent_of_path) + bridged_note(x);
      }));
      f.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return fmt::format("{:.1f}", x.run.frames_per_second);
      }));
      k.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return x.kitti.segments > 0 ? fmt::format("{:.2f} / {:.2f}", x.kitti.translation_percent,
                                                  x.kitti.rotation_deg_per_100m)
                                    : std::string("-");
      }));
      s.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return fmt::format("{:.4f} / {:.4f}", x.ate.final_drift, x.ate.max) + bridged_note(x);
      }));
    }
    (r.still ? still.rows : ate.rows).push_back(r.still ? s : a);
    fps.rows.push_back(f);
    if (!r.still) kitti.rows.push_back(k);
  }
  if (!ate.rows.empty()) tables.push_back(ate);
  if (!still.rows.empty()) tables.push_back(still);
  tables.push_back(fps);

  ResultTable stages{"CTF-ICP mean ms per stage (CTF-ICP Table 3)",
                     "",
                     {"sequence", "preprocess", "coarse", "fine", "map update", "total",
                      "max total", "points after downsampling"},
                     {}};
  for (const auto& r : results) {
    const BenchmarkCell* c = find(r, "ctf-icp");
    if (!c || !c->ok) continue;
    double points = 0;
    for (const auto& s : c->run.stats)
      points +=
          static_cast<double>(s.points_downsampled) / static_cast<double>(c->run.stats.size());
    stages.rows.push_back({r.name, fmt::format("{:.2f}", c->run.stage("preprocess").mean_ms),
                           fmt::format("{:.2f}", c->run.stage("coarse").mean_ms),
                           fmt::format("{:.2f}", c->run.stage("fine").mean_ms),
                           fmt::format("{:.2f}", c->run.stage("map_update").mean_ms),
                           fmt::format("{:.2f}", c->run.stage("total").mean_ms),
                           fmt::format("{:.1f}", c->run.stage("total").max_ms),
                           fmt::format("{:.0f}", points)});
  }
  if (!stages.rows.empty()) tables.push_back(stages);

  bool ablation = false;
  for (const auto& v : vs) ablation = ablation || v.name == "ctf-icp --no-fine";
  if (ablation) {
    ResultTable t{"Ablation, ATE % of path (CTF-ICP Table 5)",
                  "--no-map-update: the fine stage registers to the previous frame only.",
                  {"sequence", "without fine stage", "without map building and update", "full"},
                  {}};
    for (const auto& r : results) {
      if (r.still) continue;
      const auto p = [](const BenchmarkCell& x) { return percent(x.ate.rmse_percent_of_path); };
      t.rows.push_back({r.name, cell_text(find(r, "ctf-icp --no-fine"), p),
                        cell_text(find(r, "ctf-icp --no-map-update"), p),
                        cell_text(find(r, "ctf-icp"), p)});
    }
    if (!t.rows.empty()) tables.push_back(t);
  }

  ResultTable loam{"Accuracy score (m^2) and ms per frame, mean / max (LOAM paper Tables 1, 2)",
                   "Accuracy score: mean squared nearest-neighbour distance between consecutive "
                   "frames after alignment (PCL's fitness score, pairs within 1 m), 30 frame "
                   "pairs per sequence; lower is better.",
                   {"sequence", "method", "accuracy score", "mean ms", "max ms"},
                   {}};
  for (const auto& r : results)
    for (const auto& m : methods) {
      const BenchmarkCell* c = find(r, m);
      if (!c) continue;
      loam.rows.push_back(
          {r.name, m,
           cell_text(
               c, [](const BenchmarkCell& x) { return fmt::format("{:.4f}", x.accuracy_score); }),
           cell_text(c,
                     [](const BenchmarkCell& x) {
                       return fmt::format("{:.1f}", x.run.stage("total").mean_ms);
                     }),
           cell_text(c, [](const BenchmarkCell& x) {
             return fmt::format("{:.1f}", x.run.stage("total").max_ms);
           })});
    }
  tables.push_back(loam);
  // The summary a reader wants first, one row a method: accuracy and speed next to each other.
  ResultTable side{"ATE and frames per second side by side",
                   "ATE RMSE in % of path length, no alignment; frames per second of the "
                   "pipeline alone.",
                   {"method"},
                   {}};
  for (const auto& r : results)
    if (!r.still) {
      side.header.push_back(r.name + " ATE %");
      side.header.push_back(r.name + " frames/s");
    }
  for (const auto& m : methods) {
    std::vector<std::string> row{m};
    for (const auto& r : results) {
      if (r.still) continue;
      const BenchmarkCell* c = find(r, m);
      row.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return percent(x.ate.rmse_percent_of_path) + bridged_note(x);
      }));
      row.push_back(cell_text(c, [](const BenchmarkCell& x) {
        return fmt::format("{:.1f}", x.run.frames_per_second);
      }));
    }
    side.rows.push_back(row);
  }
  if (side.header.size() > 1) tables.push_back(side);
  bool any_kitti = false;
  for (const auto& row : kitti.rows)
    for (std::size_t i = 1; i < row.size(); ++i)
      any_kitti = any_kitti || (row[i] != "-" && row[i] != "not built");
  if (any_kitti) tables.push_back(kitti);
  return tables;
}

}  // namespace scanmatch
