#pragma once
// Work done on one background thread, item by item in the order pushed, while the caller goes on:
// loop closure beside the odometry. One thread and one order, so the results are those of doing
// the work inline, whatever the timing.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "scanmatch/core/stopwatch.hpp"

namespace scanmatch {

template <typename Item>
class BackgroundWorker {
 public:
  /// `work` runs on the worker thread for each pushed item. push() waits while the queued items
  /// weigh `capacity` (0: never; each weighs `weight(item)`, 1 when not given), so a worker slower
  /// than the caller holds it back instead of queueing the whole input; an item is always taken
  /// into an empty queue. With `background` false the work runs inside push() (no thread).
  explicit BackgroundWorker(std::function<void(Item&)> work, std::size_t capacity = 0,
                            bool background = true,
                            std::function<std::size_t(const Item&)> weight = {})
      : work_(std::move(work)),
        weight_(std::move(weight)),
        capacity_(capacity),
        background_(background) {
    if (background_) thread_ = std::thread([this] { run(); });
  }
  /// Drops what is still queued and joins (an exception is unwinding the caller).
  ~BackgroundWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.clear();
      queued_weight_ = 0;
      closing_ = true;
    }
    ready_.notify_all();
    space_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  BackgroundWorker(const BackgroundWorker&) = delete;
  BackgroundWorker& operator=(const BackgroundWorker&) = delete;

  /// Queues an item; rethrows an exception the work threw on an earlier item.
  void push(Item item) {
    if (!background_) {
      work_(item);
      return;
    }
    const std::size_t weight = weight_ ? weight_(item) : 1;
    const Stopwatch waiting;
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] {
      return error_ || capacity_ == 0 || queue_.empty() || queued_weight_ + weight <= capacity_;
    });
    waited_ms_ += waiting.ms();
    if (error_) std::rethrow_exception(error_);
    queued_weight_ += weight;
    queue_.push_back({std::move(item), weight});
    lock.unlock();
    ready_.notify_one();
  }

  /// Waits until every queued item is done and ends the thread; rethrows the work's exception.
  /// Call once, after the last push().
  void finish() {
    if (!background_) return;
    const Stopwatch waiting;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
    }
    ready_.notify_all();
    if (thread_.joinable()) thread_.join();
    waited_ms_ += waiting.ms();
    if (error_) std::rethrow_exception(error_);
  }

  /// Time push() and finish() spent waiting for the worker, ms: what the work added to the
  /// caller's time.
  double waited_ms() const { return waited_ms_; }
  /// Items pushed and not yet taken up by the worker (0 without a thread).
  std::size_t queued() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return queue_.size();
  }

 private:
  void run() {
    for (;;) {
      Item item;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [&] { return closing_ || !queue_.empty(); });
        if (queue_.empty()) return;  // closing and drained
        item = std::move(queue_.front().item);
        queued_weight_ -= queue_.front().weight;
        queue_.pop_front();
      }
      space_.notify_one();
      try {
        work_(item);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
        queue_.clear();
        queued_weight_ = 0;
        space_.notify_all();
        return;
      }
    }
  }

  struct Queued {
    Item item;
    std::size_t weight;
  };

  std::function<void(Item&)> work_;
  std::function<std::size_t(const Item&)> weight_;
  std::size_t capacity_;
  bool background_;
  mutable std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<Queued> queue_;
  std::size_t queued_weight_ = 0;
  bool closing_ = false;
  std::exception_ptr error_;
  double waited_ms_ = 0.0;
  std::thread thread_;
};

}  // namespace scanmatch
