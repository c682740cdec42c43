#pragma once
// Summary statistics of a list of values, shared by the metrics and the odometry's estimates.

#include <vector>

namespace scanmatch {

/// Median (the mean of the two middle values for an even count) and mean; 0 for no values.
double median_of(std::vector<double> values);
double mean_of(const std::vector<double>& values);

}  // namespace scanmatch
