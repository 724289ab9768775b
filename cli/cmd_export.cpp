// `crowdrecon export`: a run's trajectories as a plain JuPedSim trajectory file
// for tools unaware of periodic boxes, each trajectory cut at the seams of the
// box (runfile/trajectory_export.hpp, docs/scenarios.md "Periodic runs in
// other tools").
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/runfile/tables_export.hpp"
#include "crowdrecon/runfile/trajectory_export.hpp"
#include "crowdrecon/scenario/runner.hpp"

namespace crowdrecon::cli {

namespace {

struct ExportArgs {
  std::string run_file;
  std::string output;
  bool force = false;
  bool tables = false;  // --tables: the run as one run file with tables
  bool segment_head = false;  // --segment-head: the segment's head and its checkpoint
};

// --segment-head: RUN (a segment stopped at its checkpoint) as its head
// beside a copy of its checkpoint (runfile::WriteSegmentHead).
void WriteHead(const ExportArgs& args) {
  const runfile::RunFileReader one = runfile::RunFileReader::OneSegment(args.run_file);
  const std::string status = one.RunValue("status");
  if (status != "interrupted")
    throw InputError(args.run_file + ": its status is \"" + status + "\"; a segment's head is made of a segment stopped "
                     "at its checkpoint (status \"interrupted\": simulate --stop-after, Ctrl-C or SIGTERM), the one "
                     "a run continues from");
  if (!one.RunValue("segment_head").empty())
    throw InputError(args.run_file + ": is a segment's head already; copy it with its checkpoint instead");
  const std::filesystem::path from_checkpoint = scenario::CheckpointPath(args.run_file);
  std::error_code ec;
  if (!std::filesystem::exists(from_checkpoint, ec))
    throw InputError(args.run_file + ": has no checkpoint to continue from (" + from_checkpoint.string() + ")");
  const std::string checkpoint = ReadInputFile(from_checkpoint, "checkpoint");
  const std::vector<runfile::FrameTime> times = one.FrameTimes();
  runfile::WriteSegmentHead(args.run_file, args.output);
  const std::filesystem::path to_checkpoint = scenario::CheckpointPath(args.output);
  WriteFileAtomically(to_checkpoint, checkpoint);
  std::printf("segment head: %s at t = %s s (frame %lld), %lld bytes, and its checkpoint %s, %lld bytes\n",
              args.output.c_str(), times.empty() ? "?" : FormatNumber(times.back().time_s).c_str(),
              static_cast<long long>(times.empty() ? -1 : times.back().frame),
              static_cast<long long>(std::filesystem::file_size(args.output, ec)), to_checkpoint.c_str(),
              static_cast<long long>(std::filesystem::file_size(to_checkpoint, ec)));
  std::printf("continue it anywhere: crowdrecon simulate SCENARIO -o NEXT.sqlite --continue-from %s\n",
              args.output.c_str());
}

// "x in [0, 12) m" for the periodic axes of `box`.
std::string DescribeSeams(const PeriodicBox& box) {
  std::string text;
  if (box.x) text += "x in [" + FormatNumber(box.min_m.x) + ", " + FormatNumber(box.max_m.x) + ") m";
  if (box.y) text += std::string(text.empty() ? "" : ", ") + "y in [" + FormatNumber(box.min_m.y) + ", " +
                     FormatNumber(box.max_m.y) + ") m";
  return text;
}

void RunExport(const ExportArgs& args) {
  if (args.tables && args.segment_head) throw InputError("--tables and --segment-head: give one of them");
  CheckOutputs({{"-o", args.output,
                 args.tables || args.segment_head ? runfile::RunFileOutput() : runfile::TrajectoryExportOutput()}},
               {{"the run file", args.run_file}, {"the run's checkpoint", scenario::CheckpointPath(args.run_file)}},
               args.force);
  // Said here rather than as SQLite's "file is not a database".
  std::error_code ec;
  if (!std::filesystem::exists(args.run_file, ec))
    throw InputError(args.run_file + ": no such file; expected a run file (.sqlite) written by `crowdrecon simulate`");
  if (!runfile::IsRunFile(args.run_file))
    throw InputError(args.run_file + ": is " + runfile::DescribeNonRunFile(args.run_file) +
                     ", not a crowdrecon run file; expected a run file (.sqlite) written by `crowdrecon simulate`");
  if (args.segment_head) return WriteHead(args);
  const runfile::RunFileReader run(args.run_file);
  if (args.tables) {
    const runfile::TablesExportSummary t = runfile::WriteRunTables(run, args.output);
    std::printf("run file with tables: %lld segment(s) joined, %lld packed frames unpacked (%lld people's rows)\n",
                static_cast<long long>(t.segments), static_cast<long long>(t.frames), static_cast<long long>(t.rows));
    std::printf("wrote %s\n", args.output.c_str());
    SayIfUnfinished(args.run_file);
    return;
  }
  const runfile::ExportSummary s = runfile::ExportTrajectories(run, args.output);
  std::printf("export: %lld rows in %lld frames, %lld people\n", static_cast<long long>(s.rows),
              static_cast<long long>(s.frames), static_cast<long long>(s.people));
  if (s.box.any())
    std::printf("periodic box %s: %lld split(s) at its seams, %lld ids (table crowdrecon_track maps them to people)\n",
                DescribeSeams(s.box).c_str(), static_cast<long long>(s.splits), static_cast<long long>(s.tracks));
  else
    std::printf("not periodic: ids kept, no splits\n");
  for (const std::string& partial : s.removed_partials)
    std::printf("removed %s: the unfinished file of an export to %s that was killed\n", partial.c_str(),
                args.output.c_str());
  for (const std::string& side : s.removed_sidecars)
    std::printf("removed %s: a killed writer's log beside the file replaced (it would have been applied to the export)\n",
                side.c_str());
  // A killed run's checkpoint belonged to the file this export replaced.
  const std::filesystem::path checkpoint = scenario::CheckpointPath(args.output);
  if (std::filesystem::exists(checkpoint, ec) && std::filesystem::remove(checkpoint, ec))
    std::printf("removed %s: the checkpoint of the run that %s held before\n", checkpoint.c_str(), args.output.c_str());
  std::printf("wrote %s\n", args.output.c_str());
  SayIfUnfinished(args.run_file);
}

}  // namespace

void RegisterExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write a run's trajectories as a plain JuPedSim trajectory file (version 2) for PedPy and other "
                "tools; a periodic run's trajectories are cut where they cross a seam of the box, each piece "
                "with an id of its own (docs/scenarios.md, \"Periodic runs in other tools\")");
  cmd->add_option("RUN", args->run_file, "run file (.sqlite) written by `crowdrecon simulate`")->required();
  cmd->add_option("-o,--output", args->output,
                  "the trajectory file to write (.sqlite; an existing one must be a previous export)")
      ->required();
  cmd->add_flag("--tables", args->tables,
                "Write instead the whole run as one run file with tables (run.frames \"tables\"): packed frames "
                "unpacked, a run in segments joined; for scripts that read the tables (docs/scenarios.md, "
                "\"Packed frames\"); -o must not exist or be a run file");
  cmd->add_flag("--segment-head", args->segment_head,
                "Write instead RUN's head: the segment (stopped at its checkpoint) without its frames, with a copy "
                "of its checkpoint beside it (-o's name + .checkpoint): small enough to keep in a repository, and "
                "what `simulate --continue-from` needs to continue the run on another machine; no command reads "
                "a head as a run (docs/scenarios.md, \"Runs in segments\")");
  AddForceFlag(cmd, &args->force);
  cmd->callback([args] { RunExport(*args); });
}

}  // namespace crowdrecon::cli
