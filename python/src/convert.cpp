#include "convert.hpp"

#include <cmath>
#include <cstring>

#include "scanmatch/core/point_cloud.hpp"

namespace scanmatch::python {
namespace {

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Any array-like as a numpy array of a real (bool excluded) dtype.
py::array numeric_array(py::handle obj, const std::string& name) {
  if (obj.is_none()) throw py::type_error(name + ": expected an array, got None");
  py::array a;
  try {
    a = py::array::ensure(obj);
  } catch (const py::error_already_set&) {
  }
  if (!a) throw py::type_error(name + ": expected a numeric array");
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(name + ": expected a real-valued (float or integer) array, got dtype " +
                         py::str(a.dtype()).cast<std::string>());
  return a;
}

}  // namespace

py::array_t<double, py::array::c_style | py::array::forcecast> as_matrix(py::handle obj,
                                                                         const std::string& name,
                                                                         py::ssize_t columns) {
  const py::array a = numeric_array(obj, name);
  if (a.ndim() != 2 || a.shape(1) != columns)
    throw py::value_error(name + ": expected an array of shape (N, " + std::to_string(columns) +
                          "), got " + shape_of(a));
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

py::array_t<double, py::array::c_style | py::array::forcecast> as_vector(py::handle obj,
                                                                         const std::string& name,
                                                                         py::ssize_t n) {
  const py::array a = numeric_array(obj, name);
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(name + ": expected an array of shape (" + std::to_string(n) + ",), got " +
                          shape_of(a));
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

void check_finite(const PointCloud& cloud, const std::string& name) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Point& p = cloud.points[i];
    if (!p.allFinite())
      throw py::value_error(name + ": point " + std::to_string(i) +
                            " has a non-finite coordinate (" + std::to_string(p.x()) + ", " +
                            std::to_string(p.y()) + ", " + std::to_string(p.z()) + ")");
  }
}

PointCloud cloud_from_array(py::handle obj, const std::string& name, bool finite) {
  const py::array a = numeric_array(obj, name);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(name + ": expected an array of shape (N, 3) with x y z, got " +
                          shape_of(a));
  // float32 C-contiguous input is not copied here; other dtypes and layouts are converted.
  const auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  PointCloud cloud;
  cloud.points.resize(static_cast<std::size_t>(f.shape(0)));
  static_assert(sizeof(Point) == 3 * sizeof(float), "Point must be three packed floats");
  if (!cloud.points.empty())
    std::memcpy(cloud.points.front().data(), f.data(), cloud.points.size() * sizeof(Point));
  if (finite) check_finite(cloud, name);
  return cloud;
}

const PointCloud& cloud_argument(py::handle obj, const std::string& name,
                                 std::optional<PointCloud>& storage) {
  if (py::isinstance<PointCloud>(obj)) {
    const PointCloud& cloud = obj.cast<const PointCloud&>();
    check_finite(cloud, name);
    return cloud;
  }
  storage = cloud_from_array(obj, name);
  return *storage;
}

Pose pose_from_array(py::handle obj, const std::string& name) {
  if (obj.is_none()) return Pose::Identity();
  const py::array a = numeric_array(obj, name);
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(name + ": expected a 4x4 transform, got shape " + shape_of(a));
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = d.at(r, c);
  if (!m.allFinite()) throw py::value_error(name + ": the transform has non-finite entries");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    throw py::value_error(name + ": the last row of a 4x4 transform must be 0 0 0 1");
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0)
    throw py::value_error(name + ": the rotation block is not a rotation matrix");
  return from_matrix(m);
}

py::array_t<double> pose_to_array(const Pose& pose) {
  py::array_t<double> out({4, 4});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o(r, c) = pose.matrix()(r, c);
  return out;
}

namespace {

// Converts each entry along an array's first axis, named name[i] in errors.
template <typename P, typename Convert>
std::vector<P> each_pose(const py::array& a, const std::string& name, Convert convert) {
  std::vector<P> poses;
  poses.reserve(static_cast<std::size_t>(a.shape(0)));
  py::object sequence = py::reinterpret_borrow<py::object>(a);
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    poses.push_back(convert(sequence[py::int_(i)], name + "[" + std::to_string(i) + "]"));
  return poses;
}

}  // namespace

