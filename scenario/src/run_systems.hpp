// The built-in systems of the run loop (run_loop.hpp), in the order
// RunScenario adds them (runner.cpp):
//
//   wall_check      every person's centre stayed inside the walls (engine::CheckCentresStayInsideWalls)
//   frames          the frame into the run file (FrameWriterThread: on a core of its own when one is free)
//   device_fallback a GPU that failed: an event and a note, once
//   settle          ends a run whose regime has settled (run.stop_when_settled, settle.hpp)
//   checkpoint      the periodic checkpoint (run.checkpoint_interval_s)
//   stop_request    Ctrl-C, SIGTERM, a caller's flag, --stop-after: stop here (a checkpoint follows)
//   progress        the progress line on a terminal, or a line in a log now and
//                   then; the simulated time reached, for a caller (a sweep)
//
// The incident timeline's systems (inflow, exits, timed events, falls) come
// before them, acting around the engine steps.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/common/wall_clock.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "crowdrecon/scenario/run_loop.hpp"
#include "crowdrecon/scenario/settle.hpp"
#include "contact_keeper.hpp"
#include "timeline_systems.hpp"

namespace crowdrecon::scenario::detail {

// Frame `frame` into the run file; with a timeline, with its head count and
// the events since the last frame (which are then cleared).
// Which of its contacts the frame keeps, `contacts` decides.
inline void WriteTimelineFrame(runfile::FrameWriterThread& frames, const engine::Simulation& sim, std::int64_t frame,
                               ContactKeeper& contacts, TimelineState* timeline) {
  frames.Write([&](runfile::FrameSnapshot& f) {
    TakeSnapshot(sim, frame, timeline ? timeline->events : std::vector<runfile::Event>{}, true, &f);
    contacts.Decide(f);
    if (timeline) {
      f.with_census = true;
      f.census = timeline->Count(sim);
      timeline->events.clear();
    }
  });
}

// Nobody went through a wall between two frames (a safety net behind the
// engine's contact check: walls x people segment tests per frame).
class WallCheckSystem : public RunSystem {
 public:
  explicit WallCheckSystem(const engine::Simulation& sim) : centres_(sim.bodies().position_m) {
    SlotHolders(sim.bodies(), &ids_);
  }
  std::string_view name() const override { return "wall_check"; }
  void AtFrame(FrameContext& c) override {
    // A slot that changed hands since (a timeline's arrival, also into a
    // slot empty then: SlotHolders) has no path to check.
    const engine::BodyState& b = c.sim.bodies();
    for (std::size_t i = 0; i < b.size(); ++i)
      if (b.id[i] != ids_[i]) centres_[i] = b.position_m[i];
    engine::CheckCentresStayInsideWalls(c.sim, centres_);
    centres_ = b.position_m;
    SlotHolders(b, &ids_);
  }

 private:
  std::vector<Vec2> centres_;  // at the last frame (a checkpoint is taken at a frame: they are the positions then)
  std::vector<std::uint32_t> ids_;  // who held each slot then (kNoOne: empty)
};

// Writes the frame; with a timeline, also its head count and the events
// since the last frame (timeline_systems.hpp).
class FrameOutputSystem : public RunSystem {
 public:
  FrameOutputSystem(runfile::FrameWriterThread& frames, ContactKeeper& contacts, TimelineState* timeline = nullptr)
      : frames_(frames), contacts_(contacts), timeline_(timeline) {}
  std::string_view name() const override { return "frames"; }
  void AtFrame(FrameContext& c) override { WriteTimelineFrame(frames_, c.sim, c.frame, contacts_, timeline_); }
  // Which frames' contacts are kept and still to drop (run.contacts as an object).
  std::string SaveState() const override { return contacts_.SaveState(); }
  void LoadState(const std::string& state) override { contacts_.LoadState(state); }

 private:
  runfile::FrameWriterThread& frames_;
  ContactKeeper& contacts_;
  TimelineState* timeline_;
};

// The GPU failed and the processor took over (same results): say so, on the
// terminal and in the run file, once.
class DeviceFallbackSystem : public RunSystem {
 public:
  explicit DeviceFallbackSystem(bool progress_line) : progress_line_(progress_line) {}
  std::string_view name() const override { return "device_fallback"; }
  void AtFrame(FrameContext& c) override {
    if (reported_ || c.sim.device_fallback().empty()) return;
    reported_ = true;
    Event event;
    event.time_s = c.sim.time_s();
    event.kind = "device_fallback";
    event.detail = c.sim.device_fallback();
    c.write_event(event);
    std::fprintf(stderr, "%scrowdrecon: note: %s\n", progress_line_ ? "\n" : "", c.sim.device_fallback().c_str());
  }

