// BackgroundWorker (core/background_worker.hpp): items are worked in the order pushed, on one
// thread, a full queue holds the caller back, and the work's exception reaches the caller.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "scanmatch/core/background_worker.hpp"

namespace scanmatch {
namespace {

TEST(BackgroundWorker, WorksEveryItemInOrderOnOneOtherThread) {
  for (const bool background : {true, false}) {
    std::vector<int> seen;
    std::vector<std::thread::id> threads;
    BackgroundWorker<int> worker(
        [&](int& i) {
          seen.push_back(i);
          threads.push_back(std::this_thread::get_id());
        },
        4, background);
    for (int i = 0; i < 1000; ++i) worker.push(i);
    worker.finish();
    ASSERT_EQ(seen.size(), 1000u) << background;
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], i);
    for (const std::thread::id& id : threads) {
      EXPECT_EQ(id, threads.front());
      EXPECT_EQ(id == std::this_thread::get_id(), !background);
    }
  }
}

// Work that holds every item until released, counting the items done.
struct GatedWork {
  std::atomic<bool> release{false};
  std::atomic<int> done{0};
  auto work() {
    return [this](int&) {
      while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      ++done;
    };
  }
};

// Pushes `item` from another thread while the work is held and looks 50 ms later: was the push
// still waiting, and how many items were done by then. Then releases the work and finishes.
struct HeldPush {
  bool waited = false;
  int done_meanwhile = 0;
};
HeldPush push_while_held(BackgroundWorker<int>& worker, GatedWork& gate, int item) {
  std::atomic<bool> pushed{false};
  std::thread caller([&] {
    worker.push(item);
    pushed = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const HeldPush held{!pushed.load(), gate.done.load()};
  gate.release = true;
  caller.join();
  worker.finish();
  EXPECT_TRUE(pushed.load());
  return held;
}

TEST(BackgroundWorker, AFullQueueHoldsTheCallerBack) {
  GatedWork gate;
  BackgroundWorker<int> worker(gate.work(), 2);
  // One item in the work, two queued: the fourth push waits until the work goes on.
  for (int i = 0; i < 3; ++i) worker.push(i);
  const HeldPush held = push_while_held(worker, gate, 3);
  EXPECT_TRUE(held.waited);
  EXPECT_EQ(held.done_meanwhile, 0);
  EXPECT_EQ(gate.done.load(), 4);
  EXPECT_GT(worker.waited_ms(), 0.0);
}

TEST(BackgroundWorker, TheQueueIsBoundedByWeightAndTakesAHeavyItemWhenEmpty) {
  // Items weigh their value; the queue holds 10. A heavier item still goes into an empty queue
  // (nothing would ever make room for it), lighter ones queue until 10 and the next one waits.
  GatedWork gate;
  BackgroundWorker<int> worker(gate.work(), 10, true,
                               [](const int& i) { return static_cast<std::size_t>(i); });
  worker.push(100);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the worker holds it
  for (int i = 0; i < 3; ++i) worker.push(3);                  // 9 of 10 queued
  EXPECT_TRUE(push_while_held(worker, gate, 3).waited);
  EXPECT_EQ(gate.done.load(), 5);
}

TEST(BackgroundWorker, TheWorksExceptionReachesTheCaller) {
  BackgroundWorker<int> worker([](int& i) {
    if (i == 5) throw std::runtime_error("item 5 is bad");
  });
  bool thrown = false;
  try {
    for (int i = 0; i < 100000 && !thrown; ++i) worker.push(i);
    worker.finish();
  } catch (const std::runtime_error& e) {
    thrown = true;
    EXPECT_STREQ(e.what(), "item 5 is bad");
  }
  EXPECT_TRUE(thrown);
}

TEST(BackgroundWorker, DestroyedUnfinishedItDropsTheQueueAndJoins) {
  std::atomic<int> done{0};
  {
    BackgroundWorker<int> worker([&](int&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      ++done;
    });
    for (int i = 0; i < 1000; ++i) worker.push(i);
  }  // as when an exception unwinds the caller: no finish()
  EXPECT_LT(done.load(), 1000);
}

TEST(BackgroundWorker, QueuedCountsWhatTheThreadHasNotTakenUp) {
  GatedWork gate;
  BackgroundWorker<int> worker(gate.work());
  for (int i = 0; i < 3; ++i) worker.push(i);
  // The thread takes the first item up and holds it; the other two wait in the queue.
  for (int wait = 0; wait < 2000 && worker.queued() != 2; ++wait)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(worker.queued(), 2u);
  EXPECT_EQ(gate.done.load(), 0);
  gate.release = true;
  worker.finish();
  EXPECT_EQ(worker.queued(), 0u);
  EXPECT_EQ(gate.done.load(), 3);
  int inline_done = 0;
  BackgroundWorker<int> inline_worker([&](int&) { ++inline_done; }, 0, false);
  inline_worker.push(1);
  EXPECT_EQ(inline_worker.queued(), 0u);
  EXPECT_EQ(inline_done, 1);
}

}  // namespace
}  // namespace scanmatch
