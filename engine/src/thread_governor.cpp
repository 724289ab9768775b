#include "crowdrecon/engine/thread_governor.hpp"

#include <algorithm>
#include <chrono>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::engine {

bool ThreadChoice::Options::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (max_threads < 1 || max_threads > 1024) return fail("max_threads = " + std::to_string(max_threads) + ", expected 1..1024");
  if (warmup_steps < 0) return fail("warmup_steps must be >= 0");
  if (probe_steps < 2) return fail("probe_steps must be >= 2 (the first step of a probe is not counted)");
  if (!(window_s > 0) || !(probe_s > 0)) return fail("window_s and probe_s must be > 0");
  if (!(probe_interval_s > 0) || !(max_probe_interval_s >= probe_interval_s))
    return fail("expected 0 < probe_interval_s <= max_probe_interval_s");
  if (!(switch_ratio > 0 && switch_ratio <= 1)) return fail("switch_ratio must be in (0, 1]");
  if (!(abandon_ratio >= 1)) return fail("abandon_ratio must be >= 1");
  return true;
}

std::string ThreadChoice::Summary::BriefReport() const {
  std::string text = std::to_string(threads) + (threads == 1 ? " thread" : " threads") + " now; " +
                     std::to_string(probes) + (probes == 1 ? " probe, " : " probes, ") + std::to_string(switches) +
                     (switches == 1 ? " switch" : " switches");
  std::string counts;
  for (std::size_t t = 1; t < steps_at.size(); ++t)
    if (steps_at[t] > 0) counts += (counts.empty() ? "" : ", ") + std::string("at ") + std::to_string(t) + ": " + std::to_string(steps_at[t]);
  if (!counts.empty()) text += "; steps " + counts;
  return text;
}

ThreadChoice::ThreadChoice(const Options& options) : options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) throw InputError("thread choice: " + error);
  threads_ = home_ = options_.max_threads;
  interval_s_ = options_.probe_interval_s;
  summary_.threads = threads_;
  summary_.steps_at.assign(static_cast<std::size_t>(options_.max_threads) + 1, 0);
}

// The counts considered are max, max/2, max/4, ..., 1; a probe tries the
// neighbour of the current count, alternating down and up where both exist.
int ThreadChoice::ProbeCandidate() const {
  const int down = home_ > 1 ? home_ / 2 : 0;
  int up = 0;
  if (home_ < options_.max_threads) {
    up = options_.max_threads;
    while (up / 2 > home_) up /= 2;
  }
  if (down > 0 && up > 0) return last_direction_ < 0 ? up : down;
  return down > 0 ? down : up;
}

void ThreadChoice::StartProbe(double now_s) {
  const int candidate = ProbeCandidate();
  if (candidate == 0) {
    next_probe_s_ = now_s + options_.max_probe_interval_s;
    return;
  }
  last_direction_ = candidate < home_ ? -1 : +1;
  probing_ = true;
  probe_taken_ = 0;
  probe_counted_s_ = 0;
  probe_spent_s_ = 0;
  threads_ = candidate;
  ++summary_.probes;
}

double ThreadChoice::ReferenceStepS() const {
  return recent_.empty() ? 0.0 : recent_sum_s_ / static_cast<double>(recent_.size());
}

void ThreadChoice::EndProbe(double now_s) {
  probing_ = false;
  const int counted = probe_taken_ - 1;
  const bool wins =
      counted > 0 && probe_counted_s_ / counted < options_.switch_ratio * ReferenceStepS();
  if (wins) {
    home_ = threads_;
    // The new count's reference: the probe's mean until its own window fills.
    recent_.assign(1, probe_counted_s_ / counted);
    recent_sum_s_ = recent_.front();
    interval_s_ = options_.probe_interval_s;
    ++summary_.switches;
  } else {
    interval_s_ = std::min(2 * interval_s_, options_.max_probe_interval_s);
  }
  threads_ = home_;
  summary_.threads = home_;
  next_probe_s_ = now_s + interval_s_;
}

void ThreadChoice::Record(double seconds, double now_s) {
  ++steps_;
  ++summary_.steps_at[static_cast<std::size_t>(threads_)];
  if (options_.max_threads == 1) return;
  if (probing_) {
    ++probe_taken_;
    if (probe_taken_ > 1) probe_counted_s_ += seconds;  // the first step wakes the threads up
    probe_spent_s_ += seconds;
    // A probe that is already far slower than the current count ends early:
    // on a busy core one step can take a whole time slice of the scheduler.
    const bool hopeless =
        probe_taken_ >= 2 && probe_spent_s_ > options_.abandon_ratio * ReferenceStepS() * probe_taken_;
    const bool done = probe_taken_ >= options_.probe_steps && probe_spent_s_ >= options_.probe_s;
    if (done || hopeless) EndProbe(now_s);
    return;
  }
  recent_.push_back(seconds);
  recent_sum_s_ += seconds;
  while (recent_.size() > 1 && recent_sum_s_ - recent_.front() >= options_.window_s) {
    recent_sum_s_ -= recent_.front();
    recent_.pop_front();
  }
  const bool window_full = recent_sum_s_ >= options_.window_s;
  if (steps_ < static_cast<std::uint64_t>(options_.warmup_steps) || !window_full) return;
  if (next_probe_s_ < 0) next_probe_s_ = now_s;  // first probe once the warm-up and a window are done
  if (now_s >= next_probe_s_) StartProbe(now_s);
}

void ThreadGovernor::Step(Simulation& sim) {
  using Clock = std::chrono::steady_clock;
  if (sim.definition().threads != choice_.threads()) sim.SetThreads(choice_.threads());
  const auto start = Clock::now();
  sim.Step();
  const auto end = Clock::now();
  choice_.Record(std::chrono::duration<double>(end - start).count(),
                 std::chrono::duration<double>(end.time_since_epoch()).count());
}

}  // namespace crowdrecon::engine
