// RunFile: one SQLite file per run, readable by the field's tools.
//
// JuPedSim trajectory format, version 2 (what PedPy's
// load_trajectory_from_jupedsim_sqlite and load_walkable_area_from_jupedsim_sqlite read):
//   trajectory_data(frame INTEGER, id INTEGER, pos_x REAL, pos_y REAL, ori_x REAL, ori_y REAL)
//   metadata(key TEXT PRIMARY KEY, value TEXT)   version = 2, fps, xmin, xmax, ymin, ymax
//   geometry(hash INTEGER, wkt TEXT)             the walkable area as WKT
//   frame_data(frame INTEGER, geometry_hash INTEGER)
// plus crowdrecon's own tables in the same file:
//   run(key TEXT PRIMARY KEY, value TEXT)        scenario JSON, seed, time step, status, ...
//   shape(id INTEGER PRIMARY KEY, radius_m REAL, vertices TEXT)   body frame, JSON [[x,y],...]
//   person(id INTEGER PRIMARY KEY, shape INTEGER, mass_kg REAL, inertia_kg_m2 REAL,
//          desired_speed_m_per_s REAL, grp INTEGER, target TEXT)
//   frame_time(frame INTEGER PRIMARY KEY, time_s REAL)
//   person_state(frame, id, vel_x, vel_y, angle_rad, omega_rad_per_s, state, load_n)
//   contact(frame, a, b, wall, point_x, point_y, normal_x, normal_y, overlap_m,
//           normal_force_n, tangential_force_n)   every contact of the frame; b is a
//           person id, or a wall index when wall = 1; forces act on a along the
//           normal and along Perp(normal) = (-normal_y, normal_x)
//   event(frame, time_s, kind TEXT, person INTEGER, other INTEGER, detail TEXT)
//   wall(id INTEGER PRIMARY KEY, closed INTEGER, radius_m REAL, points TEXT)
// Person ids in every table are 1-based in trajectory_data/person (as PedPy
// expects ids), i.e. engine index + 1; contact.a/b use the same ids.
//
// Each frame is one transaction: a run killed at any moment leaves a valid
// file holding every frame committed so far (in write-ahead-log mode while
// written: a killed run's RUN.sqlite-wal holds the last frames, and readers
// fold it in; docs/scenarios.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::scenario {

// Identity of a run, written once.
struct RunHeader {
  std::string scenario_json;    // the scenario as given
  std::string scenario_origin;  // its file
  std::string walkable_wkt;     // POLYGON/MULTIPOLYGON of the walkable area
  double output_fps = 10.0;
  double time_step_s = 0.0;
  std::uint64_t seed = 0;
  std::vector<std::string> target_names;  // by target index
};

struct Event {
  double time_s = 0.0;
  std::string kind;          // e.g. "fall", "avalanche_start", "numerical_failure"
  std::int64_t person = -1;  // engine index, -1 if none
  std::int64_t other = -1;
  std::string detail;
};

// Everything one frame of the run file holds, copied out of the simulation
// (cheap next to writing it), so that the frame can be written while the
// simulation goes on (FrameWriterThread). Take() reuses the vectors' storage.
struct FrameSnapshot {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::vector<std::uint32_t> person;  // engine index of each entry below (removed people left out)
  std::vector<Vec2> position_m;
  std::vector<Vec2> velocity_m_per_s;
  std::vector<double> angle_rad;
  std::vector<double> angular_velocity_rad_per_s;
  std::vector<engine::PersonState> state;
  std::vector<double> load_n;  // sum of the magnitudes of the contact forces on the person
  bool with_contacts = false;
  std::vector<engine::Contact> contacts;  // every contact when with_contacts, else empty
  std::vector<Event> events;

  void Take(std::int64_t frame, const engine::Simulation& sim, const std::vector<Event>& events, bool with_contacts);
};

class RunFileWriter {
 public:
  // Creates (truncating) the file and writes the header, shapes, persons and walls.
  static RunFileWriter Create(const std::filesystem::path& file, const RunHeader& header,
                              const engine::Simulation& sim);
  // Reopens an existing run to continue after a checkpoint: frames after
  // `last_frame` are deleted (they will be written again identically).
  static RunFileWriter Resume(const std::filesystem::path& file, std::int64_t last_frame);
  RunFileWriter(RunFileWriter&&) noexcept;
  RunFileWriter& operator=(RunFileWriter&&) noexcept;
  ~RunFileWriter();

