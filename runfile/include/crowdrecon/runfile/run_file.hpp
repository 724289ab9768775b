// Run files: one SQLite file per run, readable by the field's tools, and by
// crowdrecon's analysis, renderer, reports and calibration without the engine
// (this library depends on common and SQLite only).
//
// JuPedSim trajectory format, version 2 (what PedPy's
// load_trajectory_from_jupedsim_sqlite and load_walkable_area_from_jupedsim_sqlite read):
//   trajectory_data(frame INTEGER, id INTEGER, pos_x REAL, pos_y REAL, ori_x REAL, ori_y REAL)
//   metadata(key TEXT PRIMARY KEY, value TEXT)   version = 2, fps, xmin, xmax, ymin, ymax
//   geometry(hash INTEGER, wkt TEXT)             the walkable area as WKT
//   frame_data(frame INTEGER, geometry_hash INTEGER)
// plus crowdrecon's own tables in the same file:
//   run(key TEXT PRIMARY KEY, value TEXT)        scenario JSON, venue JSON, seed, time step, status, ...
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
//   frame_pack(frame INTEGER PRIMARY KEY, key, xmin, xmax, ymin, ymax, data BLOB)
//           a packed run's people (run value frames = "packed"; src/frame_pack.hpp):
//           every frame's rows of trajectory_data, person_state and person_load,
//           without loss, in a tenth of their bytes; those tables are then
//           empty, and this reader gives the same frames, loads and digest
//           from either storage (PedPy reads `crowdrecon export`'s file)
//   contact_kept(frame INTEGER PRIMARY KEY, why TEXT)   a run that keeps some
//           frames' contacts (run.contacts as an object): the frames whose rows
//           table contact holds, and why
//   contact_forces(frame INTEGER PRIMARY KEY, f0_n, zero, total, bins TEXT)  the
//           same runs: each frame's contact forces in the report's histogram
//           (|F| / f0_n, reports::ForceHistogram's bins, "bin:count ...")
//   census(frame INTEGER PRIMARY KEY, time_s, walking, fallen, removed, queued, entered)
//           a timeline's head count per frame (runs with a timeline only):
//           people walking and fallen in the venue, removed through an exit,
//           waiting at an entry, and entered so far (the people of the start
//           included); entered = walking + fallen + removed in every frame
// Person ids in every table are 1-based in trajectory_data/person (as PedPy
// expects ids), i.e. person index + 1; contact.a/b use the same ids. In this
// library's records (Contact, PersonFrame.person, Event) people are 0-based
// indices, as in the engine.
//
// The run table's key `venue` holds the venue the run was simulated in, as
// venue JSON (docs/venues.md), so that a run file is self-contained: its
// analysis needs no other file and does not depend on where it is opened.
// Run files written before this key existed have no venue (format_version 1).
//
// Each frame is one transaction: a run killed at any moment leaves a valid
// file holding every frame committed so far (in write-ahead-log mode while
// written: a killed run's RUN.sqlite-wal holds the last frames, and readers
// fold it in; docs/scenarios.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::runfile {

// The codes of person_state.state (the engine's PersonState has the same
// values; scenario/src/frame_snapshot.cpp checks that at compile time).
enum class PersonStatus : std::uint8_t {
  kWalking = 0,
  kFallen = 1,   // lies on the floor, an obstacle to others
  kRemoved = 2,  // left the venue; not in the frame tables after it left
};

// Identity of a run, written once.
struct RunHeader {
  std::string scenario_json;    // the scenario as given
  std::string scenario_origin;  // its file
  std::string venue_json;       // the venue as venue JSON ("" when the scenario has none)
  std::string walkable_wkt;     // POLYGON/MULTIPOLYGON of the walkable area
  PeriodicBox periodic_box;     // of a periodic run (run value periodic_box, written when any())
  double output_fps = 10.0;
  double time_step_s = 0.0;
  std::uint64_t seed = 0;
  // The people's frames packed without loss (table frame_pack, run value
  // frames = "packed"; run_file_reader reads them as the tables) instead of
  // rows of trajectory_data, person_state and person_load (issue 66).
  bool packed = false;
};

