#pragma once
// A spinning sensor's beam elevation bias, estimated from the run's first moving frame pairs
// (geometry/beam_elevation.hpp): riverside02_keyframes' OS1-64 reads about 0.2 deg high, and
// ctf-icp then pitches 0.07 deg a keyframe (docs/odometry.md, "Beam elevation, estimated"). The
// correction follows the pairs' median while that is clear, and settles after at most kMaxPairs
// pairs. Clear means well above the estimator's own error on exact simulated scans (campus-os1's
// OS1-64: -0.06 deg; dynamic-outdoor-fast seed 2's Mid-360: -0.14, from the shapes of the scene),
// so that data without a bias is left as delivered.

#include <cstddef>
#include <vector>

#include "scanmatch/geometry/beam_elevation.hpp"

namespace scanmatch {

class ElevationEstimate {
 public:
  /// Pairs counted: a correction needs at least kMinPairs, and settles by kMaxPairs at the latest
  /// (earlier once the median's standard error is below 0.02 deg).
  static constexpr std::size_t kMinPairs = 8, kMaxPairs = 60;
  /// m: a pair's frames are at least this far apart. The signal grows with the step: a car's
  /// frames 1 m apart at 10 Hz scatter +-1 deg a pair, 5 m apart +-0.2 (campus-os1).
  static constexpr double kMinStep = 3.0;

  /// Offers one pair's estimate; ignored once decided, or when the pair says little (a standard
  /// error beyond 0.5 deg: few planes, or a Livox keyframe's narrow view).
  void add(const ElevationBiasFromPair& pair);
  bool decided() const { return decided_; }
  /// rad, the bias to take out now: the pairs' median where it is at least 0.15 deg and four
  /// standard errors of that median (from the pairs' spread) from zero, else 0; fixed once decided.
  double correction() const { return correction_; }
  /// The pairs' median and its standard error so far (rad; 0 and infinity without pairs).
  double median() const;
  double median_error() const;
  std::size_t pairs() const { return biases_.size(); }

 private:
  std::vector<double> biases_;
  bool decided_ = false;
  double correction_ = 0.0;
};

}  // namespace scanmatch
