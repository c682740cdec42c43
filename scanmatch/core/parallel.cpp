#include "scanmatch/core/parallel.hpp"

#include <map>
#include <memory>
#include <mutex>

namespace scanmatch {

tbb::task_arena& shared_arena(int num_threads) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<tbb::task_arena>& arena = arenas[num_threads];
  if (!arena) {
    arena = std::make_unique<tbb::task_arena>(num_threads);
    arena->initialize();
  }
  return *arena;
}

}  // namespace scanmatch