// A body shape in its own frame: a convex polygon swept by a disc of radius_m.
struct Shape {
  double radius_m = 0.0;
  std::vector<Vec2> vertices;
};

// A wall polyline (closed: a polygon) swept by a disc of radius_m.
struct Wall {
  bool closed = false;
  double radius_m = 0.0;
  std::vector<Vec2> points;
};

// A person as placed at the start of the run (table person).
struct Person {
  std::uint32_t shape = 0;  // index into RunSetup::shapes
  double mass_kg = 0.0;
  double inertia_kg_m2 = 0.0;
  double desired_speed_m_per_s = 0.0;
  std::uint32_t group = 0;
  std::string target;  // the venue target's name
};

// Everything the file stores of a run before its first frame.
struct RunSetup {
  std::vector<Shape> shapes;
  std::vector<Person> people;  // index = person index (id - 1)
  std::vector<Wall> walls;
};

// One contact of a frame: a and b are person indices (b a wall index when
// wall); the forces act on a.
struct Contact {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  bool wall = false;
  Vec2 point_m;
  Vec2 normal;  // unit, from b to a
  double overlap_m = 0.0;
  double normal_force_n = 0.0;      // along normal
  double tangential_force_n = 0.0;  // along Perp(normal)
  constexpr Vec2 Force() const { return normal * normal_force_n + Perp(normal) * tangential_force_n; }
};

// A frame's contacts in brief (table contact_summary, issue 66): written
// every frame whether or not the contacts are, so that what analysis needs of
// them (the largest overlap, its frame and whether a wall made it) is read
// without reading every contact of a run. The largest overlap is the first
// contact with it in the frame's order (the order of table contact's rows).
struct ContactSummary {
  std::int64_t contacts = 0, wall_contacts = 0;
  double max_overlap_m = 0.0;
  bool max_overlap_wall = false;
  double max_force_n = 0.0;  // the largest |Contact::Force()|
};
ContactSummary SummarizeContacts(const std::vector<Contact>& contacts);

// A timeline's head count at a frame (table census).
struct Census {
  std::int64_t walking = 0, fallen = 0, removed = 0, queued = 0, entered = 0;
};

struct CensusRow {
  std::int64_t frame = 0;
  double time_s = 0.0;
  Census census;
};

struct Event {
  double time_s = 0.0;
  std::string kind;          // e.g. "fall", "avalanche_start", "numerical_failure"
  std::int64_t person = -1;  // person index, -1 if none
  std::int64_t other = -1;
  std::string detail;
};

// Everything one frame of the run file holds, copied out of the simulation
// (cheap next to writing it: scenario::TakeSnapshot), so that the frame can
// be written while the simulation goes on (FrameWriterThread). Whoever fills
// it reuses the vectors' storage.
struct FrameSnapshot {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::vector<std::uint32_t> person;  // person index of each entry below (removed people left out)
  std::vector<Vec2> position_m;
  std::vector<Vec2> velocity_m_per_s;
  std::vector<double> angle_rad;
  std::vector<double> angular_velocity_rad_per_s;
  std::vector<PersonStatus> state;
  std::vector<double> load_n;  // sum of the magnitudes of the contact forces on the person
  // The load across the chest and across the shoulders (reports/chest_load.hpp),
  // written to table person_load where not both zero; empty: none written.
  std::vector<double> chest_load_n, lateral_load_n;
  // Every contact of the frame (their brief is written whatever
  // with_contacts says: table contact_summary); the rows themselves (table
  // contact) only when with_contacts.
  bool with_contacts = false;
  std::vector<Contact> contacts;
  std::vector<Event> events;
  bool with_census = false;  // a timeline's run: census holds the head count
  Census census;
  // A run that keeps the contacts of some frames only (run.contacts as an
  // object; issue 66): with_contacts says whether this frame's rows are
  // kept and kept_because why (table contact_kept: "every 10 s", "worst
  // moment"); the rows of frames in drop_contacts_of go now (worst moments
  // since superseded); every contact's force in the histogram of the report
  // (reports::ForceHistogram's bins of |F| / force_f0_n, as "bin:count"
  // pairs; table contact_forces), so that its distribution needs no rows.
  bool lean_contacts = false;
  std::string kept_because;
  std::vector<std::int64_t> drop_contacts_of;
  double force_f0_n = 0.0;
  std::uint64_t force_zero = 0, force_total = 0;
  std::vector<std::pair<std::uint32_t, std::uint64_t>> force_bins;
};

