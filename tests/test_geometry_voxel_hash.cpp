#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include "scanmatch/geometry/voxel_hash.hpp"

using namespace scanmatch;

namespace {

using Table = VoxelHashTable<int>;
using Reference = std::unordered_map<VoxelKey, int, VoxelKeyHash>;

// The table holds exactly the reference's entries, each findable at its position.
void expect_same(const Table& table, const Reference& reference) {
  ASSERT_EQ(table.size(), reference.size());
  ASSERT_EQ(table.keys().size(), table.values().size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    const auto it = reference.find(table.keys()[i]);
    ASSERT_NE(it, reference.end()) << "entry " << i;
    EXPECT_EQ(table.values()[i], it->second);
    EXPECT_EQ(table.find(table.keys()[i]), static_cast<std::int32_t>(i));
  }
}

VoxelKey random_key(std::mt19937& rng, int extent) {
  std::uniform_int_distribution<int> u(-extent, extent);
  return {u(rng), u(rng), u(rng)};
}

}  // namespace

TEST(VoxelHashTable, InsertAndFindAgreeWithUnorderedMapThroughGrowth) {
  Table table;
  Reference reference;
  std::mt19937 rng(3);
  EXPECT_EQ(table.find({0, 0, 0}), Table::kAbsent);  // no slots yet
  // A small extent: many repeated keys; 20000 draws grow the table from 16 slots many times.
  for (int n = 0; n < 20000; ++n) {
    const VoxelKey key = random_key(rng, 15);
    const auto [entry, inserted] = table.find_or_insert(key);
    EXPECT_EQ(inserted, reference.find(key) == reference.end());
    if (inserted) {
      EXPECT_EQ(entry, table.size() - 1);  // appended
      EXPECT_EQ(table.value(entry), 0);    // value-initialised
      reference[key] = n;
      table.value(entry) = n;
    }
    EXPECT_EQ(table.keys()[entry], key);
  }
  expect_same(table, reference);
  for (int n = 0; n < 2000; ++n) {
    const VoxelKey key = random_key(rng, 40);
    EXPECT_EQ(table.find(key) >= 0, reference.count(key) == 1);
  }
}

TEST(VoxelHashTable, CollidingKeysProbeOnToTheirOwnEntries) {
  // Keys that share their first slot in a 16-slot table (the smallest): linear probing must
  // keep them apart and find each, also after removing one in the middle of the run.
  Table table;
  table.reserve(4);  // stays at 16 slots for up to 8 entries
  std::vector<VoxelKey> colliding{{0, 0, 0}};
  const std::size_t first = VoxelKeyHash{}(colliding[0]) & 15;
  for (int x = 1; colliding.size() < 5; ++x)
    if ((VoxelKeyHash{}(VoxelKey{x, 7, -3}) & 15) == first) colliding.push_back({x, 7, -3});
  for (std::size_t i = 0; i < colliding.size(); ++i)
    table.value(table.find_or_insert(colliding[i]).entry) = static_cast<int>(i);
  for (std::size_t i = 0; i < colliding.size(); ++i)
    EXPECT_EQ(table.value(static_cast<std::size_t>(table.find(colliding[i]))), static_cast<int>(i));
  EXPECT_EQ(table.remove_if([&](const VoxelKey& k, int) { return k == colliding[2]; }), 1u);
  EXPECT_EQ(table.find(colliding[2]), Table::kAbsent);
  for (std::size_t i = 0; i < colliding.size(); ++i) {
    if (i == 2) continue;
    EXPECT_EQ(table.value(static_cast<std::size_t>(table.find(colliding[i]))), static_cast<int>(i));
  }
}

TEST(VoxelHashTable, IterationIsInsertionOrderAndRemovalKeepsIt) {
  Table table;
  std::vector<VoxelKey> order;
  for (int i = 0; i < 300; ++i) {
    const VoxelKey key{i % 17, i / 17, -i};
    table.value(table.find_or_insert(key).entry) = i;
    order.push_back(key);
  }
  ASSERT_EQ(table.keys(), order);
  // Remove every third entry: the rest keep their order and are found at their new positions.
  Reference reference;
  std::vector<VoxelKey> kept;
  for (int i = 0; i < 300; ++i)
    if (i % 3 != 0) {
      kept.push_back(order[static_cast<std::size_t>(i)]);
      reference[order[static_cast<std::size_t>(i)]] = i;
    }
  EXPECT_EQ(table.remove_if([](const VoxelKey&, int value) { return value % 3 == 0; }), 100u);
  EXPECT_EQ(table.keys(), kept);
  expect_same(table, reference);
  EXPECT_EQ(table.find(order[0]), Table::kAbsent);
  EXPECT_EQ(table.remove_if([](const VoxelKey&, int) { return false; }), 0u);
  // Inserting after a removal appends.
  const auto [entry, inserted] = table.find_or_insert(order[0]);
  EXPECT_TRUE(inserted);
  EXPECT_EQ(entry, 200u);
}

TEST(VoxelHashTable, ClearResetAndReserveEmptyOrSizeWithoutLosingEntries) {
  Table table;
  std::mt19937 rng(5);
  Reference reference;
  for (int n = 0; n < 1000; ++n) {
    const VoxelKey key = random_key(rng, 100);
    if (table.find_or_insert(key).inserted) reference[key] = 0;
  }
  table.reserve(5000);  // rebuilds the slots around the entries
  expect_same(table, reference);
  table.clear();
  EXPECT_TRUE(table.empty());
  EXPECT_EQ(table.find(reference.begin()->first), Table::kAbsent);
  EXPECT_TRUE(table.find_or_insert(reference.begin()->first).inserted);
  table.reset(10);
  EXPECT_TRUE(table.empty());
  EXPECT_EQ(table.find(reference.begin()->first), Table::kAbsent);
  for (const auto& [key, value] : reference) table.find_or_insert(key);
  EXPECT_EQ(table.size(), reference.size());
  for (const auto& [key, value] : reference) EXPECT_GE(table.find(key), 0);
}

TEST(VoxelHashTable, VoxelSetInsertsEachKeyOnce) {
  VoxelSet set;
  EXPECT_TRUE(set.find_or_insert({1, 2, 3}).inserted);
  EXPECT_FALSE(set.find_or_insert({1, 2, 3}).inserted);
  EXPECT_TRUE(set.find_or_insert({-1, 2, 3}).inserted);
  EXPECT_EQ(set.size(), 2u);
  set.prefetch({1, 2, 3});  // a hint only: changes nothing
  EXPECT_EQ(set.find({-1, 2, 3}), 1);
}
