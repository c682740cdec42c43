#pragma once
// Loop closure beside a run (map2d_run, odometry_run): fed every scan or frame in order, on its
// own thread (or inline: the same results), and what the run records of it (summary.json's
// "loop_closure": the counts by their description, mapping/loop_counts.hpp, then the run's own).

#include <cstddef>
#include <functional>
#include <type_traits>
#include <utility>

#include "scanmatch/core/background_worker.hpp"

namespace scanmatch {

/// What a run records of its loop closure.
template <typename Counts>
struct LoopClosureRecord {
  Counts counts;
  std::size_t accepted = 0;  ///< loop edges not judged outliers at the end (loops.json's)
  double ms_per_item = 0;    ///< its own time per scan or frame (on its thread or inline)
  bool thread = false;       ///< it ran on its own thread
  /// Per scan or frame, the time the run waited for it (a full queue, the end).
  double wait_ms_per_item = 0;
};

/// A LoopClosure2D or LoopClosure3D fed through a queue: `add(loop_closure, input)` runs for each
/// pushed input, on the worker thread with `own_thread`, else inside push(). push() waits while
/// the queued inputs weigh `queue` (each `weight(input)`, 1 when not given). The loop closure is
/// the worker's until finish().
template <typename LoopClosure, typename Input>
class LoopClosureRun {
 public:
  using Counts = std::remove_cvref_t<decltype(std::declval<const LoopClosure&>().counts())>;

  template <typename Options>
  LoopClosureRun(const Options& options, bool own_thread, std::size_t queue,
                 std::function<void(LoopClosure&, Input&)> add,
                 std::function<std::size_t(const Input&)> weight = {})
      : loop_closure_(options),
        add_(std::move(add)),
        worker_([this](Input& in) { add_(loop_closure_, in); }, queue, own_thread,
                std::move(weight)),
        thread_(own_thread) {}

  void push(Input input) { worker_.push(std::move(input)); }
  /// Works what is queued (also after an interruption) and optimizes once more.
  void finish() {
    worker_.finish();
    loop_closure_.finish();
  }
  const LoopClosure& loop_closure() const { return loop_closure_; }
  /// Inputs pushed and not yet taken up by its thread (0 inline): how far it has fallen behind.
  std::size_t queued() const { return worker_.queued(); }
  /// After finish(): the counts, the accepted loops and the times per scan or frame of `items`.
  LoopClosureRecord<Counts> record(std::size_t items) const {
    LoopClosureRecord<Counts> r;
    r.counts = loop_closure_.counts();
    for (const auto& loop : loop_closure_.loops()) r.accepted += !loop.outlier;
    r.thread = thread_;
    if (items > 0) {
      r.ms_per_item = r.counts.total_ms / static_cast<double>(items);
      r.wait_ms_per_item = worker_.waited_ms() / static_cast<double>(items);
    }
    return r;
  }

 private:
  LoopClosure loop_closure_;
  std::function<void(LoopClosure&, Input&)> add_;
  BackgroundWorker<Input> worker_;  ///< last: its thread ends before the rest goes
  bool thread_;
};

}  // namespace scanmatch