// A run's contact forces binned as its frames recorded them (table
// contact_forces): the sum over frames.
struct ContactForceBins {
  double f0_n = 0.0;
  std::uint64_t zero = 0, total = 0;
  std::vector<std::uint64_t> counts;  // by bin
};

// Held while a run file is written (simulate, a resume, analyze --write):
// an advisory lock (flock) on RUN.lock beside it, taken before anything is
// removed or written. A second writer is refused with a message instead of
// replacing a run in progress under the first (issue 65: two simulate with
// the same -o both said "complete", the file held the second). The lock file
// is removed when the lock is let go; one left by a killed writer holds no
// lock and is taken over.
class RunFileLock {
 public:
  // Throws InputError naming the run file if another process holds its lock.
  explicit RunFileLock(const std::filesystem::path& run_file);
  ~RunFileLock();
  RunFileLock(const RunFileLock&) = delete;
  RunFileLock& operator=(const RunFileLock&) = delete;
  // RUN.lock.
  static std::filesystem::path PathOf(const std::filesystem::path& run_file);

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

class RunFileWriter {
 public:
  // Creates (truncating) the file and writes the header, shapes, people and walls.
  static RunFileWriter Create(const std::filesystem::path& file, const RunHeader& header, const RunSetup& setup);
  // Reopens an existing run to continue after a checkpoint: frames after
  // `last_frame` are deleted (they will be written again identically), and
  // what was derived from the frames is dropped: tables metric_* and the run
  // values listed (a JSON list) under the run value "derived_keys".
  static RunFileWriter Resume(const std::filesystem::path& file, std::int64_t last_frame);
  // Starts a new segment of run `previous` (issue 66: a long run continued
  // into a new file, on another machine or day): `file` gets `previous`'s
  // header (scenario, venue, shapes, people, walls, storage, run values) and
  // no frame; run values continues (`previous`'s path from `file`'s
  // folder), continues_at_frame (`previous`'s last frame, its checkpoint's)
  // and segment (1 for the first continuation). Readers of `file` read the
  // chain from its first segment as one run. Status "interrupted": the caller
  // continues it with Resume(file, at_frame).
  static void StartSegment(const std::filesystem::path& file, const std::filesystem::path& previous,
                           std::int64_t at_frame);
  RunFileWriter(RunFileWriter&&) noexcept;
  RunFileWriter& operator=(RunFileWriter&&) noexcept;
  ~RunFileWriter();

  // Writes one frame (trajectories, states, contacts if taken, events) in one transaction.
  void WriteFrame(const FrameSnapshot& snapshot);
  // Records an event outside a frame (e.g. a failure), committed at once.
  void WriteEvent(std::int64_t frame, const Event& event);
  // Drops the contact rows (and table contact_kept's rows) of these frames,
  // in one transaction: a run that keeps some frames' contacts, at its end.
  void DropContacts(const std::vector<std::int64_t>& frames);
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

