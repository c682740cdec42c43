#include "apps/interrupt.hpp"

namespace scanmatch::cli {
namespace {

// One flag for the process: a signal handler can reach nothing else. A lock-free atomic is safe
// to set from the handler.
std::atomic<bool> interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void on_interrupt(int) {
  interrupted.store(true);
}

}  // namespace

InterruptFlag::InterruptFlag() {
  interrupted.store(false);
  previous_ = std::signal(SIGINT, on_interrupt);
  if (previous_ == SIG_ERR) previous_ = SIG_DFL;
}

InterruptFlag::~InterruptFlag() {
  std::signal(SIGINT, previous_);
}

const std::atomic<bool>* InterruptFlag::flag() const {
  return &interrupted;
}

}  // namespace scanmatch::cli
