#include "crowdrecon/scenario/run_loop.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::scenario {

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

bool RunLoop::Options::IsValid(std::string* error) const {
  if (steps_per_frame < 1) {
    if (error) *error = "steps_per_frame = " + std::to_string(steps_per_frame) + ", expected >= 1";
    return false;
  }
  if (!step || !write_event) {
    if (error) *error = "step and write_event must be set";
    return false;
  }
  return true;
}

std::string RunLoop::Summary::BriefReport() const {
  char text[64];
  std::snprintf(text, sizeof text, "engine %.2f s", engine_s);
  std::string report = text;
  for (std::size_t k = 0; k < system_s.size(); ++k) {
    std::snprintf(text, sizeof text, "%s%s %.3f s", k == 0 ? "; " : ", ", system_s[k].first.c_str(), system_s[k].second);
    report += text;
  }
  return report;
}

RunLoop::RunLoop(engine::Simulation& sim, Options options) : sim_(sim), options_(std::move(options)) {
  std::string error;
  if (!options_.IsValid(&error)) throw std::logic_error("RunLoop: " + error);
}

void RunLoop::Add(std::unique_ptr<RunSystem> system) {
  summary_.system_s.emplace_back(std::string(system->name()), 0.0);
  if (system->acts_every_step()) step_systems_.push_back(systems_.size());
  systems_.push_back(std::move(system));
}

void RunLoop::Run(std::int64_t first_frame, std::int64_t last_frame) {
  summary_.last_frame = first_frame;
  summary_.stopped = false;
  summary_.finished = false;
  for (std::int64_t frame = first_frame + 1; frame <= last_frame; ++frame) {
    // The frame's engine steps, with the per-step systems around each. The
    // engine's time is the frame's less theirs (two clock readings a frame
    // when no system acts every step).
    const auto steps_start = Clock::now();
    double step_systems_s = 0.0;
    const auto run_step_systems = [&](void (RunSystem::*call)(engine::Simulation&)) {
      for (std::size_t s : step_systems_) {
        const auto start = Clock::now();
        (systems_[s].get()->*call)(sim_);
        const double spent = Since(start);
        summary_.system_s[s].second += spent;
        step_systems_s += spent;
      }
    };
    // steps_per_frame fixed steps: with the adaptive step, fewer and longer
    // ones, which land on the frame (the runner makes frames a multiple of
    // the largest step).
    const std::uint64_t frame_end = sim_.tick_count() + static_cast<std::uint64_t>(options_.steps_per_frame);
    while (sim_.tick_count() < frame_end) {
      run_step_systems(&RunSystem::BeforeStep);
      options_.step(sim_);
      run_step_systems(&RunSystem::AfterStep);
    }
    if (sim_.tick_count() != frame_end)
      throw std::logic_error("internal error: a step of the adaptive step straddled frame " + std::to_string(frame));
    summary_.engine_s += Since(steps_start) - step_systems_s;
    // The per-frame systems, in order.
    FrameContext context{sim_, frame, last_frame,
                         [&](const Event& event) { options_.write_event(event, frame); }, false, false, {}};
    for (std::size_t s = 0; s < systems_.size(); ++s) {
      const auto start = Clock::now();
      systems_[s]->AtFrame(context);
      summary_.system_s[s].second += Since(start);
    }
    summary_.last_frame = frame;
    if (context.finish && frame < last_frame) {
      summary_.finished = true;
      summary_.finish_reason = context.finish_reason;
      return;
    }
    if (context.stop && frame < last_frame) {
      summary_.stopped = true;
      return;
    }
  }
}

std::vector<std::pair<std::string, std::string>> RunLoop::SaveStates() const {
  std::vector<std::pair<std::string, std::string>> states;
  for (const auto& system : systems_) states.emplace_back(std::string(system->name()), system->SaveState());
  return states;
}

void RunLoop::LoadStates(const std::vector<std::pair<std::string, std::string>>& states) {
  for (const auto& [name, state] : states) {
    bool found = false;
    for (const auto& system : systems_) {
      if (system->name() != name) continue;
      system->LoadState(state);
      found = true;
    }
    if (!found) throw InputError("the checkpoint holds the state of a system \"" + name + "\" that this run does not have");
  }
}

}  // namespace crowdrecon::scenario