  // Writes frame `frame` (trajectories, states, contacts if enabled, events) in one transaction.
  void WriteFrame(std::int64_t frame, const engine::Simulation& sim, const std::vector<Event>& events,
                  bool with_contacts);
  void WriteFrame(const FrameSnapshot& snapshot);
  // Records an event outside a frame (e.g. a failure), committed at once.
  void WriteEvent(std::int64_t frame, const Event& event);
  // run.status = "running" | "complete" | "interrupted" | "failed: ..."
  void SetStatus(const std::string& status);
  void SetRunValue(const std::string& key, const std::string& value);

 private:
  RunFileWriter();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes a run's frames on a thread of its own while the caller simulates
// the next ones (`background`), or in turn in the caller's thread. At 10,000
// people with every contact a frame takes SQLite 15 ms, which the steps then
// need not wait for when a core is free; when the simulation's threads
// occupy every core, a writing thread would only interrupt them (an OpenMP
// team waits at each barrier for a member the writer displaced: measured 1.5×
// slower on 2 cores), so the caller writes itself. Frames are committed in
// the order given, each in its own transaction; at most `queue` frames wait
// (the caller blocks beyond that), so memory stays bounded. The first error
// of the writing thread is rethrown by the next Write or Flush. Use the
// RunFileWriter itself only after Flush (checkpoints, status, events outside
// frames): a checkpoint must never name a frame that is not yet in the file.
class FrameWriterThread {
 public:
  FrameWriterThread(RunFileWriter& writer, bool background, std::size_t queue = 2);
  // Writes what is still queued, then stops (errors there are dropped: call
  // Flush to see them).
  ~FrameWriterThread();
  FrameWriterThread(const FrameWriterThread&) = delete;
  FrameWriterThread& operator=(const FrameWriterThread&) = delete;

  // Copies the frame out of `sim` and queues it.
  void Write(std::int64_t frame, const engine::Simulation& sim, const std::vector<Event>& events, bool with_contacts);
  // Returns once every queued frame is committed.
  void Flush();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What the readers accept in a run file. A value outside (or text, NULL, NaN
// where a number belongs) is a damaged file, reported with the table, row and
// column, never analysed or drawn. The bounds are far beyond any run: twice
// the venue coordinate limit, a hundred times the speed of a rifle bullet.
namespace run_limits {
inline constexpr double kCoordinate_m = 2e7;     // positions, contact points, wall points, lengths
inline constexpr double kUnit = 1.0 + 1e-6;      // components of orientations and normals
inline constexpr double kSpeed_m_per_s = 1e5;
inline constexpr double kForce_n = 1e12;         // contact forces, loads
inline constexpr double kTime_s = 1e9;
inline constexpr double kRadius_m = 10.0;        // sphero-radii of bodies and walls
inline constexpr std::int64_t kFrame = std::int64_t{1} << 53;
inline constexpr std::int64_t kPersonId = 10'000'000;
inline constexpr std::int64_t kGroup = 1023;
}  // namespace run_limits

// Reading a run back (render, reports, tests).
struct RunFrame {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::vector<std::int64_t> ids;  // 1-based
  std::vector<Vec2> position_m;
  std::vector<Vec2> orientation;  // unit vector the chest faces
  std::vector<engine::Contact> contacts;  // a, b as engine indices (id - 1) / wall index
};

class RunFileReader {
 public:
  explicit RunFileReader(const std::filesystem::path& file);
  RunFileReader(RunFileReader&&) noexcept;
  ~RunFileReader();

  std::string RunValue(const std::string& key) const;  // "" if absent
  // A run value that must be a number in [min, max]; absent: `fallback`.
  double RunNumber(const std::string& key, double fallback, double min, double max) const;
  double fps() const;
  std::string walkable_wkt() const;
  std::vector<std::int64_t> Frames() const;
  RunFrame Frame(std::int64_t frame) const;
  // Shapes (body frame) and each person's shape index.
  std::vector<engine::BodyShape> Shapes() const;
  std::vector<std::uint32_t> PersonShapes() const;
  std::vector<std::uint32_t> PersonGroups() const;
  std::vector<engine::Wall> Walls() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A previous crowdrecon run file (SQLite whose run table says format
// crowdrecon-run), which `simulate -o` may replace (common/output_path.hpp).
OutputKind RunFileOutput();
// True if `file` is a crowdrecon run file (false for anything else, no error).
bool IsRunFile(const std::filesystem::path& file);

}  // namespace crowdrecon::scenario
