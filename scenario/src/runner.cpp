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

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/thread_governor.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "crowdrecon/scenario/run_loop.hpp"
#include "crowdrecon/scenario/world_builder.hpp"
#include "premovement.hpp"
#include "run_systems.hpp"
#include "crowdrecon/engine/parameter_table.hpp"

namespace crowdrecon::scenario {

namespace {

std::atomic<bool> g_stop_requested{false};

std::atomic<int> g_interrupt_signal{0};

extern "C" void OnInterrupt(int signal) {
  g_interrupt_signal.store(signal);
  g_stop_requested.store(true);
}

// FNV-1a of the scenario text: a checkpoint only resumes the run it was
// written for.
std::uint64_t TextFingerprint(const std::string& json_text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : json_text) h = (h ^ c) * 1099511628211ull;
  return h;
}
std::uint64_t ScenarioFingerprint(const Scenario& s) { return TextFingerprint(s.json_text); }

// Checkpoint: magic, the scenario's fingerprint, the last frame written, the
// engine's state (Simulation::SaveState), then each run-loop system's state
// (count; per system its name and state, each as a length and bytes).
// Version 1 (no system states) is still read.
constexpr char kCheckpointMagic[8] = {'C', 'R', 'C', 'H', 'E', 'C', 'K', '2'};
constexpr char kCheckpointMagicV1[8] = {'C', 'R', 'C', 'H', 'E', 'C', 'K', '1'};

// The run value that keeps a run's wall time over all its invocations.
constexpr char kWallSecondsKey[] = "wall_s";

struct Checkpoint {
  std::int64_t last_frame = -1;
  std::string state;
  std::vector<std::pair<std::string, std::string>> systems;
};

void PutBytes(std::string& out, const std::string& bytes) {
  const std::uint64_t n = bytes.size();
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out += bytes;
}

void WriteCheckpoint(const std::filesystem::path& file, std::uint64_t fingerprint, const Checkpoint& c) {
  std::string data(kCheckpointMagic, sizeof kCheckpointMagic);
  data.append(reinterpret_cast<const char*>(&fingerprint), sizeof fingerprint);
  data.append(reinterpret_cast<const char*>(&c.last_frame), sizeof c.last_frame);
  PutBytes(data, c.state);
  const std::uint64_t count = c.systems.size();
  data.append(reinterpret_cast<const char*>(&count), sizeof count);
  for (const auto& [name, state] : c.systems) {
    PutBytes(data, name);
    PutBytes(data, state);
  }
  const std::filesystem::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(tmp.string() + ": cannot write checkpoint");
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
    out.flush();
    if (!out) throw InputError(tmp.string() + ": cannot write checkpoint (disk full?)");
  }
  std::filesystem::rename(tmp, file);  // atomic: a crash never leaves a half-written checkpoint
}

Checkpoint ReadCheckpoint(const std::filesystem::path& file, std::uint64_t fingerprint) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read the checkpoint");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string data = buffer.str();
  const std::size_t header = sizeof kCheckpointMagic + 16;
  const auto magic_is = [&](const char* magic) {
    return data.size() >= header && data.compare(0, sizeof kCheckpointMagic, magic, sizeof kCheckpointMagic) == 0;
  };
  const bool v1 = magic_is(kCheckpointMagicV1);
  if (!v1 && !magic_is(kCheckpointMagic)) throw InputError(file.string() + ": not a crowdrecon checkpoint");
  std::uint64_t stored;
  Checkpoint c;
  std::memcpy(&stored, data.data() + 8, 8);
  std::memcpy(&c.last_frame, data.data() + 16, 8);
  if (stored != fingerprint)
    throw InputError(file.string() + ": the checkpoint belongs to a different scenario (the scenario file changed?)");
  if (v1) {
    c.state = data.substr(header);
    return c;
  }
  std::size_t at = header;
  const auto damaged = [&] { return InputError(file.string() + ": the checkpoint is damaged (cut short?)"); };
  const auto get_count = [&] {
    std::uint64_t n;
    if (data.size() - at < sizeof n) throw damaged();
    std::memcpy(&n, data.data() + at, sizeof n);
    at += sizeof n;
    return n;
  };
  const auto get_bytes = [&] {
    const std::uint64_t n = get_count();
    if (n > data.size() - at) throw damaged();
    std::string bytes = data.substr(at, n);
    at += n;
    return bytes;
  };
  c.state = get_bytes();
  const std::uint64_t systems = get_count();
  if (systems > 1000) throw damaged();
  for (std::uint64_t k = 0; k < systems; ++k) {
    std::string name = get_bytes();
    c.systems.emplace_back(std::move(name), get_bytes());
  }
  if (at != data.size()) throw damaged();
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
  if (!runfile::IsRunFile(run_file))
    return file + ": nothing to resume: it is " + runfile::DescribeNonRunFile(run_file) + ", not a crowdrecon run file";
  // (This segment's own values: the chain before it is not read, and may be
  // a segment's head, runfile::WriteSegmentHead.)
  const runfile::RunFileReader reader = runfile::RunFileReader::OneSegment(run_file);
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

