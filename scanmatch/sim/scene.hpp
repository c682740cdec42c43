#pragma once
// A 3D scene: exact primitives (boxes, vertical cylinders, ellipsoids, a gently sloped ground),
// triangulated for Embree's ray caster and kept analytic for distance checks in tests.

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace scanmatch::sim {

struct Box {
  Eigen::Vector3d center, half_size;  ///< in the box's own axes
  double yaw = 0.0;                   ///< rotation about z, rad
  float reflectivity = 0.5f;
};
struct Cylinder {  ///< vertical
  Eigen::Vector2d center;
  double radius, z_min, z_max;
  float reflectivity = 0.4f;
};
struct Ellipsoid {
  Eigen::Vector3d center, radii;
  float reflectivity = 0.3f;
};
/// z = height(x, y) = slope_x x + slope_y y + amplitude sin(x / wavelength) cos(y / wavelength),
/// over [-half_extent, half_extent] in x and [-y_half_extent(), y_half_extent()] in y.
struct Ground {
  double slope_x = 0.0, slope_y = 0.0, amplitude = 0.0, wavelength = 20.0, half_extent = 100.0;
  /// A long strip instead of a square (a straight road needs no ground far to its sides): the
  /// half extent in y, 0 for half_extent.
  double half_extent_y = 0.0;
  double y_half_extent() const { return half_extent_y > 0.0 ? half_extent_y : half_extent; }
  double cell = 1.0;  ///< triangulation step, m
  float reflectivity = 0.25f;
  double height(double x, double y) const;
  Eigen::Vector3d normal(double x, double y) const;
};

struct RayHit {
  bool hit = false;
  double range = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  float reflectivity = 0.0f;
};

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  void add(const Box& box);
  void add(const Cylinder& cylinder);
  void add(const Ellipsoid& ellipsoid);
  void set_ground(const Ground& ground);
  /// Builds the ray-casting structure; call once after adding everything.
  void commit();

  /// First hit along origin + t dir (dir normalised) for t in [min_range, max_range].
  RayHit raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double min_range,
                 double max_range) const;
  /// Distance from p to the nearest exact surface (boxes, cylinders, ellipsoids (approximate
  /// for non-spheres), ground); for tests of point consistency.
  double distance_to_surface(const Eigen::Vector3d& p) const;
  /// Signed distance from p to the nearest box, cylinder or ellipsoid (negative inside one; the
  /// ground left out): where a sensor may not be.
  double distance_to_objects(const Eigen::Vector3d& p) const;

  const std::vector<Box>& boxes() const { return boxes_; }
  const std::vector<Cylinder>& cylinders() const { return cylinders_; }
  const std::vector<Ellipsoid>& ellipsoids() const { return ellipsoids_; }
  const Ground* ground() const { return has_ground_ ? &ground_ : nullptr; }
  std::size_t triangle_count() const { return triangles_.size(); }

 private:
  void add_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    float reflectivity);
  std::vector<Box> boxes_;
  std::vector<Cylinder> cylinders_;
  std::vector<Ellipsoid> ellipsoids_;
  Ground ground_;
  bool has_ground_ = false;
  std::vector<Eigen::Vector3f> vertices_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<float> triangle_reflectivity_;
  struct Embree;
  std::unique_ptr<Embree> embree_;
};

}  // namespace scanmatch::sim