 private:
  bool progress_line_;
  bool reported_ = false;
};

// Ends the run as complete once its regime has settled (settle.hpp): an
// event `settled` with the reason; the runner stores the reason as run value
// `settled`.
class SettleSystem : public RunSystem {
 public:
  SettleSystem(const engine::Simulation& sim, const SettleOptions& options, std::vector<std::string> group_names)
      : detector_(options, sim.bodies().group, std::move(group_names), sim.definition().periodic) {
    // Frame 0 (written before the loop starts); a resumed run replaces all
    // of this with the checkpoint's state.
    Feed(sim);
  }
  std::string_view name() const override { return "settle"; }
  void AtFrame(FrameContext& c) override {
    const std::string reason = Feed(c.sim);
    if (reason.empty()) return;
    Event event;
    event.time_s = c.sim.time_s();
    event.kind = "settled";
    event.detail = reason;
    c.write_event(event);
    c.finish = true;
    c.finish_reason = reason;
  }
  std::string SaveState() const override { return detector_.SaveState(); }
  void LoadState(const std::string& state) override { detector_.LoadState(state); }

 private:
  std::string Feed(const engine::Simulation& sim) {
    const engine::BodyState& b = sim.bodies();
    direction_.resize(b.size());
    present_.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) {
      direction_[i] = sim.definition().targets[b.target[i]].Direction(b.position_m[i]);
      present_[i] = b.state[i] != engine::PersonState::kRemoved;
    }
    PersonLoads(sim, &load_);
    return detector_.Add({sim.time_s(), &b.position_m, &b.velocity_m_per_s, &direction_, &load_, &present_});
  }

  SettleDetector detector_;
  std::vector<Vec2> direction_;
  std::vector<char> present_;
  std::vector<double> load_;
};

class CheckpointSystem : public RunSystem {
 public:
  // `write(frame)` writes the checkpoint of the run at `frame`; every `every` frames (0: never).
  CheckpointSystem(std::int64_t every, std::function<void(std::int64_t)> write) : every_(every), write_(std::move(write)) {}
  std::string_view name() const override { return "checkpoint"; }
  void AtFrame(FrameContext& c) override {
    if (every_ > 0 && c.frame % every_ == 0) write_(c.frame);
  }

 private:
  std::int64_t every_;
  std::function<void(std::int64_t)> write_;
};

class StopRequestSystem : public RunSystem {
 public:
  StopRequestSystem(const std::atomic<bool>& signal, const std::atomic<bool>* flag, double stop_after_s)
      : signal_(signal), flag_(flag), stop_after_s_(stop_after_s) {}
  std::string_view name() const override { return "stop_request"; }
  void AtFrame(FrameContext& c) override {
    c.stop = signal_.load() || (flag_ && flag_->load()) || (stop_after_s_ >= 0 && c.sim.time_s() >= stop_after_s_ - 1e-9);
  }

 private:
  const std::atomic<bool>& signal_;
  const std::atomic<bool>* flag_;
  double stop_after_s_;
};

// Simulated time, real-time factor and time left, twice a second (and at a
// stop and at the end), on stderr.
class ProgressSystem : public RunSystem {
 public:
  struct Options {
    double duration_s = 0.0;     // the run's end
    double start_sim_s = 0.0;    // where this invocation began (a resumed run's checkpoint)
    bool terminal = false;       // a line rewritten in place every half second
    double log_every_s = 0.0;    // > 0 (and no terminal line): a line of its own this often (wall s)
    std::atomic<double>* simulated_s = nullptr;  // if set: the simulated time, at every frame
  };
  explicit ProgressSystem(const Options& options) : options_(options) {}
  std::string_view name() const override { return "progress"; }
  void AtFrame(FrameContext& c) override {
    if (options_.simulated_s) options_.simulated_s->store(c.sim.time_s(), std::memory_order_relaxed);
    const auto now = Clock::now();
    const bool last = c.stop || c.frame == c.last_frame;
    if (options_.terminal) {
      if (!(now - last_print_ > std::chrono::milliseconds(500) || last)) return;
    } else if (options_.log_every_s > 0) {
      // A log gets no line at the end: the run's summary follows.
      if (!(std::chrono::duration<double>(now - last_print_).count() >= options_.log_every_s) || last) return;
    } else {
      return;
    }
    last_print_ = now;
    const double wall = std::chrono::duration<double>(now - start_).count();
    const double rtf = wall > 0 ? (c.sim.time_s() - options_.start_sim_s) / wall : 0.0;
    const double left = rtf > 0 ? (options_.duration_s - c.sim.time_s()) / rtf : std::numeric_limits<double>::infinity();
    if (options_.terminal) {
      std::fprintf(stderr, "\r  t = %.1f / %.1f s   real-time factor %.3f   time left %s      ", c.sim.time_s(),
                   options_.duration_s, rtf, FormatDuration(left).c_str());
    } else {
      std::fprintf(stderr, "  %s  t = %.1f / %.1f s, real-time factor %.3f, time left %s\n", WallClockNow().c_str(),
                   c.sim.time_s(), options_.duration_s, rtf, FormatDuration(left).c_str());
    }
    std::fflush(stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;
  Options options_;
  Clock::time_point start_ = Clock::now(), last_print_ = Clock::now();
};

}  // namespace crowdrecon::scenario::detail
