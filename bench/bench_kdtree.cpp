// k-d tree micro-benchmarks: building the 3D tree over a frame-sized cloud, nearest and
// k-nearest queries on it, and nearest queries on a 2D tree and a 2D point grid of a laser
// scan's size.
//   build/bench/scanmatch_bench --benchmark_filter="KdTree|PointGrid2"

#include <benchmark/benchmark.h>

#include <random>

#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/geometry/point_grid2.hpp"

namespace {
using namespace scanmatch;

// 100k points spread over a 100 m x 100 m x 10 m box, and 10k queries in it.
const std::vector<Point>& cloud() {
  static const std::vector<Point> points = [] {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-50, 50), z(-5, 5);
    std::vector<Point> p;
    for (int i = 0; i < 100'000; ++i) p.emplace_back(u(rng), u(rng), z(rng));
    return p;
  }();
  return points;
}
const std::vector<Point>& queries() {
  static const std::vector<Point> points = [] {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-50, 50), z(-5, 5);
    std::vector<Point> p;
    for (int i = 0; i < 10'000; ++i) p.emplace_back(u(rng), u(rng), z(rng));
    return p;
  }();
  return points;
}

void BM_KdTreeBuild3D(benchmark::State& state) {
  for (auto _ : state) {
    const KdTree tree(cloud());
    benchmark::DoNotOptimize(tree.size());
  }
}
BENCHMARK(BM_KdTreeBuild3D)->Unit(benchmark::kMillisecond);

void BM_KdTreeNearest3D(benchmark::State& state) {
  const KdTree tree(cloud());
  std::size_t sum = 0;
  for (auto _ : state)
    for (const Point& q : queries()) {
      std::size_t index = 0;
      float squared = 0.0f;
      if (tree.nearest(q, 1.0f, index, squared)) sum += index;
    }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(queries().size()));
}
BENCHMARK(BM_KdTreeNearest3D)->Unit(benchmark::kMillisecond);

void BM_KdTreeKnn3D(benchmark::State& state) {
  const KdTree tree(cloud());
  std::size_t indices[20], sum = 0;
  float squared[20];
  for (auto _ : state)
    for (const Point& q : queries()) sum += indices[tree.knn(q, 20, indices, squared) - 1];
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(queries().size()));
}
BENCHMARK(BM_KdTreeKnn3D)->Unit(benchmark::kMillisecond);

// Points along the walls of a 10 m x 6 m room, 720 (a laser scan) or 9360 (loop closure's
// submap of 13 scans), and 10k queries within 5 cm of the walls (a converged registration's
// pairing).
struct RoomQueries {
  std::vector<Eigen::Vector2d> points, queries;
};
RoomQueries make_room_queries(int points) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1), noise(-0.05, 0.05);
  const auto on_wall = [&] {
    const double t = 32 * u(rng);  // along the perimeter
    if (t < 10) return Eigen::Vector2d(t, 0);
    if (t < 16) return Eigen::Vector2d(10, t - 10);
    if (t < 26) return Eigen::Vector2d(26 - t, 6);
    return Eigen::Vector2d(0, 32 - t);
  };
  RoomQueries r;
  for (int i = 0; i < points; ++i) r.points.push_back(on_wall());
  for (int i = 0; i < 10'000; ++i)
    r.queries.push_back(on_wall() + Eigen::Vector2d(noise(rng), noise(rng)));
  return r;
}
const RoomQueries& room_queries(bool submap) {
  static const RoomQueries scan = make_room_queries(720), joined = make_room_queries(9360);
  return submap ? joined : scan;
}

// Nearest within 0.5 m of each query, through `index` (a KdTree2 or a PointGrid2).
template <typename Index>
void nearest_in_room(benchmark::State& state, const RoomQueries& room, const Index& index) {
  std::size_t sum = 0;
  for (auto _ : state)
    for (const Eigen::Vector2d& q : room.queries) {
      std::size_t i = 0;
      double squared = 0.0;
      if (index.nearest(q, 0.25, i, squared)) sum += i;
    }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(room.queries.size()));
}

void BM_KdTreeNearest2D(benchmark::State& state) {
  const RoomQueries& room = room_queries(state.range(0) != 0);
  nearest_in_room(state, room, KdTree2(room.points));
}
BENCHMARK(BM_KdTreeNearest2D)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The same queries through the grid of 0.2 m cells that 2D registration pairs with.
void BM_PointGrid2Nearest(benchmark::State& state) {
  const RoomQueries& room = room_queries(state.range(0) != 0);
  nearest_in_room(state, room, PointGrid2(room.points, 0.2));
}
BENCHMARK(BM_PointGrid2Nearest)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
