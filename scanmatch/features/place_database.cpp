// The place database: stored descriptors and their queries (place_database.hpp).
#include "scanmatch/features/place_database.hpp"

#include <algorithm>
#include <nanoflann.hpp>
#include <string>
#include <utility>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

// A k-d tree over the ring keys of the entries present at its last build.
template <class Descriptor>
struct PlaceDatabase<Descriptor>::KeyTree {
  struct Adaptor {
    const std::vector<float>& keys;
    std::size_t dim;
    std::size_t kdtree_get_point_count() const { return keys.size() / dim; }
    float kdtree_get_pt(std::size_t i, std::size_t k) const { return keys[i * dim + k]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>,
                                                   Adaptor, -1, std::size_t>;

  KeyTree(std::vector<float> all_keys, std::size_t dimension)
      : keys(std::move(all_keys)),
        adaptor{keys, dimension},
        tree(static_cast<int>(dimension), adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }
  std::size_t size() const { return keys.size() / adaptor.dim; }

  std::vector<float> keys;  // entry i's ring key at [i * dim, (i + 1) * dim)
  Adaptor adaptor;
  Tree tree;
};

namespace {
// nanoflann's k-nearest result set, taking only indices below `end` (entries old enough).
struct OlderThanResultSet {
  nanoflann::KNNResultSet<float, std::size_t, std::size_t> nearest;
  std::size_t end;
  OlderThanResultSet(std::size_t k, std::size_t end_index) : nearest(k), end(end_index) {}
  bool full() const { return nearest.full(); }
  float worstDist() const { return nearest.worstDist(); }
  bool addPoint(float distance, std::size_t index) {
    return index < end ? nearest.addPoint(distance, index) : true;
  }
};

// Entries without a key (empty descriptors) sit this far away in key space.
constexpr float kNoKey = 1e6f;

float squared_key_distance(const std::vector<float>& a, const std::vector<float>& b) {
  float sum = 0.0f;
  for (std::size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
  return sum;
}
}  // namespace

template <class Descriptor>
PlaceDatabase<Descriptor>::PlaceDatabase(const PlaceDatabaseOptions& options) : options_(options) {
  options_.rebuild_every = std::max<std::size_t>(1, options_.rebuild_every);
}
template <class Descriptor>
PlaceDatabase<Descriptor>::~PlaceDatabase() = default;
template <class Descriptor>
PlaceDatabase<Descriptor>::PlaceDatabase(PlaceDatabase&&) noexcept = default;
template <class Descriptor>
PlaceDatabase<Descriptor>& PlaceDatabase<Descriptor>::operator=(PlaceDatabase&&) noexcept = default;

template <class Descriptor>
std::size_t PlaceDatabase<Descriptor>::add(const Descriptor& descriptor) {
  if (!descriptor.empty())
    for (const Descriptor& e : entries_)
      if (!e.empty()) {
        if (e.rings != descriptor.rings || e.sectors != descriptor.sectors)
          fail("place database", "descriptor of " + std::to_string(descriptor.rings) + " x " +
                                     std::to_string(descriptor.sectors) +
                                     " cells added to a database of " + std::to_string(e.rings) +
                                     " x " + std::to_string(e.sectors));
        break;
      }
  entries_.push_back(descriptor);
  const std::size_t indexed = tree_ ? tree_->size() : 0;
  if (entries_.size() - indexed >= options_.rebuild_every) {
    std::size_t dim = 0;
    for (const Descriptor& e : entries_) dim = std::max(dim, e.ring_key.size());
    if (dim > 0) {
      std::vector<float> keys;
      keys.reserve(entries_.size() * dim);
      for (const Descriptor& e : entries_) {
        if (e.empty())
          keys.insert(keys.end(), dim, kNoKey);
        else
          keys.insert(keys.end(), e.ring_key.begin(), e.ring_key.end());
      }
      tree_ = std::make_unique<KeyTree>(std::move(keys), dim);
    }
  }
  return entries_.size() - 1;
}

template <class Descriptor>
std::vector<PlaceCandidate> PlaceDatabase<Descriptor>::query(const Descriptor& descriptor,
                                                             std::size_t exclude_newest,
                                                             std::size_t max_candidates) const {
  if (descriptor.empty() || max_candidates == 0 || exclude_newest >= entries_.size()) return {};
  const std::size_t end = entries_.size() - exclude_newest;  // entries [0, end) are eligible
  const std::size_t k = std::max(options_.key_candidates, max_candidates);
  std::vector<std::pair<float, std::size_t>> nearest;  // squared key distance, index
  std::size_t searched_to = 0;
  if (tree_ && tree_->adaptor.dim == descriptor.ring_key.size()) {
    std::vector<float> query_key(descriptor.ring_key);
    OlderThanResultSet result(k, end);
    std::vector<std::size_t> indices(k);
    std::vector<float> distances(k);
    result.nearest.init(indices.data(), distances.data());
    tree_->tree.findNeighbors(result, query_key.data(), nanoflann::SearchParams());
    for (std::size_t i = 0; i < result.nearest.size(); ++i)
      nearest.emplace_back(distances[i], indices[i]);
    searched_to = tree_->size();
  }
  // Entries added since the last build: brute force (fewer than rebuild_every).
  for (std::size_t i = searched_to; i < end; ++i) {
    const Descriptor& e = entries_[i];
    if (e.empty() || e.ring_key.size() != descriptor.ring_key.size()) continue;
    nearest.emplace_back(squared_key_distance(e.ring_key, descriptor.ring_key), i);
  }
  const std::size_t keep = std::min(k, nearest.size());
  std::partial_sort(nearest.begin(), nearest.begin() + static_cast<long>(keep), nearest.end());
  std::vector<PlaceCandidate> candidates;
  for (std::size_t i = 0; i < keep; ++i) {
    const PlaceMatch m = compare(descriptor, entries_[nearest[i].second]);
    if (m.distance < 1.0) candidates.push_back({nearest[i].second, m.distance, m.yaw});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const PlaceCandidate& a, const PlaceCandidate& b) {
              return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
            });
  if (candidates.size() > max_candidates) candidates.resize(max_candidates);
  return candidates;
}

template class PlaceDatabase<PlaceDescriptor3D>;
template class PlaceDatabase<PlaceDescriptor2D>;

}  // namespace scanmatch