double RecordedWallSeconds(const std::filesystem::path& run_file) {
  const double s = std::strtod(runfile::RunFileReader::OneSegment(run_file).RunValue(kWallSecondsKey).c_str(), nullptr);
  return std::isfinite(s) ? std::max(0.0, s) : 0.0;
}

int InterruptedExitStatus() {
  const int signal = g_interrupt_signal.load();
  return signal == SIGTERM ? 128 + SIGTERM : 128 + SIGINT;
}

void InstallInterruptHandlers() {
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
}

namespace {

using Clock = std::chrono::steady_clock;

// 2. The time step: the scenario's, or the engine's choice, shortened so that
//    a whole number of steps fits one output frame (frames exactly 1/fps
//    apart, the rate JuPedSim's format declares), never lengthened. A step
//    above the stability limit is refused; one above the accurate step is
//    allowed with a warning (returned). Sets the world's step.
//    With a timeline, the step serves every body that will arrive and every
//    parameter set its events give (the smallest of their steps).
engine::TimeStepEstimate TimelineTimeStep(const Scenario& scenario, const BuiltWorld& built) {
  engine::WorldDef probe = built.world;
  for (const auto& list : built.timeline.arrivals) probe.people.insert(probe.people.end(), list.begin(), list.end());
  engine::TimeStepEstimate estimate = engine::EstimateTimeStep(probe);
  engine::ModelParameters p = probe.parameters;
  for (const TimelineEvent& e : scenario.timeline.events) {
    if (e.kind != TimelineEvent::Kind::kSetParameters) continue;
    for (const auto& [name, value] : e.parameters)
      if (const engine::ParameterInfo* info = engine::FindModelParameter(name)) {
        // Per group only Gamma and lambda change; the step bounds them as if for everyone.
        if (name == "torsion_stiffness_lambda") p.torsion_stiffness_lambda = std::max(p.torsion_stiffness_lambda, value);
        else p.*(info->number) = value;
      }
    probe.parameters = p;
    const engine::TimeStepEstimate here = engine::EstimateTimeStep(probe);
    if (here.stability_limit_s < estimate.stability_limit_s) estimate = here;
  }
  return estimate;
}

std::string ChooseTimeStep(const Scenario& scenario, BuiltWorld& built, std::int64_t* steps_per_frame) {
  const double frame_dt = 1.0 / scenario.run.output_fps;
  const engine::TimeStepEstimate estimate =
      scenario.timeline.enabled ? TimelineTimeStep(scenario, built) : engine::EstimateTimeStep(built.world);
  if (const std::string unstable =
          engine::TimeStepAboveLimit(scenario.model.time_step_s, scenario.model.integrator, estimate);
      !unstable.empty())
    throw InputError(scenario.file.string() + ": /model/time_step_s: " + unstable);
  double steps = std::ceil(frame_dt / estimate.chosen_s - 1e-9);
  // The adaptive step's largest step lands on every frame: frames a multiple
  // of 2^L fixed steps apart (the fixed step then a little shorter).
  const double largest = std::ldexp(1.0, engine::AdaptiveStepLevels(built.world.parameters));
  steps = std::ceil(steps / largest) * largest;
  built.world.parameters.time_step_s = frame_dt / steps;
  *steps_per_frame = static_cast<std::int64_t>(std::llround(frame_dt / built.world.parameters.time_step_s));
  return TimeStepWarning(scenario, built.world, estimate);
}

// 3. The run file: created with the run's header and records, or, with
//    --resume, reopened at the checkpoint's frame (whose state `sim` takes,
//    with the systems' saved states and the last frame written). A run
//    without a checkpoint yet starts again from the beginning if that gives
//    the same result (NothingToResume).
struct OpenedRun {
  runfile::RunFileWriter writer;
  std::int64_t last_frame = -1;  // -1: nothing written yet
  std::vector<std::pair<std::string, std::string>> systems;
  double earlier_wall_s = 0.0;  // a resumed run's wall time to its checkpoint (run value wall_s)
};

OpenedRun OpenRunFile(const Scenario& scenario, const RunOptions& options, const BuiltWorld& built,
                      engine::Simulation& sim, std::uint64_t fingerprint, const std::function<void(const std::string&)>& say) {
  const std::filesystem::path checkpoint = CheckpointPath(options.output);
  std::error_code ec;
  if (options.resume && !std::filesystem::exists(checkpoint, ec)) {
    const std::string why = NothingToResume(options.output, scenario);
    if (!why.empty()) throw InputError(why);
    std::fprintf(stderr, "crowdrecon: note: %s has no checkpoint yet (the run stopped before its first one); "
                 "starting it again from the beginning\n", options.output.string().c_str());
  } else if (options.resume) {
    const Checkpoint c = ReadCheckpoint(checkpoint, fingerprint);
    sim.LoadState(c.state);
    say("resuming at t = " + FormatNumber(sim.time_s()) + " s (frame " + std::to_string(c.last_frame) + ")");
    // The wall time its frames took so far (written with each checkpoint;
    // absent in a run written before it was kept: counted from here).
    const double earlier_wall_s = RecordedWallSeconds(options.output);
    return {runfile::RunFileWriter::Resume(options.output, c.last_frame), c.last_frame, c.systems, earlier_wall_s};
  }
  std::filesystem::remove(checkpoint, ec);
  runfile::RunHeader header;
  header.scenario_json = scenario.json_text;
  header.scenario_origin = scenario.file.string();
  header.venue_json = geometry::VenueToJson(scenario.venue);
  header.walkable_wkt = built.walkable_wkt;
  header.output_fps = scenario.run.output_fps;
  header.time_step_s = sim.tick_s();
  header.seed = scenario.population.seed;
  header.packed = scenario.run.packed_frames;
  if (!scenario.timeline.enabled) return {CreateRunFile(options.output, header, sim, built.target_names), -1, {}};
  // A timeline's people: those of the start, then every arrival the schedule
  // may bring, each at its id (BuiltTimeline), whether or not they come.
  runfile::RunSetup setup = RunSetupOf(sim, built.target_names);
  const BuiltTimeline& t = built.timeline;
  std::size_t people = t.initial_people;
  for (const auto& list : t.arrivals) people += list.size();
  setup.people.resize(people);  // every row past the start is an arrival's (ids are a permutation)
  for (std::size_t f = 0; f < t.arrivals.size(); ++f)
    for (std::size_t k = 0; k < t.arrivals[f].size(); ++k) {
      const engine::PersonDef& p = t.arrivals[f][k];
      setup.people[t.arrival_id[f][k]] = {p.shape, p.mass_kg, p.inertia_kg_m2, p.desired_speed_m_per_s, p.group,
                                          built.target_names[p.target]};
    }
  return {CreateRunFileOf(options.output, header, sim, setup), -1, {}};
}

}  // namespace

