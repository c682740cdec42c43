#include "scanmatch/sim/scene.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanmatch/core/error.hpp"

namespace scanmatch::sim {
namespace {
constexpr int kCylinderFacets = 48;  // chord error 0.2 % of the radius
constexpr int kEllipsoidSlices = 24, kEllipsoidStacks = 16;

Eigen::Matrix2d yaw_rotation(double yaw) {
  Eigen::Matrix2d R;
  R << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  return R;
}
}  // namespace

double Ground::height(double x, double y) const {
  return slope_x * x + slope_y * y +
         amplitude * std::sin(x / wavelength) * std::cos(y / wavelength);
}

Eigen::Vector3d Ground::normal(double x, double y) const {
  const double dx =
      slope_x + amplitude / wavelength * std::cos(x / wavelength) * std::cos(y / wavelength);
  const double dy =
      slope_y - amplitude / wavelength * std::sin(x / wavelength) * std::sin(y / wavelength);
  return Eigen::Vector3d(-dx, -dy, 1.0).normalized();
}

struct Scene::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

void Scene::add_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, float reflectivity) {
  const int base = static_cast<int>(vertices_.size());
  vertices_.push_back(a.cast<float>());
  vertices_.push_back(b.cast<float>());
  vertices_.push_back(c.cast<float>());
  triangles_.emplace_back(base, base + 1, base + 2);
  triangle_reflectivity_.push_back(reflectivity);
}

void Scene::add(const Box& box) {
  boxes_.push_back(box);
  const Eigen::Matrix2d R = yaw_rotation(box.yaw);
  Eigen::Vector3d corners[8];
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d local((i & 1 ? 1 : -1) * box.half_size.x(),
                                (i & 2 ? 1 : -1) * box.half_size.y(),
                                (i & 4 ? 1 : -1) * box.half_size.z());
    corners[i].head<2>() = box.center.head<2>() + R * local.head<2>();
    corners[i].z() = box.center.z() + local.z();
  }
  static const int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                   {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : kFaces) {
    add_triangle(corners[f[0]], corners[f[1]], corners[f[2]], box.reflectivity);
    add_triangle(corners[f[0]], corners[f[2]], corners[f[3]], box.reflectivity);
  }
}

void Scene::add(const Cylinder& c) {
  cylinders_.push_back(c);
  for (int k = 0; k < kCylinderFacets; ++k) {
    const double a0 = 2 * M_PI * k / kCylinderFacets, a1 = 2 * M_PI * (k + 1) / kCylinderFacets;
    const Eigen::Vector3d p0(c.center.x() + c.radius * std::cos(a0),
                             c.center.y() + c.radius * std::sin(a0), 0);
    const Eigen::Vector3d p1(c.center.x() + c.radius * std::cos(a1),
                             c.center.y() + c.radius * std::sin(a1), 0);
    const Eigen::Vector3d lo(0, 0, c.z_min), hi(0, 0, c.z_max);
    add_triangle(p0 + lo, p1 + lo, p1 + hi, c.reflectivity);
    add_triangle(p0 + lo, p1 + hi, p0 + hi, c.reflectivity);
    const Eigen::Vector3d top(c.center.x(), c.center.y(), c.z_max),
        bottom(c.center.x(), c.center.y(), c.z_min);
    add_triangle(top, p0 + hi, p1 + hi, c.reflectivity);
    add_triangle(bottom, p1 + lo, p0 + lo, c.reflectivity);
  }
}

void Scene::add(const Ellipsoid& e) {
  ellipsoids_.push_back(e);
  const auto point = [&](int slice, int stack) {
    const double theta = M_PI * stack / kEllipsoidStacks, phi = 2 * M_PI * slice / kEllipsoidSlices;
    return Eigen::Vector3d(e.center.x() + e.radii.x() * std::sin(theta) * std::cos(phi),
                           e.center.y() + e.radii.y() * std::sin(theta) * std::sin(phi),
                           e.center.z() + e.radii.z() * std::cos(theta));
  };
  for (int i = 0; i < kEllipsoidSlices; ++i)
    for (int j = 0; j < kEllipsoidStacks; ++j) {
      add_triangle(point(i, j), point(i, j + 1), point(i + 1, j + 1), e.reflectivity);
      add_triangle(point(i, j), point(i + 1, j + 1), point(i + 1, j), e.reflectivity);
    }
}

