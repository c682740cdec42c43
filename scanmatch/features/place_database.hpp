#pragma once
// The place database: descriptors of past scans (place_descriptor.hpp), searched for the places a
// new scan revisits. A k-d tree over the rotation-invariant ring keys picks the few entries worth
// a full comparison (compare()); entries added since its last build are searched by brute force.

#include <cstddef>
#include <memory>
#include <vector>

#include "scanmatch/features/place_descriptor.hpp"

namespace scanmatch {

struct PlaceCandidate {
  std::size_t index = 0;  ///< what PlaceDatabase::add returned
  double distance = 1.0;  ///< PlaceMatch::distance
  double yaw = 0.0;       ///< PlaceMatch::yaw: query heading in the candidate's frame
};

struct PlaceDatabaseOptions {
  /// How many entries nearest by ring key are scored with compare() (at least max_candidates).
  std::size_t key_candidates = 10;
  /// The k-d tree over ring keys is rebuilt once this many entries were added since the last
  /// build; entries added since are searched by brute force (at most this many per query), so a
  /// query costs a tree search plus O(rebuild_every), and adding costs O(n log n / rebuild_every)
  /// amortised.
  std::size_t rebuild_every = 50;
};

/// Descriptors of past scans, searched for the places a new scan revisits.
template <class Descriptor>
class PlaceDatabase {
 public:
  explicit PlaceDatabase(const PlaceDatabaseOptions& options = {});
  ~PlaceDatabase();
  PlaceDatabase(PlaceDatabase&&) noexcept;
  PlaceDatabase& operator=(PlaceDatabase&&) noexcept;

  /// Stores a copy; returns its index (0, 1, 2, ... in order of addition).
  std::size_t add(const Descriptor& descriptor);
  /// Up to max_candidates entries, lowest distance first, among those added before the newest
  /// `exclude_newest` (recent scans are trivially similar and no loop). Empty descriptors
  /// (empty query or entries) never appear: they match nothing.
  std::vector<PlaceCandidate> query(const Descriptor& descriptor, std::size_t exclude_newest,
                                    std::size_t max_candidates) const;
  std::size_t size() const { return entries_.size(); }
  const Descriptor& at(std::size_t index) const { return entries_.at(index); }

 private:
  struct KeyTree;
  PlaceDatabaseOptions options_;
  std::vector<Descriptor> entries_;
  std::unique_ptr<KeyTree> tree_;  // over the ring keys of entries [0, tree size)
};

using PlaceDatabase3D = PlaceDatabase<PlaceDescriptor3D>;
using PlaceDatabase2D = PlaceDatabase<PlaceDescriptor2D>;
extern template class PlaceDatabase<PlaceDescriptor3D>;
extern template class PlaceDatabase<PlaceDescriptor2D>;

}  // namespace scanmatch
