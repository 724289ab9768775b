// The run loop: the engine step plus an ordered list of systems, in the
// manner of JuPedSim's simulation iterating its systems. A system acts around
// every engine step (inflow, timed events, exits, falls: the incident
// timeline) or once per output frame (the wall-passage check, writing the
// frame, reporting a GPU fallback, periodic checkpoints, progress); each is
// timed (RunLoop::SystemSeconds), may write events to the run file, and saves
// its own state in checkpoints, so that a resumed run continues exactly.
//
//   RunLoop loop(sim, options);
//   loop.Add(std::make_unique<FrameOutputSystem>(...));   // in the order they run
//   loop.Run(first_frame, last_frame);
//
// Where things go: a new per-step behaviour is a RunSystem with BeforeStep
// or AfterStep; a new per-frame output or check, one with AtFrame
// (scenario/src/run_systems.hpp has the built-in ones).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::runfile {
struct Event;
}  // namespace crowdrecon::runfile

namespace crowdrecon::scenario {

using runfile::Event;

// What a system sees at a frame.
struct FrameContext {
  engine::Simulation& sim;
  std::int64_t frame = 0;  // the frame whose steps have just run
  std::int64_t last_frame = 0;  // the run's last frame
  // Writes an event of the run (run file's event table) at this frame.
  std::function<void(const Event&)> write_event;
  // Set by a system to end the run here as interrupted (a checkpoint is then written).
  bool stop = false;
  // Set by a system to end the run here as complete, before its duration
  // (a run whose regime has settled, scenario/settle.hpp), with the reason.
  bool finish = false;
  std::string finish_reason;
};

class RunSystem {
 public:
  virtual ~RunSystem() = default;
  virtual std::string_view name() const = 0;
  // True if BeforeStep or AfterStep act: only such systems are called around
  // the engine steps (the per-frame ones cost the step loop nothing).
  virtual bool acts_every_step() const { return false; }
  // Around every engine step.
  virtual void BeforeStep(engine::Simulation&) {}
  virtual void AfterStep(engine::Simulation&) {}
  // Once per output frame, after its steps, in the order the systems were added.
  virtual void AtFrame(FrameContext&) {}
  // The system's state in a checkpoint, and given back on resume ("" if none).
  virtual std::string SaveState() const { return {}; }
  virtual void LoadState(const std::string& /*state*/) {}
};

class RunLoop {
 public:
  struct Options {
    std::int64_t steps_per_frame = 1;
    // Runs one engine step (the thread governor's or Simulation::Step).
    std::function<void(engine::Simulation&)> step;
    std::function<void(const Event&, std::int64_t frame)> write_event;
    bool IsValid(std::string* error) const;
  };
  struct Summary {
    std::int64_t last_frame = 0;  // the last frame whose systems all ran
    bool stopped = false;         // a system asked to stop before the run's end
    bool finished = false;        // a system ended the run early as complete
    std::string finish_reason;
    std::vector<std::pair<std::string, double>> system_s;  // wall seconds per system, in order
    double engine_s = 0;                                   // wall seconds in engine steps
    std::string BriefReport() const;  // "engine 3.2 s; frames 0.4 s, wall_check 0.01 s, ..."
  };

  RunLoop(engine::Simulation& sim, Options options);
  void Add(std::unique_ptr<RunSystem> system);
  // Frames first_frame + 1 .. last_frame (frame first_frame is already done).
  // Stops early when a system sets FrameContext::stop or finish (finish wins:
  // the other systems of that frame still run). Exceptions of the
  // engine or of a system propagate, with summary() up to the last frame done.
  void Run(std::int64_t first_frame, std::int64_t last_frame);
  const Summary& summary() const { return summary_; }

  // Every system's state (for a checkpoint), and back.
  std::vector<std::pair<std::string, std::string>> SaveStates() const;
  void LoadStates(const std::vector<std::pair<std::string, std::string>>& states);

 private:
  engine::Simulation& sim_;
  Options options_;
  std::vector<std::unique_ptr<RunSystem>> systems_;
  std::vector<std::size_t> step_systems_;  // indices of those that act every step
  Summary summary_;
};

}  // namespace crowdrecon::scenario