namespace {

// A scenario's JSON without what a branch may change (name, notes, the
// timeline's events), and those events in the order the parser applies
// them (stably by time), each with its time.
struct BranchParts {
  nlohmann::json rest;
  std::vector<std::pair<double, nlohmann::json>> events;
};

// The scenario's file paths (venue, body files, rate tables) resolved
// against its folder, as the parser resolves them: two scenarios in
// different folders that name the same files are the same.
void ResolveFilePaths(nlohmann::json& scenario, const std::filesystem::path& base_dir) {
  const auto resolve = [&](nlohmann::json& value) {
    if (!value.is_string()) return;
    const std::filesystem::path p(value.get<std::string>());
    value = (p.is_absolute() ? p : std::filesystem::absolute(base_dir / p)).lexically_normal().string();
  };
  if (scenario.contains("venue")) resolve(scenario["venue"]);
  if (auto pop = scenario.find("population"); pop != scenario.end() && pop->is_object())
    if (auto body = pop->find("body"); body != pop->end() && body->is_object())
      for (const char* key : {"reference", "anthropometry"})
        if (body->contains(key)) resolve((*body)[key]);
  if (auto t = scenario.find("timeline"); t != scenario.end() && t->is_object())
    if (auto inflows = t->find("inflows"); inflows != t->end() && inflows->is_array())
      for (nlohmann::json& inflow : *inflows)
        if (inflow.is_object() && inflow.contains("rate_csv")) resolve(inflow["rate_csv"]);
}

BranchParts SplitForBranch(const std::string& json_text, const std::filesystem::path& scenario_file,
                           const std::string& what) {
  BranchParts parts;
  try {
    parts.rest = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": its scenario is not JSON (" + e.what() + ")");
  }
  if (!parts.rest.is_object()) throw InputError(what + ": its scenario is not a JSON object");
  ResolveFilePaths(parts.rest, scenario_file.parent_path());
  parts.rest.erase("name");
  parts.rest.erase("notes");
  if (auto t = parts.rest.find("timeline"); t != parts.rest.end() && t->is_object()) {
    if (auto e = t->find("events"); e != t->end() && e->is_array()) {
      for (const nlohmann::json& event : *e) {
        const auto time = event.find("time_s");
        parts.events.emplace_back(time != event.end() && time->is_number() ? time->get<double>() : 0.0, event);
      }
      t->erase("events");
    }
  }
  std::stable_sort(parts.events.begin(), parts.events.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  return parts;
}

}  // namespace