  // Has `fill` copy the frame into a snapshot (one whose storage is reused)
  // in the caller's thread, then queues it.
  void Write(const std::function<void(FrameSnapshot&)>& fill);
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
inline constexpr double kAngle_rad = 1e9;             // orientations are not wrapped into [-pi, pi)
inline constexpr double kAngularSpeed_rad_per_s = 1e5;
inline constexpr double kForce_n = 1e12;         // contact forces, loads
inline constexpr double kTime_s = 1e9;
inline constexpr double kRadius_m = 10.0;        // sphero-radii of bodies and walls
inline constexpr double kMass_kg = 1e4;          // masses; inertias up to kMass_kg * kRadius_m^2
inline constexpr std::int64_t kFrame = std::int64_t{1} << 53;
inline constexpr std::int64_t kPersonId = 10'000'000;
inline constexpr std::int64_t kGroup = 1023;
}  // namespace run_limits

// Reading a run back: the trajectory of one frame, as PedPy sees it.
struct RunFrame {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::vector<std::int64_t> ids;  // 1-based
  std::vector<Vec2> position_m;
  std::vector<Vec2> orientation;  // unit vector the chest faces
  std::vector<Contact> contacts;
};

struct FrameTime {
  std::int64_t frame = 0;
  double time_s = 0.0;
};

// The state of every person present in one frame (trajectory_data joined with
// person_state), for analysis, reports and calibration.
struct PersonFrame {
  std::int64_t frame = 0;
  std::vector<std::uint32_t> person;  // person index (id - 1), ascending
  std::vector<Vec2> position_m;
  std::vector<Vec2> velocity_m_per_s;
  std::vector<double> angle_rad;
  std::vector<double> angular_velocity_rad_per_s;
  std::vector<PersonStatus> state;
  std::vector<double> load_n;
};

class RunFileReader;

// The frames of a run in order, one PersonFrame at a time (one query, so that
// a long run is read in one pass without holding it in memory).
class PersonFrameStream {
 public:
  PersonFrameStream(PersonFrameStream&&) noexcept;
  ~PersonFrameStream();
  // Fills `out` with the next frame; false after the last.
  bool Next(PersonFrame* out);

 private:
  friend class RunFileReader;
  PersonFrameStream();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One person's chest loads in a frame (table person_load; people without
// load have no row).
struct PersonLoad {
  std::uint32_t person = 0;  // person index (id - 1)
  double chest_n = 0.0, lateral_n = 0.0;
};

// The person_load rows of a run frame by frame, in order (frames where nobody
// is loaded are skipped: compare the frame numbers).
class PersonLoadStream {
 public:
  PersonLoadStream(PersonLoadStream&&) noexcept;
  ~PersonLoadStream();
  bool Next(std::int64_t* frame, std::vector<PersonLoad>* out);

