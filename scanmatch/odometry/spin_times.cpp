#include "scanmatch/odometry/spin_times.hpp"

#include <cmath>
#include <limits>

namespace scanmatch {

void assign_azimuth_times(PointCloud& cloud, const SpinTiming& timing) {
  cloud.time.clear();
  if (!(timing.period > 0.0) || !std::isfinite(timing.period)) return;
  const double turn = 2.0 * M_PI;
  const double direction = timing.clockwise ? -1.0 : 1.0;
  cloud.time.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Point& p = cloud.points[i];
    if (!p.allFinite() || (p.x() == 0.0f && p.y() == 0.0f)) {
      cloud.time[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    // The angle swept from the start to this azimuth, in [0, 2 pi).
    const double swept =
        direction *
        (std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x())) - timing.start_azimuth);
    double fraction = swept / turn;
    fraction -= std::floor(fraction);
    if (fraction >= 1.0) fraction = 0.0;  // rounding of a tiny negative angle
    cloud.time[i] = static_cast<float>(fraction * timing.period);
  }
}

}  // namespace scanmatch