double BranchRun(const Scenario& scenario, const std::filesystem::path& from, const std::filesystem::path& output) {
  const std::string name = from.string();
  if (!runfile::IsRunFile(from)) throw InputError(name + ": not a crowdrecon run file (the run to branch from)");
  std::error_code ec;
  const runfile::RunFileReader reader(from);
  const std::string old_text = reader.RunValue("scenario");
  if (!std::filesystem::exists(CheckpointPath(from), ec))
    throw InputError(name + ": has no checkpoint to branch from (" + CheckpointPath(from).string() +
                     "); a run keeps its last checkpoint while it is unfinished");
  const Checkpoint c = ReadCheckpoint(CheckpointPath(from), TextFingerprint(old_text));
  double t_s = -1.0;
  for (const runfile::FrameTime& f : reader.FrameTimes())
    if (f.frame == c.last_frame) t_s = f.time_s;
  if (t_s < 0.0)
    throw InputError(name + ": its checkpoint is at frame " + std::to_string(c.last_frame) +
                     ", which the run file does not have (the file and the checkpoint are not of one run)");

  // The same run up to the checkpoint: everything but the name, the notes
  // and the events from the checkpoint's time on.
  const std::string at = " (a branch at t = " + FormatNumber(t_s) + " s may change only the name, the notes and "
                         "timeline events at or after that time)";
  const BranchParts was = SplitForBranch(old_text, reader.RunValue("scenario_file"), name);
  const BranchParts now = SplitForBranch(scenario.json_text, scenario.file, scenario.file.string());
  if (was.rest != now.rest) {
    const nlohmann::json patch = nlohmann::json::diff(was.rest, now.rest);
    const std::string path = patch.empty() ? "/" : patch[0].value("path", "/");
    throw InputError(scenario.file.string() + ": " + path + ": differs from the scenario of " + name + at);
  }
  // An event at the checkpoint's time is applied at the first step after it.
  const auto before = [&](const BranchParts& p) {
    std::vector<nlohmann::json> out;
    for (const auto& [time, event] : p.events)
      if (time < t_s - 1e-9) out.push_back(event);
    return out;
  };
  const std::vector<nlohmann::json> was_before = before(was), now_before = before(now);
  if (was_before != now_before) {
    std::size_t k = 0;
    while (k < was_before.size() && k < now_before.size() && was_before[k] == now_before[k]) ++k;
    throw InputError(scenario.file.string() + ": /timeline/events: the events before t = " + FormatNumber(t_s) +
                     " s differ from those of " + name + " from the " + std::to_string(k + 1) +
                     (k == 0 ? "st" : k == 1 ? "nd" : k == 2 ? "rd" : "th") + " on" + at);
  }

  // The run file to its checkpoint's frame, now the scenario's; the
  // checkpoint with the scenario's fingerprint.
  // (A copy cut short, by a full disk say, is removed: nothing half-made is left.)
  const auto remove_output = [&] {
    std::filesystem::remove(output, ec);
    std::filesystem::remove(CheckpointPath(output), ec);
  };
  remove_output();
  try {
    runfile::CopyRunFile(from, output);
    {
      runfile::RunFileWriter writer = runfile::RunFileWriter::Resume(output, c.last_frame);
      writer.SetRunValue("scenario", scenario.json_text);
      writer.SetRunValue("scenario_file", scenario.file.string());
      writer.SetRunValue("branched_from", name + " at t = " + FormatNumber(t_s) + " s (frame " +
                                              std::to_string(c.last_frame) + ")");
      writer.SetStatus("interrupted");
    }
    WriteCheckpoint(CheckpointPath(output), ScenarioFingerprint(scenario), c);
  } catch (...) {
    remove_output();
    throw;
  }
  return t_s;
}

