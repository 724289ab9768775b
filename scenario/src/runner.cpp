#include "crowdrecon/scenario/runner.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/thread_governor.hpp"
#include "crowdrecon/scenario/run_file.hpp"
#include "crowdrecon/scenario/world_builder.hpp"

namespace crowdrecon::scenario {

namespace {

std::atomic<bool> g_stop_requested{false};

extern "C" void OnInterrupt(int) { g_stop_requested.store(true); }

// FNV-1a of the scenario text and thread-independent settings: a checkpoint
// only resumes the run it was written for.
std::uint64_t ScenarioFingerprint(const Scenario& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s.json_text) h = (h ^ c) * 1099511628211ull;
  return h;
}

constexpr char kCheckpointMagic[8] = {'C', 'R', 'C', 'H', 'E', 'C', 'K', '1'};

void WriteCheckpoint(const std::filesystem::path& file, std::uint64_t fingerprint, std::int64_t last_frame,
                     const engine::Simulation& sim) {
  const std::string state = sim.SaveState();
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(tmp.string() + ": cannot write checkpoint");
    out.write(kCheckpointMagic, sizeof kCheckpointMagic);
    out.write(reinterpret_cast<const char*>(&fingerprint), sizeof fingerprint);
    out.write(reinterpret_cast<const char*>(&last_frame), sizeof last_frame);
    out.write(state.data(), static_cast<std::streamsize>(state.size()));
    out.flush();
    if (!out) throw InputError(tmp.string() + ": cannot write checkpoint (disk full?)");
  }
  std::filesystem::rename(tmp, file);  // atomic: a crash never leaves a half-written checkpoint
}

struct Checkpoint {
  std::int64_t last_frame = -1;
  std::string state;
};

Checkpoint ReadCheckpoint(const std::filesystem::path& file, std::uint64_t fingerprint) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read the checkpoint");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string data = buffer.str();
  const std::size_t header = sizeof kCheckpointMagic + 16;
  if (data.size() < header || data.compare(0, sizeof kCheckpointMagic, kCheckpointMagic, sizeof kCheckpointMagic) != 0)
    throw InputError(file.string() + ": not a crowdrecon checkpoint");
  std::uint64_t stored;
  Checkpoint c;
  std::memcpy(&stored, data.data() + 8, 8);
  std::memcpy(&c.last_frame, data.data() + 16, 8);
  if (stored != fingerprint)
    throw InputError(file.string() + ": the checkpoint belongs to a different scenario (the scenario file changed?)");
  c.state = data.substr(header);
  return c;
}

// A user's step longer than the engine's own (time_step_safety of the
// stability limit) is stable but less accurate: collisions rebound with a
// restitution off by more than the 2 % the engine's step keeps, and results
// change with the step. Empty when the step is the engine's or shorter.
std::string TimeStepWarning(const Scenario& scenario, const engine::WorldDef& world,
                            const engine::TimeStepEstimate& estimate) {
  const double h = world.parameters.time_step_s;
  if (!(scenario.model.time_step_s > 0.0) || !(h > estimate.accurate_s * (1.0 + 1e-9))) return "";
  const double error = engine::RestitutionErrorAtStep(world, h);
  return scenario.file.string() + ": /model/time_step_s: the step " + FormatNumber(h) + " s is " +
         FormatNumber(h / estimate.accurate_s) + " times the engine's accurate step " + FormatNumber(estimate.accurate_s) +
         " s (stability limit " + FormatNumber(estimate.stability_limit_s) +
         " s): collisions then rebound with a restitution off by up to " + FormatNumber(100.0 * error) +
         " % (measured on a head-on collision in the stiffest contact mode, against about 2 % at the engine's step), and "
         "results change with the step; give 0 to let the engine choose";
}

// Why a run without a checkpoint cannot be resumed, or "" if it can be
// started again from the beginning: the run file is ours, was written for
// this scenario and is unfinished (the run stopped before its first
// checkpoint, which gives the same result as starting it again).
std::string NothingToResume(const std::filesystem::path& run_file, const Scenario& scenario) {
  const std::string file = run_file.string();
  std::error_code ec;
  if (!std::filesystem::exists(run_file, ec))
    return file + ": nothing to resume: the run file does not exist; start the run without --resume";
  if (!IsRunFile(run_file))
    return file + ": nothing to resume: it is " + DescribeExisting(run_file) + ", not a crowdrecon run file";
  const RunFileReader reader(run_file);
  if (reader.RunValue("scenario") != scenario.json_text)
    return file + ": nothing to resume: the run file was written for a different scenario (" +
           reader.RunValue("scenario_file") + ", or the scenario file changed); start the run without --resume";
  const std::string status = reader.RunValue("status");
  if (status == "complete")
    return file + ": nothing to resume: the run is complete; run without --resume to run it again";
  if (status.rfind("failed", 0) == 0)
    return file + ": nothing to resume: the run " + status + " (its state is in " + file + ".failed-state)";
  return "";
}

}  // namespace

