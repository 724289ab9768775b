// SIGINT and SIGTERM handled by `handler` for the life of the object, the
// previous handlers (or an inherited SIG_IGN) restored after it: a stage
// that stops cleanly on either signal (a sweep, a calibration) owns them
// while it runs, nested ones in turn.
#pragma once

#include <csignal>

namespace crowdrecon {

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
