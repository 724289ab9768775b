// Trajectories read from any source, in one form: PeTrack text files (the
// Jülich experiments), JuPedSim SQLite files (versions 1, 2 and 3, ours
// included) and crowdrecon run files (which are JuPedSim version 2 files with
// more tables). Observations (observation.hpp) and fundamental diagrams
// (fundamental_diagram.hpp) are computed from this form only, so that a
// simulated run and an experiment go through the same code.
//
//   observe::Trajectories t = observe::ReadTrajectories("040_c_56_h-.txt");
//   for (const observe::Track& track : observe::TracksOf(t)) ...
//
// Every problem with a file is an InputError naming the file and what was
// expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::observe {

struct TrajectoryPoint {
  std::uint32_t id = 0;      // the person's id in the file
  std::int64_t frame = 0;
  Vec2 position_m;
  double z_m = 0.0;          // height or 3D position, as the file says (0 without the column)
};

struct Trajectories {
  std::string source;        // the file's name, for messages
  // "petrack", "jupedsim-v1", "jupedsim-v2", "jupedsim-v3" or "crowdrecon-run"
  std::string format;
  double fps = 0.0;
  std::string unit = "m";    // of the coordinates in the file: m, cm or mm
  std::vector<TrajectoryPoint> points;  // in file order
  std::size_t people = 0;    // distinct ids
  std::int64_t first_frame = 0, last_frame = 0;
  // The walkable area as WKT where the file has one (JuPedSim files), else "".
  std::string walkable_wkt;
  // The periodic box of a periodic crowdrecon run (positions are stored
  // wrapped into it; velocities are then taken over minimum images).
  PeriodicBox box;
  // crowdrecon runs: the group (direction of travel of the scenario) of each
  // id, as (id, group) pairs; empty for other sources.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> groups;
  std::vector<std::string> notes;  // what the reader assumed (a unit not stated, ...)
};

// Limits of what a file may hold (an error names them).
inline constexpr std::uint32_t kMaxPersonId = 10'000'000;
inline constexpr std::int64_t kMaxFrame = 1'000'000'000;
inline constexpr double kMaxCoordinate_m = 1e5;

// Reads a trajectory file of any supported kind, told apart by its content
// (an SQLite file is read as JuPedSim/crowdrecon, anything else as PeTrack
// text). `fps_override` > 0 replaces the file's frame rate.
// `unit` ("m", "cm", "mm" or "" for the file's own) is for PeTrack files
// (ReadPeTrack); SQLite trajectory files are in metres.
Trajectories ReadTrajectories(const std::filesystem::path& file, double fps_override = 0.0, const std::string& unit = "");

// JuPedSim SQLite trajectory files: version 1 (geometry(wkt)), version 2
// (trajectory_data with ori_x, ori_y; geometry(hash, wkt); frame_data) and
// version 3 (trajectory_data without orientation), and crowdrecon run files
// (version 2 plus a run table: the periodic box and the groups are read too).
Trajectories ReadJuPedSim(const std::filesystem::path& file, double fps_override = 0.0);

// One person's points, in frame order (frames strictly increasing).
struct Track {
  std::uint32_t id = 0;
  std::uint32_t group = 0;  // Trajectories::groups, else 0
  std::vector<std::int64_t> frame;
  std::vector<Vec2> position_m;
};

// The tracks of every person, ordered by id. Throws InputError if a person has
// two points in one frame (names the file, the id and the frame).
std::vector<Track> TracksOf(const Trajectories& t);

// Velocity at point k of a track by a centred difference over `half_span`
// frames either side (one-sided at the track's ends; a gap in the track, a
// missing frame, shortens the span to the points that exist), over minimum
// images in a periodic box. False if the track has a single point.
bool VelocityAt(const Track& track, std::size_t k, int half_span, double fps, const PeriodicBox& box,
                Vec2* velocity_m_per_s);

}  // namespace crowdrecon::observe