 private:
  friend class RunFileReader;
  PersonLoadStream();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The contacts of a run frame by frame, in order (one query; frames without
// contacts are skipped: compare the frame numbers).
class ContactFrameStream {
 public:
  ContactFrameStream(ContactFrameStream&&) noexcept;
  ~ContactFrameStream();
  // Fills `frame` and `out` with the next frame that has contacts; false after the last.
  bool Next(std::int64_t* frame, std::vector<Contact>* out);

 private:
  friend class RunFileReader;
  ContactFrameStream();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A run written in segments (simulate --continue-from; run value
// `continues`) is read as one run from its last segment: the reader opens the
// segments before it (each named by the next, relative to its folder) and
// gives their frames, contacts, events and digest in order, as the run made
// in one go; header values (scenario, people, shapes, walls) are the last
// segment's, which are every segment's, and so are its status and run values.
class RunFileReader {
 public:
  explicit RunFileReader(const std::filesystem::path& file);
  // `file` alone, without the segments before it (its header, run values and
  // own frames): to continue or check a segment whose predecessors are elsewhere.
  static RunFileReader OneSegment(const std::filesystem::path& file);
  RunFileReader(RunFileReader&&) noexcept;
  ~RunFileReader();

  const std::string& file() const;
  std::string RunValue(const std::string& key) const;  // "" if absent
  // "" for a finished run (status "complete"); otherwise one sentence for the
  // outputs drawn from it: its status, what it means and how far it got
  // ("... unfinished (status \"running\": still being written, or killed):
  // what follows covers its frames up to t = 12.3 s only; ...").
  // SHA-256 of every table the run writes per frame (trajectory_data,
  // person_state, contact, frame_time, event, and person_load and census
  // where present), row by row in a fixed order, each value with its type.
  // A run resumed from a checkpoint has the same digest as the run that was
  // never stopped, though the files' own bytes differ (SQLite's pages are
  // laid out by the order of writing): `crowdrecon analyze RUN --digest`.
  std::string TablesDigest() const;
  std::string UnfinishedNote() const;
  // A run value that must be a number in [min, max]; absent: `fallback`.
  double RunNumber(const std::string& key, double fallback, double min, double max) const;
  double fps() const;
  std::string walkable_wkt() const;
  // The venue JSON stored with the run ("" in run files written before it was).
  std::string venue_json() const;
  // The periodic box (run value periodic_box = {"x": true, "y": false,
  // "min_m": [x, y], "max_m": [x, y]}); none recorded: no periodic axis.
  PeriodicBox periodic_box() const;
  std::vector<std::int64_t> Frames() const;
  std::vector<FrameTime> FrameTimes() const;
  RunFrame Frame(std::int64_t frame) const;
  // Every frame up to `last_frame` inclusive, in order.
  PersonFrameStream PersonFrames(std::int64_t last_frame) const;
  // Every frame's contacts up to `last_frame` inclusive, in order.
  ContactFrameStream ContactFrames(std::int64_t last_frame) const;
  // Whether the run records chest loads (table person_load; runs written
  // before 2026-11-26 do not), and those loads frame by frame.
  bool HasPersonLoads() const;
  PersonLoadStream PersonLoads(std::int64_t last_frame) const;
  // The sum of every recorded velocity of each group's people (index = group).
  // The contact with the largest overlap of the run (the earliest of equal
  // ones), in one query; nullopt when the run has no contacts.
  struct LargestOverlap {
    std::int64_t frame = 0;
    double overlap_m = 0.0;
    bool wall = false;
  };
  std::optional<LargestOverlap> LargestContactOverlap() const;
  // Whether the run has its frames' contact briefs (table contact_summary,
  // runs from 2026-12-06 on): then its overlaps are known even where the
  // contacts were not written, or none happened.
  bool HasContactSummary() const;
  // Whether the run keeps the contacts of some frames only (table
  // contact_kept), and which (with why: "every 10 s", "worst moment").
  bool KeepsSomeContacts() const;
  std::vector<std::pair<std::int64_t, std::string>> ContactKeptFrames() const;
  // The contact forces of every frame up to `last_frame` binned (table
  // contact_forces; nullopt without it); `bins` bounds the bin numbers.
  std::optional<ContactForceBins> ContactForces(std::int64_t last_frame, std::size_t bins) const;
  std::vector<Vec2> GroupVelocitySums() const;
  std::vector<Event> Events() const;
  // A timeline's head count per frame (empty for a run without a timeline).
  std::vector<CensusRow> CensusRows() const;
  // Shapes (body frame) and each person's shape index.
  std::vector<Shape> Shapes() const;
  std::vector<Person> People() const;  // index = person index (id - 1)
  std::vector<std::uint32_t> PersonShapes() const;
  std::vector<std::uint32_t> PersonGroups() const;
  std::vector<Wall> Walls() const;
  // Whether the people's frames are packed (table frame_pack).
  bool packed() const;
  // The run's segment files, first to last (one: a run in one file).
  std::vector<std::string> SegmentFiles() const;
  // What RunFileWriter::Create wrote of the run before its first frame
  // (header: its storage included; setup: shapes, people, walls), to write
  // another file of the same run (a segment, the run with tables).
  RunHeader Header() const;
  RunSetup Setup() const;

 private:
  friend struct ChainAccess;
  RunFileReader(const std::filesystem::path& file, bool follow_segments);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A previous crowdrecon run file (SQLite whose run table says format
// crowdrecon-run), which `simulate -o` may replace (common/output_path.hpp).
OutputKind RunFileOutput();
// True if `file` is a crowdrecon run file (false for anything else, no error).
bool IsRunFile(const std::filesystem::path& file);
// What `file`, which is not a run file, is: DescribeExisting's words, or for
// an SQLite file that SQLite cannot read "a damaged SQLite file (SQLite:
// database disk image is malformed; a run file cut short or damaged, which
// cannot be read or resumed)" (issue 65: such a file was called "not a
// crowdrecon run file", and replacing it was offered for a resume).
std::string DescribeNonRunFile(const std::filesystem::path& file);
// Copies the run file `from` to `to` (which must not exist): a consistent
// snapshot, also of a run being written (SQLite's VACUUM INTO). For a run
// branched at a checkpoint (scenario::BranchRun).
void CopyRunFile(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace crowdrecon::runfile