double ContinueRun(const Scenario& scenario, const std::filesystem::path& from, const std::filesystem::path& output) {
  const std::string name = from.string();
  if (!runfile::IsRunFile(from))
    throw InputError(name + ": " + runfile::DescribeNonRunFile(from) + ", not a crowdrecon run file (the segment to continue)");
  std::error_code ec;
  if (std::filesystem::equivalent(from, output, ec))
    throw InputError(output.string() + ": is the segment to continue itself; a continuation is written into a new file");
  const runfile::RunFileReader reader = runfile::RunFileReader::OneSegment(from);
  const std::string status = reader.RunValue("status");
  if (status != "interrupted")
    throw InputError(name + ": its status is \"" + status + "\"; only a segment stopped at its checkpoint (status "
                     "\"interrupted\": simulate --stop-after, or a run stopped with Ctrl-C or SIGTERM) can be continued" +
                     (status == "running" ? " (a killed run: resume it first with --resume, then stop it)" : ""));
  if (!std::filesystem::exists(CheckpointPath(from), ec))
    throw InputError(name + ": has no checkpoint to continue from (" + CheckpointPath(from).string() + ")");
  const Checkpoint c = ReadCheckpoint(CheckpointPath(from), ScenarioFingerprint(scenario));
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  if (times.empty() || times.back().frame != c.last_frame)
    throw InputError(name + ": its checkpoint is at frame " + std::to_string(c.last_frame) + ", but its last frame is " +
                     (times.empty() ? std::string("none") : std::to_string(times.back().frame)) +
                     " (the file and the checkpoint are not of one segment)");
  const auto remove_output = [&] {
    std::filesystem::remove(output, ec);
    sqlite::RemoveSidecars(output);
    std::filesystem::remove(CheckpointPath(output), ec);
  };
  remove_output();
  try {
    runfile::RunFileWriter::StartSegment(output, from, c.last_frame);
    WriteCheckpoint(CheckpointPath(output), ScenarioFingerprint(scenario), c);
  } catch (...) {
    remove_output();
    throw;
  }
  return times.back().time_s;
}