void Scene::set_ground(const Ground& g) {
  ground_ = g;
  has_ground_ = true;
  const int nx = static_cast<int>(std::ceil(2 * g.half_extent / g.cell));
  const int ny = static_cast<int>(std::ceil(2 * g.y_half_extent() / g.cell));
  const auto vertex = [&](int i, int j) {
    const double x = -g.half_extent + i * g.cell, y = -g.y_half_extent() + j * g.cell;
    return Eigen::Vector3d(x, y, g.height(x, y));
  };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      add_triangle(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), g.reflectivity);
      add_triangle(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1), g.reflectivity);
    }
}

void Scene::commit() {
  embree_ = std::make_unique<Embree>();
  // One build thread: the BVH, and so every tie between triangles, is the same on every machine.
  embree_->device = rtcNewDevice("threads=1");
  if (!embree_->device) throw Error("simulator: cannot create the Embree device");
  embree_->scene = rtcNewScene(embree_->device);
  RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices_.size()));
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                            triangles_.size()));
  for (std::size_t i = 0; i < vertices_.size(); ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + k] = vertices_[i][k];
  for (std::size_t i = 0; i < triangles_.size(); ++i)
    for (int k = 0; k < 3; ++k) ib[3 * i + k] = static_cast<unsigned>(triangles_[i][k]);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(embree_->scene);
}

RayHit Scene::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double min_range,
                      double max_range) const {
  RayHit out;
  if (!embree_) throw Error("simulator: scene used before commit()");
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(dir.x());
  rh.ray.dir_y = static_cast<float>(dir.y());
  rh.ray.dir_z = static_cast<float>(dir.z());
  rh.ray.tnear = static_cast<float>(min_range);
  rh.ray.tfar = static_cast<float>(max_range);
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
  out.hit = true;
  out.range = rh.ray.tfar;
  out.normal = Eigen::Vector3d(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
  if (out.normal.dot(dir) > 0) out.normal = -out.normal;
  out.reflectivity = triangle_reflectivity_[rh.hit.primID];
  return out;
}

namespace {
// Signed distances (negative inside), exact for boxes and cylinders, approximate for ellipsoids
// other than spheres.
double signed_distance(const Box& b, const Eigen::Vector3d& p) {
  Eigen::Vector3d local;
  local.head<2>() = yaw_rotation(b.yaw).transpose() * (p.head<2>() - b.center.head<2>());
  local.z() = p.z() - b.center.z();
  const Eigen::Vector3d q = local.cwiseAbs() - b.half_size;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}
double signed_distance(const Cylinder& c, const Eigen::Vector3d& p) {
  const double radial = (p.head<2>() - c.center).norm() - c.radius;
  const double vertical = std::max(c.z_min - p.z(), p.z() - c.z_max);
  const Eigen::Vector2d q(radial, vertical);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}
double signed_distance(const Ellipsoid& e, const Eigen::Vector3d& p) {
  return (((p - e.center).cwiseQuotient(e.radii)).norm() - 1.0) * e.radii.minCoeff();
}
}  // namespace

double Scene::distance_to_objects(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::max();
  for (const Box& b : boxes_) best = std::min(best, signed_distance(b, p));
  for (const Cylinder& c : cylinders_) best = std::min(best, signed_distance(c, p));
  for (const Ellipsoid& e : ellipsoids_) best = std::min(best, signed_distance(e, p));
  return best;
}

double Scene::distance_to_surface(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::max();
  for (const Box& b : boxes_) best = std::min(best, std::abs(signed_distance(b, p)));
  for (const Cylinder& c : cylinders_) best = std::min(best, std::abs(signed_distance(c, p)));
  for (const Ellipsoid& e : ellipsoids_) best = std::min(best, std::abs(signed_distance(e, p)));
  if (has_ground_ && std::abs(p.x()) <= ground_.half_extent &&
      std::abs(p.y()) <= ground_.y_half_extent()) {
    // Height of the triangulated surface (what the rays hit), not of the analytic one.
    const double gx = (p.x() + ground_.half_extent) / ground_.cell,
                 gy = (p.y() + ground_.y_half_extent()) / ground_.cell;
    const double i = std::floor(gx), j = std::floor(gy), u = gx - i, v = gy - j;
    const auto h = [&](double a, double b) {
      return ground_.height(-ground_.half_extent + a * ground_.cell,
                            -ground_.y_half_extent() + b * ground_.cell);
    };
    const double z =
        u >= v ? h(i, j) + u * (h(i + 1, j) - h(i, j)) + v * (h(i + 1, j + 1) - h(i + 1, j))
               : h(i, j) + v * (h(i, j + 1) - h(i, j)) + u * (h(i + 1, j + 1) - h(i, j + 1));
    best = std::min(best, std::abs(p.z() - z) * ground_.normal(p.x(), p.y()).z());
  }
  return best;
}

}  // namespace scanmatch::sim
