// The timed loop of the Step benchmarks (bench_kernels.cpp on worlds built
// from scenarios, bench_device.cpp on saved worlds): one Step() per
// iteration, the state restored every kWindowSteps steps with the timer
// paused, and the counters: agent-steps per second, contacts per step, and
// the milliseconds per step of each stage of the step (Simulation::profile()).
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::bench {

inline constexpr std::int64_t kWindowSteps = 100;

inline void TimeSteps(benchmark::State& state, engine::Simulation& sim, const std::string& saved_state) {
  const auto people = static_cast<std::int64_t>(sim.bodies().size());
  std::int64_t in_window = 0;
  double contacts = 0.0;
  const engine::Profile before = sim.profile();
  for (auto _ : state) {
    if (in_window == kWindowSteps) {
      state.PauseTiming();
      sim.LoadState(saved_state);
      state.ResumeTiming();
      in_window = 0;
    }
    sim.Step();
    ++in_window;
    contacts += static_cast<double>(sim.contacts().size());
  }
  state.SetItemsProcessed(state.iterations() * people);
  const double steps = static_cast<double>(std::max<std::int64_t>(1, state.iterations()));
  state.counters["people"] = static_cast<double>(people);
  state.counters["contacts"] = contacts / steps;
  state.counters["dt_s"] = sim.time_step_s();
  // Where the time goes: milliseconds per step in each stage (Profile).
  const engine::Profile& after = sim.profile();
  const double per_step_ms = 1e3 / steps;
  for (const engine::StageInfo& stage : engine::kStages)
    state.counters[std::string(stage.name) + "_ms"] = (after.seconds(stage.stage) - before.seconds(stage.stage)) * per_step_ms;
  if (sim.definition().device == engine::ComputeDevice::kCuda) {
    // Of collide_ms: copies to and from the GPU, and its kernels.
    state.counters["device_copy_ms"] = (after.device_copy_s - before.device_copy_s) * per_step_ms;
    state.counters["device_kernels_ms"] = (after.device_kernels_s - before.device_kernels_s) * per_step_ms;
  }
}

}  // namespace crowdrecon::bench
