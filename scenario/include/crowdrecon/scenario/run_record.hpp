// What a run file records of a simulation. The run-file library
// (runfile/run_file.hpp) knows no engine; these functions copy the engine's
// world and frames into its records.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::scenario {

// Shapes, people (as placed; their targets named by `target_names`, by
// engine target index) and walls of the simulation.
runfile::RunSetup RunSetupOf(const engine::Simulation& sim, const std::vector<std::string>& target_names);
// Creates the run file of `sim`: the header (its periodic box taken from the
// simulation) and RunSetupOf(sim, target_names).
runfile::RunFileWriter CreateRunFile(const std::filesystem::path& file, runfile::RunHeader header,
                                     const engine::Simulation& sim, const std::vector<std::string>& target_names);
// The same with the records given (a timeline's: the people of the start and
// every arrival, RunSetupOf lists the engine's slots).
runfile::RunFileWriter CreateRunFileOf(const std::filesystem::path& file, runfile::RunHeader header,
                                       const engine::Simulation& sim, const runfile::RunSetup& setup);

// Each person's load (engine index; 0 for the removed): the sum of the
// magnitudes of the contact forces on them, the quantity compared with the
// 400 N threshold.
void PersonLoads(const engine::Simulation& sim, std::vector<double>* load);
// The load across each person's chest and across the shoulders
// (reports/chest_load.hpp: what both sides press together), by engine slot,
// as the reports compare with tolerance data; PersonChestLoads: the larger.
void ChestLoadsOf(const engine::Simulation& sim, std::vector<double>* chest, std::vector<double>* lateral);
void PersonChestLoads(const engine::Simulation& sim, std::vector<double>* load);

// Copies frame `frame` of the simulation into `out`, reusing its storage:
// every person still in the venue (by run id, BodyState::id), their loads (the sum of the magnitudes of
// the contact forces on each, the quantity compared with the 400 N
// threshold), every contact when `with_contacts`, and the frame's events.
void TakeSnapshot(const engine::Simulation& sim, std::int64_t frame, const std::vector<runfile::Event>& events,
                  bool with_contacts, runfile::FrameSnapshot* out);
// TakeSnapshot then RunFileWriter::WriteFrame, in the caller's thread.
void WriteFrame(runfile::RunFileWriter& writer, const engine::Simulation& sim, std::int64_t frame,
                const std::vector<runfile::Event>& events, bool with_contacts);

}  // namespace crowdrecon::scenario
