#include "scanmatch/sim/sensor.hpp"

#include <algorithm>
#include <cmath>

#include "scanmatch/core/error.hpp"

namespace scanmatch::sim {
namespace {
constexpr double kDeg = M_PI / 180.0;

std::vector<SensorModel> make_models() {
  std::vector<SensorModel> m;
  SensorModel mid360;
  mid360.name = "mid360";
  mid360.pattern = ScanPattern::kLivoxMid360;
  mid360.rays_per_frame = 20000;
  mid360.elevation_min_deg = -7;
  mid360.elevation_max_deg = 52;
  mid360.min_range = 0.1;
  mid360.max_range = 40;
  mid360.high_reflectivity_max_range = 70;
  mid360.rings = 4;  // laser channels
  m.push_back(mid360);

  SensorModel avia;
  avia.name = "avia";
  avia.pattern = ScanPattern::kLivoxRosette;
  avia.rays_per_frame = 24000;
  avia.horizontal_fov_deg = 70.4;
  avia.elevation_min_deg = -77.2 / 2;
  avia.elevation_max_deg = 77.2 / 2;
  avia.min_range = 0.5;
  avia.max_range = 190;
  avia.rings = 6;
  m.push_back(avia);

  const auto spinning = [](std::string name, int rings, std::size_t azimuth_steps, double lo,
                           double hi, double max_range, double noise) {
    SensorModel s;
    s.name = std::move(name);
    s.rings = rings;
    s.rays_per_frame = static_cast<std::size_t>(rings) * azimuth_steps;
    s.elevation_min_deg = lo;
    s.elevation_max_deg = hi;
    s.min_range = 0.5;
    s.max_range = max_range;
    s.range_noise = noise;
    return s;
  };
  m.push_back(spinning("vlp16", 16, 1800, -15, 15, 100, 0.03));
  m.push_back(spinning("hdl64", 64, 1875, -24.9, 2.0, 120, 0.02));
  m.push_back(spinning("os1-64", 64, 1024, -16.6, 16.6, 120, 0.03));

  SensorModel neato;
  neato.name = "neato";
  neato.pattern = ScanPattern::kPlanar;
  neato.rate_hz = 5;
  neato.rays_per_frame = 360;
  neato.min_range = 0.15;
  neato.max_range = 4.0;
  neato.range_noise = 0.0;
  neato.range_noise_fraction = 0.01;
  neato.dropout = 0.01;
  m.push_back(neato);

  // A SICK LMS as in the Radish 2D logs (ACES, Intel): 180 deg at 1 deg, logged about once a
  // second, so consecutive scans are about a metre apart.
  SensorModel sick;
  sick.name = "sick-lms";
  sick.pattern = ScanPattern::kPlanar;
  sick.rate_hz = 1;
  sick.mirror_period = 1.0 / 75.0;
  sick.horizontal_fov_deg = 180;
  sick.rays_per_frame = 181;
  sick.min_range = 0.1;
  sick.max_range = 50.0;
  sick.range_noise = 0.015;
  sick.dropout = 0.005;
  m.push_back(sick);
  return m;
}

const std::vector<SensorModel>& models() {
  static const std::vector<SensorModel> kModels = make_models();
  return kModels;
}

// Triangle wave in [-1, 1]: uniform dwell over its range, unlike a sine.
double triangle(double phase) {
  return 4.0 * std::abs(phase - std::floor(phase + 0.5)) - 1.0;
}

Eigen::Vector3f direction(double azimuth, double elevation) {
  return Eigen::Vector3f(static_cast<float>(std::cos(elevation) * std::cos(azimuth)),
                         static_cast<float>(std::cos(elevation) * std::sin(azimuth)),
                         static_cast<float>(std::sin(elevation)));
}
}  // namespace

double SensorModel::planar_angle_min() const {
  return is_full_turn() ? 0.0 : -0.5 * horizontal_fov_deg * kDeg;
}

double SensorModel::planar_angle_increment() const {
  const double n = static_cast<double>(rays_per_frame);
  return is_full_turn() ? 2 * M_PI / n : horizontal_fov_deg * kDeg / std::max(1.0, n - 1);
}

const SensorModel& sensor_model(const std::string& name) {
  for (const auto& m : models())
    if (m.name == name) return m;
  std::string valid;
  for (const auto& n : sensor_names()) valid += (valid.empty() ? "" : ", ") + n;
  throw Error("unknown sensor '" + name + "' (valid: " + valid + ")");
}

std::vector<std::string> sensor_names() {
  std::vector<std::string> names;
  for (const auto& m : models()) names.push_back(m.name);
  return names;
}

void generate_pattern(const SensorModel& s, std::uint64_t frame_index, RayPattern& p) {
  const std::size_t n = s.rays_per_frame;
  p.directions.resize(n);
  p.times.resize(n);
  p.rings.resize(n);
  const double period = s.frame_period();
  switch (s.pattern) {
    case ScanPattern::kSpinning: {
      const std::size_t steps = n / static_cast<std::size_t>(s.rings);
      const double elevation_step = (s.elevation_max_deg - s.elevation_min_deg) / (s.rings - 1);
      for (std::size_t a = 0; a < steps; ++a) {
        const double azimuth = 2 * M_PI * static_cast<double>(a) / static_cast<double>(steps);
        const float t =
            static_cast<float>(period * static_cast<double>(a) / static_cast<double>(steps));
        for (int r = 0; r < s.rings; ++r) {
          const std::size_t i = a * static_cast<std::size_t>(s.rings) + static_cast<std::size_t>(r);
          p.directions[i] = direction(azimuth, (s.elevation_min_deg + r * elevation_step) * kDeg);
          p.times[i] = t;
          p.rings[i] = static_cast<std::uint16_t>(r);
        }
      }
      break;
    }
    case ScanPattern::kLivoxMid360: {
      // Four lasers sweep the azimuth ten times a second while their elevation zig-zags at a
      // frequency incommensurate with the frame rate: each frame lands between the last ones.
      constexpr double kZigZagHz = 1234.5678;
      const double rate = static_cast<double>(n) / period;
      const double sin_lo = std::sin(s.elevation_min_deg * kDeg),
                   sin_hi = std::sin(s.elevation_max_deg * kDeg);
      for (std::size_t k = 0; k < n; ++k) {
        const double t_global = static_cast<double>(frame_index * n + k) / rate;
        const int laser = static_cast<int>(k % 4);
        const double azimuth = 2 * M_PI * (s.rate_hz * t_global + 0.25 * laser);
        // sin(elevation) uniform over the band keeps the density uniform on the sphere.
        const double u = 0.5 * (1.0 + triangle(kZigZagHz * t_global + 0.25 * laser));
        const double elevation = std::asin(sin_lo + u * (sin_hi - sin_lo));
        p.directions[k] = direction(azimuth, elevation);
        p.times[k] = static_cast<float>(period * static_cast<double>(k) / static_cast<double>(n));
        p.rings[k] = static_cast<std::uint16_t>(laser);
      }
      break;
    }
    case ScanPattern::kLivoxRosette: {
      // Two Risley prisms turning in opposite directions at incommensurate rates draw a rosette.
      constexpr double kPrism1Hz = 121.7, kPrism2Hz = -87.31;
      const double rate = static_cast<double>(n) / period;
      const double half_h = 0.5 * s.horizontal_fov_deg * kDeg;
      const double half_v = 0.5 * (s.elevation_max_deg - s.elevation_min_deg) * kDeg;
      for (std::size_t k = 0; k < n; ++k) {
        const double t_global = static_cast<double>(frame_index * n + k) / rate;
        const int laser = static_cast<int>(k % 6);
        const double phase = 2 * M_PI * laser / 6.0;
        const double a1 = 2 * M_PI * kPrism1Hz * t_global + phase,
                     a2 = 2 * M_PI * kPrism2Hz * t_global;
        const double x = 0.5 * (std::cos(a1) + std::cos(a2)),
                     y = 0.5 * (std::sin(a1) + std::sin(a2));
        const double azimuth = x * half_h, elevation = y * half_v;
        p.directions[k] =
            Eigen::Vector3f(1.0f, static_cast<float>(std::tan(azimuth)),
                            static_cast<float>(std::tan(elevation) / std::cos(azimuth)))
                .normalized();
        p.times[k] = static_cast<float>(period * static_cast<double>(k) / static_cast<double>(n));
        p.rings[k] = static_cast<std::uint16_t>(laser);
      }
      break;
    }
    case ScanPattern::kPlanar: {
      if (!s.is_full_turn()) {
        // The mirror sweeps the field of view in a fraction of its turn.
        const double first = s.planar_angle_min(), step = s.planar_angle_increment();
        for (std::size_t k = 0; k < n; ++k) {
          const double offset = step * static_cast<double>(k);
          p.directions[k] = direction(first + offset, 0.0);
          p.times[k] = static_cast<float>(s.rotation_period() * offset / (2 * M_PI));
          p.rings[k] = 0;
        }
        break;
      }
      for (std::size_t k = 0; k < n; ++k) {
        const double angle = 2 * M_PI * static_cast<double>(k) / static_cast<double>(n);
        p.directions[k] = direction(angle, 0.0);
        p.times[k] = static_cast<float>(period * static_cast<double>(k) / static_cast<double>(n));
        p.rings[k] = 0;
      }
      break;
    }
  }
}

}  // namespace scanmatch::sim
