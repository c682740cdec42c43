#pragma once
// Counter-based random numbers: every value is a pure function of (seed, stream, index), so the
// simulator's output is identical whatever the thread count or order of evaluation, and on any
// machine (std::*_distribution differ between standard libraries, so they are not used).

#include <cmath>
#include <cstdint>

namespace scanmatch::sim {

inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline std::uint64_t hash_combine(std::uint64_t a, std::uint64_t b) {
  return mix64(a ^ mix64(b));
}

/// Uniform in [0, 1) from 53 random bits.
inline double to_unit(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

/// A small sequential generator for scene building (splitmix64 stream).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() { return mix64(state_++); }
  double uniform() { return to_unit(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal by Box-Muller (one value per call, deterministic).
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::uint64_t state_;
};

/// Per-ray randomness: a generator seeded from (seed, frame, ray), independent of evaluation order.
inline Rng ray_rng(std::uint64_t seed, std::uint64_t frame, std::uint64_t ray) {
  return Rng(hash_combine(hash_combine(seed, frame), ray));
}

}  // namespace scanmatch::sim
