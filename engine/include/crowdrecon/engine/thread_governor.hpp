// ThreadGovernor: keeps a Simulation on the number of worker threads that is
// fastest on the machine as it is now.
//
// Why: the engine's stages meet at barriers several times a step. On a machine
// where another process keeps a core busy, a worker thread that shares that
// core runs only in the scheduler's time slices, and every barrier waits for
// it: two threads were measured 14x (once 170x) slower than one on a 2-core
// machine with one busy core. The number of threads never changes a result
// (every stage splits its work in a fixed way and sums in a fixed order), so
// the count can change between any two steps. The governor times every step,
// now and then tries a neighbouring count for a few steps (a probe), and keeps
// whichever is faster. A probe that loses waits twice as long before the next
// one (up to a stated maximum), so a machine that stays busy costs little, and
// a machine that becomes idle again gets its threads back.
//
//   ThreadGovernor governor(ThreadGovernor::Options{.max_threads = 2});
//   while (...) governor.Step(sim);       // instead of sim.Step()
//   std::puts(governor.summary().BriefReport().c_str());
//
// The decisions (ThreadChoice) depend on measured step times only, and are
// kept apart from the clock so that tests can drive them with given times.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace crowdrecon::engine {

class Simulation;

// The decision rule, fed with the duration of every step.
class ThreadChoice {
 public:
  struct Options {
    int max_threads = 1;               // the count asked for; never exceeded
    int warmup_steps = 16;             // steps before the first probe (first steps are untypical)
    // A busy core shows as the scheduler's time slices (milliseconds), not in
    // every step: steps are compared by their mean over stated wall times, long
    // enough to hold several slices, never by a median (which hides the stalls).
    double window_s = 0.1;             // recent wall time at the current count that forms its reference
    double probe_s = 0.05;             // wall time a probe lasts (at least probe_steps steps)
    int probe_steps = 8;               // steps a probe lasts at least (its first is not counted: wake-up)
    // Wall time between probes, at first and after a switch. Short, so that a
    // first probe spoiled by a scheduler stall is retried within a second, not
    // after seconds at the slow count; a probe that loses doubles it.
    double probe_interval_s = 0.25;
    double max_probe_interval_s = 60.0;  // after losing probes the interval doubles up to this
    double switch_ratio = 0.9;         // switch when the other count's mean step < ratio x the current's
    double abandon_ratio = 4.0;        // end a probe early once it has taken this x the current's time for as many steps
    bool IsValid(std::string* error) const;
  };

  struct Summary {
    int threads = 1;                     // count in use now
    std::uint64_t probes = 0;            // probes run
    std::uint64_t switches = 0;          // probes won (count changed)
    std::vector<std::uint64_t> steps_at; // steps run at each count, index = threads (0 unused)
    std::string BriefReport() const;     // "2 threads now; 3 probes, 1 switch; steps at 1: 100, at 2: 900"
  };

  explicit ThreadChoice(const Options& options);

  // Threads for the next step.
  int threads() const { return threads_; }
  // Records the step just run with threads() threads that took `seconds` and
  // ended at wall time `now_s` (any monotonic clock); may change threads().
  void Record(double seconds, double now_s);
  const Summary& summary() const { return summary_; }

 private:
  double ReferenceStepS() const;
  void StartProbe(double now_s);
  void EndProbe(double now_s);
  int ProbeCandidate() const;

  Options options_;
  int threads_ = 1;
  int home_ = 1;                      // count outside a probe
  bool probing_ = false;
  int probe_taken_ = 0;               // steps of the current probe so far
  double probe_counted_s_ = 0;        // its steps' time, the first (wake-up) left out
  double probe_spent_s_ = 0;          // all its steps' time, the first included
  std::deque<double> recent_;         // step times at home_ over the last window_s
  double recent_sum_s_ = 0;
  std::uint64_t steps_ = 0;
  double interval_s_ = 0;
  double next_probe_s_ = -1;          // < 0: not yet scheduled
  int last_direction_ = -1;           // -1: last probe went down, +1: up
  Summary summary_;
};

// Runs Simulation::Step with the count ThreadChoice picks, timing each step
// with a steady clock.
class ThreadGovernor {
 public:
  explicit ThreadGovernor(const ThreadChoice::Options& options) : choice_(options) {}
  void Step(Simulation& sim);
  const ThreadChoice::Summary& summary() const { return choice_.summary(); }

 private:
  ThreadChoice choice_;
};

}  // namespace crowdrecon::engine