std::vector<Pose> poses_from_array(py::handle obj, const std::string& name) {
  const py::array a = numeric_array(obj, name);
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4)
    throw py::value_error(name + ": expected an array of shape (N, 4, 4), got " + shape_of(a));
  return each_pose<Pose>(a, name, pose_from_array);
}

py::array_t<double> poses_to_array(const std::vector<Pose>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto o = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(static_cast<py::ssize_t>(i), r, c) = poses[i].matrix()(r, c);
  return out;
}

Scan2D scan_from_arrays(py::handle points, py::handle times, bool circular,
                        const std::string& name) {
  const auto a = as_matrix(points, name, 2);
  Scan2D scan;
  scan.circular = circular;
  scan.points.resize(static_cast<std::size_t>(a.shape(0)));
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    scan.points[i] =
        Eigen::Vector2d(a.at(static_cast<py::ssize_t>(i), 0), a.at(static_cast<py::ssize_t>(i), 1));
    if (!scan.points[i].allFinite())
      throw py::value_error(name + ": point " + std::to_string(i) + " has a non-finite coordinate");
  }
  if (!times.is_none()) {
    const auto t = as_vector(times, "times", a.shape(0));
    scan.times.assign(t.data(), t.data() + scan.points.size());
    for (std::size_t i = 0; i < scan.times.size(); ++i)
      if (!std::isfinite(scan.times[i]))
        throw py::value_error("times: entry " + std::to_string(i) + " is not finite");
  }
  return scan;
}

// A 3x3 homogeneous matrix or (x, y, theta); None: the identity.
Pose2 pose2_from(py::handle obj, const std::string& name) {
  if (obj.is_none()) return Pose2::Identity();
  const py::array a = py::array::ensure(obj);
  const bool vector = a && a.ndim() == 1 && a.shape(0) == 3;
  const bool matrix = a && a.ndim() == 2 && a.shape(0) == 3 && a.shape(1) == 3;
  if (!vector && !matrix) throw py::value_error(name + ": expected a 3x3 matrix or (x, y, theta)");
  if (vector) {
    const auto v = as_vector(obj, name, 3);
    const Eigen::Vector3d xyt(v.at(0), v.at(1), v.at(2));
    if (!xyt.allFinite()) throw py::value_error(name + ": (x, y, theta) must be finite");
    return pose2(xyt);
  }
  const auto m = as_matrix(obj, name, 3);
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = m.at(r, c);
  if (!M.allFinite()) throw py::value_error(name + ": the transform has non-finite entries");
  if ((M.row(2) - Eigen::RowVector3d(0, 0, 1)).norm() > 1e-9)
    throw py::value_error(name + ": the last row of a 3x3 transform must be 0 0 1");
  const Eigen::Matrix2d R = M.topLeftCorner<2, 2>();
  if ((R.transpose() * R - Eigen::Matrix2d::Identity()).norm() > 1e-4 || R.determinant() < 0)
    throw py::value_error(name + ": the rotation block is not a rotation matrix");
  return pose2(M(0, 2), M(1, 2), std::atan2(M(1, 0), M(0, 0)));
}

py::array_t<double> pose2_to_array(const Pose2& T) {
  py::array_t<double> out({3, 3});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) o(r, c) = T.matrix()(r, c);
  return out;
}

std::vector<Pose2> poses2_from_array(py::handle obj, const std::string& name) {
  const py::array a = numeric_array(obj, name);
  const bool matrices = a.ndim() == 3 && a.shape(1) == 3 && a.shape(2) == 3;
  const bool rows = a.ndim() == 2 && a.shape(1) == 3;
  if (!matrices && !rows)
    throw py::value_error(
        name + ": expected an array of shape (N, 3, 3) or (N, 3) of x y theta, got " + shape_of(a));
  return each_pose<Pose2>(a, name, pose2_from);
}

py::array_t<double> poses2_to_array(const std::vector<Pose2>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{3}, py::ssize_t{3}});
  auto o = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col)
        o(static_cast<py::ssize_t>(i), r, col) = poses[i].matrix()(r, col);
  return out;
}

}  // namespace scanmatch::python
