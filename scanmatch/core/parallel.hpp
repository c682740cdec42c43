#pragma once
// One loop over independent indices, serial for one thread and on a TBB arena of `num_threads`
// otherwise: per-point work (normals, covariances, descriptors) whose results do not depend on
// the order.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstddef>

namespace scanmatch {

/// The TBB arena of `num_threads` threads, made once and kept for the process: an arena made per
/// call costs tens of microseconds, which a registration's every iteration paid (the coarse stage
/// of a dense scan ran no faster on two threads than on one). Safe to use from several threads.
tbb::task_arena& shared_arena(int num_threads);

/// Calls body(i) for every i in [0, n); `grain` indices per task when threaded.
template <typename Body>
void for_each_index(std::size_t n, int num_threads, std::size_t grain, Body body) {
  if (num_threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
  shared_arena(num_threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i) body(i);
                      });
  });
}

}  // namespace scanmatch