EngineAtCheckpoint ReadEngineAtCheckpoint(const Scenario& scenario, const std::filesystem::path& run_file, int threads) {
  BuiltWorld built = BuildWorld(scenario, threads, [](const std::string&) {});
  std::int64_t steps_per_frame = 1;
  ChooseTimeStep(scenario, built, &steps_per_frame);
  EngineAtCheckpoint out;
  out.state = ReadCheckpoint(CheckpointPath(run_file), ScenarioFingerprint(scenario)).state;
  engine::Simulation sim(built.world);
  sim.LoadState(out.state);  // checks that the state fits the world
  out.time_s = sim.time_s();
  out.world = std::move(built.world);
  return out;
}

RunSummary RunScenario(const Scenario& scenario, const RunOptions& options) {
  const auto say = [&](const std::string& line) {
    if (options.show_progress) std::fprintf(stderr, "%s\n", line.c_str());
  };
  g_stop_requested.store(false);
  // 1. The world.
  BuiltWorld built = BuildWorld(scenario, options.threads, say);
  std::int64_t steps_per_frame = 1;
  const std::string step_warning = ChooseTimeStep(scenario, built, &steps_per_frame);
  built.world.device = options.device;
  engine::Simulation sim(built.world);
  // The incident timeline's shared state; its doors as at t = 0.
  std::unique_ptr<detail::TimelineState> timeline;
  std::vector<double> premovement;  // the people of the start's times (premovement.hpp)
  if (scenario.timeline.enabled) {
    timeline = std::make_unique<detail::TimelineState>(scenario, built);
    detail::OpenDoorsAtStart(sim, *timeline);
    premovement = detail::PremovementTimes(scenario, built.timeline.initial_people);
    detail::HoldUntilPremovement(sim, premovement);
  }

  const std::uint64_t fingerprint = ScenarioFingerprint(scenario);
  const std::filesystem::path checkpoint = CheckpointPath(options.output);
  // No other process writes this run while this one does (before anything
  // of an earlier run there is removed).
  const runfile::RunFileLock lock(options.output);
  OpenedRun opened = OpenRunFile(scenario, options, built, sim, fingerprint, say);
  runfile::RunFileWriter& writer = opened.writer;
  std::int64_t last_frame = opened.last_frame;
  writer.SetRunValue("people", std::to_string(timeline ? built.timeline.initial_people : sim.bodies().size()));
  writer.SetRunValue("profile", scenario.profile);  // the model profile (scenario/profile.hpp)
  if (timeline) {
    std::string groups;
    for (const std::string& g : scenario.timeline.groups) groups += (groups.empty() ? "" : ",") + g;
    writer.SetRunValue("groups", groups);
    // What the figure marks (timeline.hpp: RecordedMark), as JSON.
    if (!scenario.timeline.clock_start.empty()) writer.SetRunValue("timeline_clock_start", scenario.timeline.clock_start);
    if (scenario.timeline.clock_scale != 1.0)
      writer.SetRunValue("timeline_clock_scale", FormatNumber(scenario.timeline.clock_scale));
    nlohmann::json marks = nlohmann::json::array();
    for (const RecordedMark& m : scenario.timeline.recorded) {
      marks.push_back({{"time_s", m.time_s}, {"label", m.label}, {"kind", m.kind}});
      if (m.HasMaxSpeed()) {
        marks.back()["max_speed_m_per_s"] = m.max_speed_m_per_s;
        marks.back()["max_speed_uncertainty_m_per_s"] = m.max_speed_uncertainty_m_per_s;
      }
    }
    writer.SetRunValue("timeline_recorded", marks.dump());
  }
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
  summary.people = timeline ? built.timeline.initial_people : sim.bodies().size();
  summary.slots = timeline ? sim.bodies().size() : 0;
  summary.time_step_s = sim.tick_s();
  const auto start = Clock::now();
  const double start_sim = sim.time_s();

  // 4. Frames are written by a thread of their own while the next ones are
  //    simulated, if the engine leaves a core free (see FrameWriterThread);
  //    everything that must follow the frames in the file (a checkpoint
  //    naming the last frame, an event, the status) waits for them with Flush.
  const bool core_free = static_cast<unsigned>(std::max(1, options.threads)) < std::thread::hardware_concurrency();
  runfile::FrameWriterThread frames(writer, core_free);
  detail::ContactKeeper contacts(scenario.run, checkpoint_every);  // (its state: the frames system's)
  if (last_frame < 0) {
    detail::WriteTimelineFrame(frames, sim, 0, contacts, timeline.get());
    last_frame = 0;
  }

  engine::ThreadChoice::Options thread_options;
  thread_options.max_threads = sim.definition().threads;
  engine::ThreadGovernor governor(thread_options);
  const bool adapt_threads = options.adapt_threads && thread_options.max_threads > 1;

  // 5. The run loop: the engine step and the systems (run_systems.hpp), in order.
  RunLoop::Options loop_options;
  loop_options.steps_per_frame = steps_per_frame;
  loop_options.step = [&](engine::Simulation& s) {
    if (adapt_threads) governor.Step(s);
    else s.Step();
  };
  loop_options.write_event = [&](const Event& event, std::int64_t frame) {
    frames.Flush();  // an event follows its frame in the file
    writer.WriteEvent(frame, event);
  };
  RunLoop loop(sim, loop_options);
  // The run's wall time over all its invocations (run value wall_s): what
  // its frames took to compute, to its last checkpoint while it is
  // unfinished (a run killed outright computes again what followed it).
  const auto record_wall_time = [&] {
    writer.SetRunValue(kWallSecondsKey, FormatNumber(opened.earlier_wall_s + std::chrono::duration<double>(Clock::now() - start).count()));
  };
  const auto checkpoint_at = [&](const std::filesystem::path& file, std::int64_t frame) {
    frames.Flush();
    WriteCheckpoint(file, fingerprint, Checkpoint{frame, sim.SaveState(), loop.SaveStates()});
    record_wall_time();
  };
  if (timeline) {  // the incident timeline's systems, around the steps (timeline_systems.hpp)
    loop.Add(detail::MakeTimelineEventSystem(*timeline));
    if (scenario.timeline.premovement.enabled)
      loop.Add(detail::MakePremovementSystem(*timeline, built, std::move(premovement)));
    loop.Add(detail::MakeInflowSystem(*timeline));
    loop.Add(detail::MakeExitSystem(*timeline));
    loop.Add(detail::MakeFallSystem(*timeline));
    loop.Add(detail::MakeAvalancheSystem(*timeline));
    loop.Add(detail::MakeLeftSystem(*timeline));
  }
  loop.Add(std::make_unique<detail::WallCheckSystem>(sim));
  loop.Add(std::make_unique<detail::FrameOutputSystem>(frames, contacts, timeline.get()));
  loop.Add(std::make_unique<detail::DeviceFallbackSystem>(options.show_progress));
  if (scenario.run.settle.enabled) {
    // Directions of travel by group, named after their target.
    std::vector<std::string> group_names;
    const engine::BodyState& b = sim.bodies();
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b.group[i] >= group_names.size()) group_names.resize(b.group[i] + 1);
      if (group_names[b.group[i]].empty() && b.target[i] < built.target_names.size())
        group_names[b.group[i]] = built.target_names[b.target[i]];
    }
    loop.Add(std::make_unique<detail::SettleSystem>(sim, scenario.run.settle, group_names));
  }
  loop.Add(std::make_unique<detail::CheckpointSystem>(
      checkpoint_every, [&](std::int64_t frame) { checkpoint_at(checkpoint, frame); }));
  loop.Add(std::make_unique<detail::StopRequestSystem>(g_stop_requested, options.stop_flag, options.stop_after_s));
  if (options.show_progress || options.log_progress_every_s > 0 || options.simulated_s) {
    detail::ProgressSystem::Options progress;
    progress.duration_s = scenario.run.duration_s;
    progress.start_sim_s = start_sim;
    progress.terminal = options.show_progress;
    progress.log_every_s = options.log_progress_every_s;
    progress.simulated_s = options.simulated_s;
    loop.Add(std::make_unique<detail::ProgressSystem>(progress));
  }
  try {
    loop.LoadStates(opened.systems);
  } catch (const InputError& e) {  // (the file that holds the states)
    throw InputError(checkpoint.string() + ": " + e.what());
  }

  // 6. Run; a run that goes numerically wrong stops with its state saved.
  std::string status = "complete";
  try {
    loop.Run(last_frame, total_frames);
    last_frame = loop.summary().last_frame;
    if (loop.summary().finished) {
      frames.Flush();
      writer.SetRunValue(scenario.run.settle.enabled ? "settled" : "finished_early", loop.summary().finish_reason);
      say(loop.summary().finish_reason);
    } else if (loop.summary().stopped) {
      checkpoint_at(checkpoint, last_frame);
      status = "interrupted";
    }
  } catch (const engine::SimulationError& e) {
    last_frame = loop.summary().last_frame;
    // Save the state in which the run failed, next to the run file, and say so.
    const std::filesystem::path failed = options.output.string() + ".failed-state";
    checkpoint_at(failed, last_frame);
    Event event;
    event.time_s = sim.time_s();
    event.kind = "numerical_failure";
    // The engine names slots; the run file names people (a timeline's
    // arrivals take whichever slot is free).
    const auto id_of = [&](std::int64_t slot) {
      return slot >= 0 && static_cast<std::size_t>(slot) < sim.bodies().size() ? std::int64_t{sim.bodies().id[static_cast<std::size_t>(slot)]} : slot;
    };
    event.person = id_of(e.person());
    event.other = id_of(e.other());
    event.detail = e.what();
    writer.WriteEvent(last_frame, event);
    writer.SetStatus(std::string("failed: ") + e.what());
    if (options.show_progress) std::fprintf(stderr, "\n");
    throw InputError(options.output.string() + ": the run went numerically wrong: " + e.what() +
                     "; frames up to " + std::to_string(last_frame) + " are in the run file and the state is saved in " +
                     failed.string());
  }

  // 7. Status and summary (a timeline's totals: run values).
  frames.Flush();
  if (timeline) {
    const runfile::Census c = timeline->Count(sim);
    writer.SetRunValue("timeline_entered", std::to_string(c.entered));
    writer.SetRunValue("timeline_removed", std::to_string(c.removed));
    writer.SetRunValue("timeline_fallen", std::to_string(c.fallen));
    writer.SetRunValue("timeline_queued", std::to_string(c.queued));
    std::string exits = "{";
    for (std::size_t x = 0; x < scenario.venue.exits.size(); ++x)
      exits += (x ? ", \"" : "\"") + scenario.venue.exits[x].id + "\": " + std::to_string(timeline->exit_count[x]);
    writer.SetRunValue("timeline_exit_counts", exits + "}");
  }
  if (options.show_progress) std::fprintf(stderr, "\n");
  if (sim.max_step_level() > 0) {  // the adaptive step's steps by length (issue 42)
    const std::string steps = engine::StepLevelHistogram(sim.profile(), sim.tick_s());
    writer.SetRunValue("adaptive_steps", (steps.empty() ? "every step 1 h (the fixed step)" : steps) +
                                             (options.resume ? " (since the resume)" : ""));
  }
  if (adapt_threads)  // how many engine threads the governor chose (several asked for)
    writer.SetRunValue("engine_threads", governor.summary().BriefReport() + (options.resume ? " (since the resume)" : ""));
  record_wall_time();
  if (status == "complete") writer.DropContacts(contacts.Finish());  // worst moments superseded since the last checkpoint
  writer.SetStatus(status);
  if (status == "complete") {
    std::error_code ec;
    std::filesystem::remove(checkpoint, ec);
  }
  summary.systems_report = loop.summary().BriefReport();
  summary.status = status;
  summary.simulated_s = sim.time_s();
  summary.started_at_s = start_sim;
  summary.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  summary.total_wall_s = opened.earlier_wall_s + summary.wall_s;
  summary.real_time_factor = summary.wall_s > 0 ? (sim.time_s() - start_sim) / summary.wall_s : 0.0;
  summary.frames = last_frame + 1;
  summary.profile = sim.profile();
  summary.device_fallback = sim.device_fallback();
  if (adapt_threads) summary.threads_report = governor.summary().BriefReport();
  return summary;
}

}  // namespace crowdrecon::scenario