std::filesystem::path CheckpointPath(const std::filesystem::path& run_file) {
  return run_file.string() + ".checkpoint";
}

void InstallInterruptHandlers() {
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
}

RunSummary RunScenario(const Scenario& scenario, const RunOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto say = [&](const std::string& line) {
    if (options.show_progress) std::fprintf(stderr, "%s\n", line.c_str());
  };
  g_stop_requested.store(false);
  BuiltWorld built = BuildWorld(scenario, options.threads, say);

  // An integer number of steps per output frame, so that frames are exactly
  // 1/fps apart (the frame rate JuPedSim's format declares): the chosen step
  // is shortened, never lengthened.
  const double frame_dt = 1.0 / scenario.run.output_fps;
  std::string step_warning;
  {
    const engine::TimeStepEstimate estimate = engine::EstimateTimeStep(built.world);
    if (scenario.model.time_step_s > estimate.stability_limit_s)
      throw InputError(scenario.file.string() + ": /model/time_step_s: " + FormatNumber(scenario.model.time_step_s) +
                       " s is above the stability limit of the " + engine::ToString(scenario.model.integrator) +
                       " integrator for these bodies, " + FormatNumber(estimate.stability_limit_s) +
                       " s (omega_max = " + FormatNumber(estimate.omega_max_rad_per_s) + " rad/s, set by /model/" +
                       estimate.limited_by + "); give a smaller step, or 0 to let the engine choose");
    const double steps = std::ceil(frame_dt / estimate.chosen_s - 1e-9);
    built.world.parameters.time_step_s = frame_dt / steps;
    step_warning = TimeStepWarning(scenario, built.world, estimate);
  }
  const auto steps_per_frame = static_cast<std::int64_t>(std::llround(frame_dt / built.world.parameters.time_step_s));
  built.world.device = options.device;
  engine::Simulation sim(built.world);

  RunHeader header;
  header.scenario_json = scenario.json_text;
  header.scenario_origin = scenario.file.string();
  header.walkable_wkt = built.walkable_wkt;
  header.output_fps = scenario.run.output_fps;
  header.time_step_s = sim.time_step_s();
  header.seed = scenario.population.seed;
  header.target_names = built.target_names;

  const std::uint64_t fingerprint = ScenarioFingerprint(scenario);
  const std::filesystem::path checkpoint = CheckpointPath(options.output);
  std::int64_t last_frame = -1;
  RunFileWriter writer = [&] {
    std::error_code ec;
    if (options.resume && !std::filesystem::exists(checkpoint, ec)) {
      const std::string why = NothingToResume(options.output, scenario);
      if (!why.empty()) throw InputError(why);
      std::fprintf(stderr, "crowdrecon: note: %s has no checkpoint yet (the run stopped before its first one); "
                   "starting it again from the beginning\n", options.output.string().c_str());
    } else if (options.resume) {
      const Checkpoint c = ReadCheckpoint(checkpoint, fingerprint);
      sim.LoadState(c.state);
      last_frame = c.last_frame;
      say("resuming at t = " + FormatNumber(sim.time_s()) + " s (frame " + std::to_string(last_frame) + ")");
      return RunFileWriter::Resume(options.output, last_frame);
    }
    std::filesystem::remove(checkpoint, ec);
    return RunFileWriter::Create(options.output, header, sim);
  }();
  writer.SetRunValue("people", std::to_string(sim.bodies().size()));
  writer.SetRunValue("max_initial_overlap_m", FormatNumber(built.max_initial_overlap_m));
  if (!step_warning.empty()) {
    writer.SetRunValue("time_step_warning", step_warning);
    std::fprintf(stderr, "crowdrecon: warning: %s\n", step_warning.c_str());
  }

  const std::int64_t total_frames = static_cast<std::int64_t>(std::floor(scenario.run.duration_s * scenario.run.output_fps + 1e-9));
  const std::int64_t checkpoint_every =
      scenario.run.checkpoint_interval_s > 0
          ? std::max<std::int64_t>(1, std::llround(scenario.run.checkpoint_interval_s * scenario.run.output_fps))
          : 0;
  RunSummary summary;
  summary.people = sim.bodies().size();
  summary.time_step_s = sim.time_step_s();
  const auto start = Clock::now();
  const double start_sim = sim.time_s();
  auto last_print = start;

  // Frames are written by a thread of their own while the next ones are
  // simulated, if the engine leaves a core free (see FrameWriterThread);
  // everything that must follow the frames in the file (a checkpoint naming
  // the last frame, an event, the status) waits for them with Flush.
  const bool core_free = static_cast<unsigned>(std::max(1, options.threads)) < std::thread::hardware_concurrency();
  FrameWriterThread frames(writer, core_free);
  const auto write_frame = [&](std::int64_t frame) {
    frames.Write(frame, sim, {}, scenario.run.write_contacts);
    last_frame = frame;
  };
  const auto checkpoint_now = [&](const std::filesystem::path& file) {
    frames.Flush();
    WriteCheckpoint(file, fingerprint, last_frame, sim);
  };
  if (last_frame < 0) write_frame(0);

  engine::ThreadChoice::Options thread_options;
  thread_options.max_threads = sim.definition().threads;
  engine::ThreadGovernor governor(thread_options);
  const bool adapt_threads = options.adapt_threads && thread_options.max_threads > 1;
  std::string status = "complete";
  bool device_fallback_reported = false;
  try {
    std::vector<Vec2> centres = sim.bodies().position_m;
    while (last_frame < total_frames) {
      for (std::int64_t k = 0; k < steps_per_frame; ++k) {
        if (adapt_threads) governor.Step(sim);
        else sim.Step();
      }
      engine::CheckCentresStayInsideWalls(sim, centres);  // nobody went through a wall
      centres = sim.bodies().position_m;
      write_frame(last_frame + 1);
      if (!device_fallback_reported && !sim.device_fallback().empty()) {
        // The GPU failed and the processor took over (same results): say so,
        // on the terminal and in the run file, once.
        device_fallback_reported = true;
        frames.Flush();
        Event event;
        event.time_s = sim.time_s();
        event.kind = "device_fallback";
        event.detail = sim.device_fallback();
        writer.WriteEvent(last_frame, event);
        std::fprintf(stderr, "%scrowdrecon: note: %s\n", options.show_progress ? "\n" : "", sim.device_fallback().c_str());
      }
      if (checkpoint_every > 0 && last_frame % checkpoint_every == 0) checkpoint_now(checkpoint);
      const bool stop = g_stop_requested.load() || (options.stop_flag && options.stop_flag->load()) ||
                        (options.stop_after_s >= 0 && sim.time_s() >= options.stop_after_s - 1e-9);
      const auto now = Clock::now();
      if (options.show_progress && (now - last_print > std::chrono::milliseconds(500) || stop || last_frame == total_frames)) {
        last_print = now;
        const double wall = std::chrono::duration<double>(now - start).count();
        const double rtf = wall > 0 ? (sim.time_s() - start_sim) / wall : 0.0;
        const double left = rtf > 0 ? (scenario.run.duration_s - sim.time_s()) / rtf : std::numeric_limits<double>::infinity();
        std::fprintf(stderr, "\r  t = %.1f / %.1f s   real-time factor %.3f   time left %s      ", sim.time_s(),
                     scenario.run.duration_s, rtf, FormatDuration(left).c_str());
        std::fflush(stderr);
      }
      if (stop && last_frame < total_frames) {
        checkpoint_now(checkpoint);
        status = "interrupted";
        break;
      }
    }
  } catch (const engine::SimulationError& e) {
    // Save the state in which the run failed, next to the run file, and say so.
    const std::filesystem::path failed = options.output.string() + ".failed-state";
    checkpoint_now(failed);
    Event event;
    event.time_s = sim.time_s();
    event.kind = "numerical_failure";
    event.person = e.person();
    event.other = e.other();
    event.detail = e.what();
    writer.WriteEvent(last_frame, event);
    writer.SetStatus(std::string("failed: ") + e.what());
    if (options.show_progress) std::fprintf(stderr, "\n");
    throw InputError(options.output.string() + ": the run went numerically wrong: " + e.what() +
                     "; frames up to " + std::to_string(last_frame) + " are in the run file and the state is saved in " +
                     failed.string());
  }
  frames.Flush();
  if (options.show_progress) std::fprintf(stderr, "\n");
  writer.SetStatus(status);
  if (status == "complete") {
    std::error_code ec;
    std::filesystem::remove(checkpoint, ec);
  }
  summary.status = status;
  summary.simulated_s = sim.time_s();
  summary.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  summary.real_time_factor = summary.wall_s > 0 ? (sim.time_s() - start_sim) / summary.wall_s : 0.0;
  summary.frames = last_frame + 1;
  summary.profile = sim.profile();
  summary.device_fallback = sim.device_fallback();
  if (adapt_threads) summary.threads_report = governor.summary().BriefReport();
  return summary;
}

}  // namespace crowdrecon::scenario
