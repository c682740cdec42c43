#pragma once
// The one voxel hash table of the library: values of any type keyed by VoxelKey. Used by the
// voxel filter (per-voxel sums), the Gaussian voxel map (its voxels) and the exported map (a set
// of occupied cells).
//
// Layout: the entries live densely, in insertion order, in two parallel vectors (keys() and
// values()), so iteration and removal are plain array loops and an entry is named by its
// position. The hash part is open addressing with linear probing over 16-byte slots that hold a
// key and its entry's position, at most half full: a probe reads one cache line of the slots and
// nothing else, and a hit costs one more read of the value.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_key.hpp"

namespace scanmatch {

template <typename Value>
class VoxelHashTable {
 public:
  /// find's answer for a key that is absent.
  static constexpr std::int32_t kAbsent = -1;

  /// Position of the key's entry in keys() and values(), or kAbsent.
  std::int32_t find(const VoxelKey& key) const {
    if (slots_.empty()) return kAbsent;
    return slots_[probe(key)].entry;
  }

  struct FindOrInsert {
    std::size_t entry;  ///< position in keys() and values()
    bool inserted;      ///< the key was absent: its value is new, value-initialised
  };
  /// The key's entry, appended with a value-initialised Value when absent.
  FindOrInsert find_or_insert(const VoxelKey& key) {
    // Grown before the probe, so that the empty slot it ends on is where a new key goes.
    if (2 * (values_.size() + 1) > slots_.size()) rebuild(2 * (values_.size() + 1));
    const std::size_t at = probe(key);
    if (slots_[at].entry >= 0) return {static_cast<std::size_t>(slots_[at].entry), false};
    if (values_.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw Error("voxel hash table: too many voxels");
    slots_[at] = Slot{key, static_cast<std::int32_t>(values_.size())};
    values_.emplace_back();
    keys_.push_back(key);
    return {values_.size() - 1, true};
  }

  /// Starts loading the slot where a probe for `key` begins, for a find shortly after (loops
  /// that look many keys up overlap their memory reads this way). Always inlined: GCC finds a
  /// function that only prefetches free of effects and drops calls to it that it did not inline.
  [[gnu::always_inline]] void prefetch(const VoxelKey& key) const {
    if (!slots_.empty()) __builtin_prefetch(&slots_[VoxelKeyHash{}(key) & (slots_.size() - 1)]);
  }

  std::size_t size() const { return values_.size(); }
  bool empty() const { return values_.empty(); }
  /// Every key and value, in parallel, in insertion order (removals keep the order of the rest).
  const std::vector<VoxelKey>& keys() const { return keys_; }
  const std::vector<Value>& values() const { return values_; }
  /// One value, writable in place.
  Value& value(std::size_t entry) { return values_[entry]; }
  const Value& value(std::size_t entry) const { return values_[entry]; }

  /// Removes every entry for which remove(key, value) is true; the others keep their order (and
  /// so move to lower positions). Returns how many were removed.
  template <typename Remove>
  std::size_t remove_if(Remove&& remove) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < values_.size(); ++i) {
      if (remove(std::as_const(keys_[i]), std::as_const(values_[i]))) continue;
      if (kept != i) {
        keys_[kept] = keys_[i];
        values_[kept] = std::move(values_[i]);
      }
      ++kept;
    }
    const std::size_t removed = values_.size() - kept;
    if (removed > 0) {
      keys_.resize(kept);
      values_.resize(kept);
      rebuild(kept);
    }
    return removed;
  }

  /// Removes every entry; keeps the allocations and the number of slots (a table refilled with
  /// about as many entries).
  void clear() {
    keys_.clear();
    values_.clear();
    std::fill(slots_.begin(), slots_.end(), Slot{});
  }
  /// Removes every entry and sizes the slots for about `expected` entries (they still grow when
  /// needed): keeps the allocations, but never probes a table much larger than the work at hand.
  void reset(std::size_t expected) {
    keys_.clear();
    values_.clear();
    slots_.assign(slot_count_for(expected), Slot{});
  }
  /// Room for this many entries without growing.
  void reserve(std::size_t entries) {
    values_.reserve(entries);
    keys_.reserve(entries);
    if (2 * entries > slots_.size()) rebuild(entries);
  }

 private:
  struct Slot {
    VoxelKey key;
    std::int32_t entry = kAbsent;  ///< position in keys_ and values_; kAbsent: empty slot
  };

  /// A power of two (the probe masks the hash), at least twice `entries`.
  static std::size_t slot_count_for(std::size_t entries) {
    std::size_t count = 16;
    while (count < 2 * entries) count *= 2;
    return count;
  }
  /// The one probe (linear, from the key's hash): the slot holding `key`, or else the empty slot
  /// where it would go. The slots must not be empty; at most half full, a probe always ends.
  std::size_t probe(const VoxelKey& key) const {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t at = VoxelKeyHash{}(key)&mask;; at = (at + 1) & mask) {
      const Slot& slot = slots_[at];
      if (slot.entry < 0 || slot.key == key) return at;
    }
  }
  /// Slots for `entries`, refilled from keys_.
  void rebuild(std::size_t entries) {
    slots_.assign(slot_count_for(entries), Slot{});
    for (std::size_t i = 0; i < keys_.size(); ++i)
      slots_[probe(keys_[i])] = Slot{keys_[i], static_cast<std::int32_t>(i)};
  }

  std::vector<Value> values_;
  std::vector<VoxelKey> keys_;
  std::vector<Slot> slots_;
};

/// A set of voxels (the exported map's occupied cells): the table with nothing per voxel.
struct NoValue {};
using VoxelSet = VoxelHashTable<NoValue>;

}  // namespace scanmatch
