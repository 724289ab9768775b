// SIGINT and SIGTERM handled by `handler` for the life of the object, the
// previous handlers (or an inherited SIG_IGN) restored after it: a stage
// that stops cleanly on either signal (a sweep, a calibration) owns them
// while it runs, nested ones in turn.
#pragma once

#include <atomic>
#include <csignal>

namespace crowdrecon {

// The last SIGINT or SIGTERM a stage's handler received (0: none), recorded
// by the handlers (RecordStopSignal, async-signal-safe), so that a command
// stopped by one exits as the shell expects: 128 + the signal (130 after
// Ctrl-C, 143 after SIGTERM, the status `simulate` gives too).
inline std::atomic<int>& StopSignal() {
  static std::atomic<int> signal{0};
  return signal;
}
inline void RecordStopSignal(int signal) { StopSignal().store(signal); }
// The exit status of a command that stopped because it was asked to:
// 143 after SIGTERM, else 130 (SIGINT, or a stop asked for otherwise).
inline int StoppedExitStatus() { return StopSignal().load() == SIGTERM ? 128 + SIGTERM : 128 + SIGINT; }

class ScopedSignals {
 public:
  explicit ScopedSignals(void (*handler)(int))
      : int_(std::signal(SIGINT, handler)), term_(std::signal(SIGTERM, handler)) {}
  ~ScopedSignals() {
    std::signal(SIGINT, int_);
    std::signal(SIGTERM, term_);
  }
  ScopedSignals(const ScopedSignals&) = delete;
  ScopedSignals& operator=(const ScopedSignals&) = delete;

 private:
  void (*int_)(int);
  void (*term_)(int);
};

}  // namespace crowdrecon
