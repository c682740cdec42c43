#include "scanmatch/geometry/kdtree.hpp"

#include <nanoflann.hpp>

namespace scanmatch {
namespace {
struct PointsAdaptor {
  const std::vector<Point>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points[i][static_cast<int>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointsAdaptor>,
                                                 PointsAdaptor, 3, std::size_t>;
}  // namespace

struct KdTree::Impl {
  explicit Impl(const std::vector<Point>& points)
      : adaptor{points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }
  PointsAdaptor adaptor;
  Tree tree;
};

KdTree::KdTree(const std::vector<Point>& points) : impl_(std::make_unique<Impl>(points)) {}
KdTree::~KdTree() = default;
KdTree::KdTree(KdTree&&) noexcept = default;

std::size_t KdTree::size() const {
  return impl_->adaptor.points.size();
}

bool KdTree::nearest(const Point& query, float max_squared_distance, std::size_t& index,
                     float& squared_distance) const {
  if (size() == 0) return false;
  std::size_t i = 0;
  float d = 0.0f;
  nanoflann::KNNResultSet<float, std::size_t> result(1);
  result.init(&i, &d);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (d > max_squared_distance) return false;
  index = i;
  squared_distance = d;
  return true;
}

std::size_t KdTree::knn(const Point& query, std::size_t k, std::size_t* indices,
                        float* squared_distances) const {
  if (size() == 0 || k == 0) return 0;
  nanoflann::KNNResultSet<float, std::size_t> result(k);
  result.init(indices, squared_distances);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.size();
}

}  // namespace scanmatch
