#include "scanmatch/geometry/kdtree.hpp"

#include <nanoflann.hpp>

namespace scanmatch {
namespace {
template <class PointT>
struct PointsAdaptor {
  using Scalar = typename PointT::Scalar;
  const std::vector<PointT>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  Scalar kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points[i][static_cast<int>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
}  // namespace

template <class PointT>
struct BasicKdTree<PointT>::Impl {
  static constexpr int kDim = PointT::RowsAtCompileTime;
  using Adaptor = PointsAdaptor<PointT>;
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<Scalar, Adaptor>,
                                                   Adaptor, kDim, std::size_t>;
  explicit Impl(const std::vector<PointT>& points)
      : adaptor{points}, tree(kDim, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }
  Adaptor adaptor;
  Tree tree;
};

template <class PointT>
BasicKdTree<PointT>::BasicKdTree(const std::vector<PointT>& points)
    : impl_(std::make_unique<Impl>(points)) {}
template <class PointT>
BasicKdTree<PointT>::~BasicKdTree() = default;
template <class PointT>
BasicKdTree<PointT>::BasicKdTree(BasicKdTree&&) noexcept = default;

template <class PointT>
std::size_t BasicKdTree<PointT>::size() const {
  return impl_->adaptor.points.size();
}

template <class PointT>
bool BasicKdTree<PointT>::nearest(const PointT& query, Scalar max_squared_distance,
                                  std::size_t& index, Scalar& squared_distance) const {
  if (size() == 0) return false;
  std::size_t i = 0;
  Scalar d = 0;
  nanoflann::KNNResultSet<Scalar, std::size_t> result(1);
  result.init(&i, &d);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (d > max_squared_distance) return false;
  index = i;
  squared_distance = d;
  return true;
}

template <class PointT>
std::size_t BasicKdTree<PointT>::knn(const PointT& query, std::size_t k, std::size_t* indices,
                                     Scalar* squared_distances) const {
  if (size() == 0 || k == 0) return 0;
  nanoflann::KNNResultSet<Scalar, std::size_t> result(k);
  result.init(indices, squared_distances);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.size();
}

template class BasicKdTree<Point>;
template class BasicKdTree<Eigen::Vector2d>;

}  // namespace scanmatch
