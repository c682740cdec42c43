#pragma once
// Ctrl-C for the long commands: while an InterruptFlag lives, SIGINT only sets its flag, which
// the library's runs poll (RunOptions::stop, Map2DRunOptions::stop) to end after the current
// frame with their files complete; the command then exits with 130. The handler that was there
// before is restored when the object goes away, also when the run throws.

#include <atomic>
#include <csignal>

namespace scanmatch::cli {

class InterruptFlag {
 public:
  InterruptFlag();  ///< clears the flag and installs the handler
  ~InterruptFlag();
  InterruptFlag(const InterruptFlag&) = delete;
  InterruptFlag& operator=(const InterruptFlag&) = delete;

  /// Set once SIGINT arrived; for the library's `stop` options.
  const std::atomic<bool>* flag() const;

 private:
  void (*previous_)(int);
};

}  // namespace scanmatch::cli
