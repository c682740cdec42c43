#include "scanmatch/odometry/odometry_config.hpp"

#include <cmath>

#include "scanmatch/core/error.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {

bool is_odometry_method(const std::string& name) {
  return name == "ctf-icp" || is_registration_method(name);
}

std::string odometry_method_list() {
  return "ctf-icp, " + registration_method_list();
}

void check_odometry_config(const OdometryConfig& c) {
  if (!is_odometry_method(c.method))
    throw Error("unknown odometry method '" + c.method + "' (valid: " + odometry_method_list() +
                ")");
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw Error(std::string("odometry: ") + name + " must be positive");
  };
  positive(c.ndt_resolution, "ndt_resolution");
  positive(c.max_jump, "max_jump");
  positive(c.max_jump_angle, "max_jump_angle");
  positive(c.map_voxel_size, "map_voxel_size");
  positive(c.map_radius, "map_radius");
  positive(c.max_range, "max_range");
  positive(c.coarse_tolerance, "coarse_tolerance");
  if (c.voxel_size < 0.0 || c.coarse_voxel_size < 0.0 || c.min_range < 0.0)
    throw Error("odometry: voxel sizes and min_range must not be negative");
  if (!(c.start_voxel_size >= 0.0))
    throw Error("odometry: start_voxel_size must be a number, 0 or more (0: not thinned)");
  if (c.merge_threshold == 0) throw Error("odometry: merge_threshold must be at least 1");
  if (c.threads < 1) throw Error("odometry: threads must be at least 1");
  if (!(c.max_step_ratio >= 1.0)) throw Error("odometry: max_step_ratio must be at least 1");
  if (!(c.uncertain_rotation > 0.0) || !(c.rotation_start_step > 0.0) ||
      !(c.rotation_start_step < M_PI) || c.rotation_starts < 0 || c.rotation_starts > 18)
    throw Error(
        "odometry: uncertain_rotation and rotation_start_step must be positive (the step below "
        "pi) and rotation_starts within 0..18");
  if (!(c.uncertain_ndt_scale >= 1.0) || !(c.uncertain_jump_scale >= 1.0))
    throw Error("odometry: uncertain_ndt_scale and uncertain_jump_scale must be at least 1");
  if (!(c.global_start_below >= 0.0 && c.global_start_below <= 1.0) ||
      !(c.global_start_gain >= 1.0))
    throw Error(
        "odometry: global_start_below must lie within 0..1 (0: off) and global_start_gain be at "
        "least 1");
  if (c.wide_start_iterations < 0)
    throw Error("odometry: wide_start_iterations must not be negative (0: never)");
  if (!(std::abs(c.elevation_correction_deg) <= 5.0))
    throw Error("odometry: elevation_correction_deg must lie within -5..5 degrees");
  positive(c.prior_miss_distance, "prior_miss_distance");
  if (c.degeneracy_guard_frames < 0 || !(c.degeneracy_guard_ratio >= 0.0) ||
      !(c.degeneracy_ratio >= 0.0))
    throw Error(
        "odometry: degeneracy_ratio, degeneracy_guard_ratio and degeneracy_guard_frames must not "
        "be negative");
  if (!(c.anchor_min_translation >= 0.0) || !(c.anchor_min_rotation >= 0.0))
    throw Error("odometry: anchor_min_translation and anchor_min_rotation must not be negative");
  if (!(c.redeskew_translation >= 0.0) || !(c.redeskew_rotation >= 0.0))
    throw Error("odometry: redeskew_translation and redeskew_rotation must not be negative");
  positive(c.prior_miss_angle, "prior_miss_angle");
  positive(c.spin_period, "spin_period");
  if (!std::isfinite(c.spin_start_azimuth))
    throw Error("odometry: spin_start_azimuth must be finite (radians)");
}

}  // namespace scanmatch
