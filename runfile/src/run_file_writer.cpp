// Writing run files (run_file.hpp): the writer, its frames, events and run values, the writer thread.
#include "crowdrecon/runfile/run_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "frame_pack.hpp"
#include "jupedsim_tables.hpp"

namespace crowdrecon::runfile {

namespace {

using sqlite::Database;
using sqlite::Statement;

using detail::GeometryHash;
using detail::NumberText;

std::string PointsJson(const std::vector<Vec2>& points) {
  nlohmann::json j = nlohmann::json::array();
  for (const Vec2& p : points) j.push_back({p.x, p.y});
  return j.dump();
}

// The writer's connection is used by one thread at a time (the caller, or
// FrameWriterThread's thread between handoffs under its mutex), so SQLite
// need not lock it around every call (a tenth of the time of writing frames).
constexpr int kWriterMutexMode = SQLITE_OPEN_NOMUTEX;

// While a run is written, the file is in write-ahead-log mode: a frame's
// commit appends to RUN.sqlite-wal without waiting for the disk (with
// synchronous=NORMAL a crash of the machine may lose the last frames, never
// the file's consistency; a crash of the program loses nothing committed).
// Rollback journalling synced every commit: at 400 people that was half the
// time of writing a frame. Closing the writer returns the file to rollback
// journalling, so a finished run is one plain file; a run killed outright
// leaves its -wal and -shm files, which SQLite (and every reader) folds back
// in when the file is next opened.
constexpr const char* kJournal = "PRAGMA journal_mode=WAL";

// crowdrecon's own tables, after the JuPedSim ones (jupedsim_tables.hpp).
constexpr const char* kSchema = R"SQL(
CREATE INDEX frame_id_idx ON trajectory_data(frame, id);
CREATE TABLE run(key TEXT NOT NULL PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE shape(id INTEGER PRIMARY KEY, radius_m REAL NOT NULL, vertices TEXT NOT NULL);
CREATE TABLE person(id INTEGER PRIMARY KEY, shape INTEGER NOT NULL, mass_kg REAL NOT NULL,
  inertia_kg_m2 REAL NOT NULL, desired_speed_m_per_s REAL NOT NULL, grp INTEGER NOT NULL, target TEXT NOT NULL);
CREATE TABLE wall(id INTEGER PRIMARY KEY, closed INTEGER NOT NULL, radius_m REAL NOT NULL, points TEXT NOT NULL);
CREATE TABLE frame_time(frame INTEGER PRIMARY KEY, time_s REAL NOT NULL);
CREATE TABLE person_state(frame INTEGER NOT NULL, id INTEGER NOT NULL, vel_x REAL NOT NULL, vel_y REAL NOT NULL,
  angle_rad REAL NOT NULL, omega_rad_per_s REAL NOT NULL, state INTEGER NOT NULL, load_n REAL NOT NULL);
CREATE INDEX person_state_idx ON person_state(frame, id);
CREATE TABLE contact(frame INTEGER NOT NULL, a INTEGER NOT NULL, b INTEGER NOT NULL, wall INTEGER NOT NULL,
  point_x REAL NOT NULL, point_y REAL NOT NULL, normal_x REAL NOT NULL, normal_y REAL NOT NULL,
  overlap_m REAL NOT NULL, normal_force_n REAL NOT NULL, tangential_force_n REAL NOT NULL);
CREATE INDEX contact_frame_idx ON contact(frame);
CREATE TABLE person_load(frame INTEGER NOT NULL, id INTEGER NOT NULL, chest_n REAL NOT NULL, lateral_n REAL NOT NULL);
CREATE INDEX person_load_idx ON person_load(frame, id);
CREATE TABLE event(frame INTEGER NOT NULL, time_s REAL NOT NULL, kind TEXT NOT NULL, person INTEGER NOT NULL,
  other INTEGER NOT NULL, detail TEXT NOT NULL);
CREATE TABLE contact_summary(frame INTEGER PRIMARY KEY, contacts INTEGER NOT NULL, wall_contacts INTEGER NOT NULL,
  max_overlap_m REAL NOT NULL, max_overlap_wall INTEGER NOT NULL, max_force_n REAL NOT NULL);
)SQL";

// The people of a packed run (frame_pack.hpp), instead of rows of
// trajectory_data, person_state and person_load (which stay, empty).
constexpr const char* kPackSchema = R"SQL(
CREATE TABLE frame_pack(frame INTEGER PRIMARY KEY, key INTEGER NOT NULL, xmin REAL, xmax REAL, ymin REAL, ymax REAL,
  data BLOB NOT NULL);
)SQL";

// What was derived from the run's frames (an analysis stored with analyze
// --write: tables metric_*, and the run values it lists under
// "derived_keys") no longer describes a run whose frames change (issue 65: a
// resumed run kept the analysis of its first half): dropped.
void ForgetDerived(Database& db) {
  std::vector<std::string> tables;
  {
    Statement s(db, "SELECT name FROM sqlite_master WHERE type = 'table' AND name LIKE 'metric\\_%' ESCAPE '\\'");
    while (s.Next()) tables.push_back(s.Text(0));
  }
  for (const std::string& t : tables) db.Exec("DROP TABLE IF EXISTS \"" + t + "\"");
  std::string listed;
  {
    Statement s(db, "SELECT value FROM run WHERE key = 'derived_keys'");
    if (s.Next()) listed = s.Text(0);
  }
  if (listed.empty()) return;
  const nlohmann::json keys = nlohmann::json::parse(listed, nullptr, false);
  Statement erase(db, "DELETE FROM run WHERE key = ?");
  if (keys.is_array())
    for (const nlohmann::json& k : keys)
      if (k.is_string()) erase.Bind(1, k.get<std::string>()).Run();
  erase.Bind(1, std::string("derived_keys")).Run();
}

// The rows of these frames in tables contact and contact_kept; in a
// segment of a run, frames of the segments before it (at or before
// `continues_at`) are listed in table contact_dropped instead (with the
// frame at which they were dropped, undone by a resume before it), which
// readers of the chain apply to them.
void DropContactRows(Database& db, const std::vector<std::int64_t>& frames, std::int64_t continues_at,
                     std::int64_t at_frame) {
  if (frames.empty()) return;
  Statement drop_rows(db, "DELETE FROM contact WHERE frame = ?");
  Statement drop_kept(db, "DELETE FROM contact_kept WHERE frame = ?");
  std::unique_ptr<Statement> dropped;
  for (const std::int64_t d : frames) {
    if (d <= continues_at) {
      if (!dropped) {
        db.Exec("CREATE TABLE IF NOT EXISTS contact_dropped(frame INTEGER PRIMARY KEY, at_frame INTEGER NOT NULL)");
        dropped = std::make_unique<Statement>(db, "INSERT OR IGNORE INTO contact_dropped VALUES(?, ?)");
      }
      dropped->Bind(1, d).Bind(2, at_frame).Run();
      continue;
    }
    drop_rows.Bind(1, d).Run();
    drop_kept.Bind(1, d).Run();
  }
}

}  // namespace

struct RunFileWriter::Impl {
  std::unique_ptr<Database> db;
  // The frame tables' inserts, prepared once (WriteFrame).
  std::unique_ptr<sqlite::BatchInsert> trajectory, person_state, contact, person_load;
  bool has_person_load = true;  // false for a resumed run file written before the table existed
  bool has_contact_summary = true;  // likewise (issue 66)
  // A packed run (RunHeader::packed): its packer, and the frames this writer
  // has written (its first one, and every kKeyInterval-th, is a key frame).
  std::unique_ptr<detail::FramePacker> packer;
  std::int64_t packed_frames = 0;
  std::int64_t continues_at = -1;  // a segment of a run: the last frame of the segments before it
  std::int64_t last_frame = -1;    // the last frame written (or kept by a resume)
  std::int64_t geometry_hash = 0;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -std::numeric_limits<double>::infinity();
  double ymin = std::numeric_limits<double>::infinity(), ymax = -std::numeric_limits<double>::infinity();
};

RunFileWriter::RunFileWriter() : impl_(std::make_unique<Impl>()) {}
RunFileWriter::RunFileWriter(RunFileWriter&&) noexcept = default;
RunFileWriter& RunFileWriter::operator=(RunFileWriter&&) noexcept = default;
RunFileWriter::~RunFileWriter() {
  if (!impl_ || !impl_->db) return;  // moved from
  impl_->trajectory.reset();
  impl_->person_state.reset();
  impl_->person_load.reset();
  impl_->contact.reset();
  try {
    impl_->db->Exec("PRAGMA journal_mode=DELETE");  // see kJournal
  } catch (const std::exception&) {
    // Still a valid file in WAL mode; readers fold the log in.
  }
}

std::filesystem::path RunFileLock::PathOf(const std::filesystem::path& run_file) {
  return run_file.string() + ".lock";
}

RunFileLock::RunFileLock(const std::filesystem::path& run_file) : path_(PathOf(run_file)) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  // A folder that cannot hold the lock cannot hold the run either: the
  // writer's own message says so (a missing folder, no permission).
  if (fd_ < 0) return;
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK)
      throw InputError(run_file.string() + ": being written by another crowdrecon process (it holds " +
                       path_.filename().string() + "); wait until it ends, or choose another output");
  }
}

RunFileLock::~RunFileLock() {
  if (fd_ < 0) return;
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);  // (while held: a newcomer locks a file of its own)
  ::flock(fd_, LOCK_UN);
  ::close(fd_);
}

RunFileWriter RunFileWriter::Create(const std::filesystem::path& file, const RunHeader& header,
                                    const RunSetup& setup) {
  // The caller checked the path (CheckOutputs: a previous run file, or a
  // file --force lets us replace); a folder is never removed here.
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file.string() + ": exists and is " + DescribeExisting(file) +
                     ", not a crowdrecon run file; a folder is never replaced by a file");
  std::filesystem::remove(file, ec);
  sqlite::RemoveSidecars(file);
  RunFileWriter w;
  // A file that could not be made whole (a full disk, a file-size limit) is
  // removed with its logs: nothing is left that looks like a run.
  try {
    w.impl_->db = std::make_unique<Database>(file, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | kWriterMutexMode);
    Database& db = *w.impl_->db;
    // A packed frame is a blob of a few kB to a few hundred: in SQLite's
    // 4 kB pages a third of the file was the pages' unused ends (measured on
    // the Madrid night: 64 bytes a person-frame in the file for 47 in the
    // blobs); in 16 kB pages a few percent. Set before anything is written.
    if (header.packed) db.Exec("PRAGMA page_size=16384");
    db.Exec(kJournal);
    db.Exec("PRAGMA synchronous=NORMAL");
    db.Exec("BEGIN");
    db.Exec(detail::kJuPedSimSchema);
    db.Exec(kSchema);
    if (header.packed) {
      db.Exec(kPackSchema);
      w.impl_->packer = std::make_unique<detail::FramePacker>();
    }
    w.impl_->geometry_hash = GeometryHash(header.walkable_wkt);
    {
      Statement meta(db, "INSERT INTO metadata VALUES(?, ?)");
      meta.Bind(1, std::string("version")).Bind(2, std::string("2")).Run();
      meta.Bind(1, std::string("fps")).Bind(2, NumberText(header.output_fps)).Run();
      Statement geo(db, "INSERT INTO geometry VALUES(?, ?)");
      geo.Bind(1, w.impl_->geometry_hash).Bind(2, header.walkable_wkt).Run();
      Statement run(db, "INSERT INTO run VALUES(?, ?)");
      const auto put = [&](const std::string& k, const std::string& v) { run.Bind(1, k).Bind(2, v).Run(); };
      put("format", "crowdrecon-run");
      put("format_version", "2");  // 2: the venue is stored (key venue)
      put("scenario", header.scenario_json);
      put("scenario_file", header.scenario_origin);
      put("seed", std::to_string(header.seed));
      put("time_step_s", NumberText(header.time_step_s));
      put("output_fps", NumberText(header.output_fps));
      put("status", "running");
      if (header.packed) put("frames", "packed");
      if (!header.venue_json.empty()) put("venue", header.venue_json);
      const PeriodicBox& box = header.periodic_box;
      if (box.any()) {
        const nlohmann::json j = {{"x", box.x}, {"y", box.y}, {"min_m", {box.min_m.x, box.min_m.y}},
                                  {"max_m", {box.max_m.x, box.max_m.y}}};
        put("periodic_box", j.dump());
      }
    }
    {
      Statement shape(db, "INSERT INTO shape VALUES(?, ?, ?)");
      for (std::size_t s = 0; s < setup.shapes.size(); ++s)
        shape.Bind(1, static_cast<std::int64_t>(s)).Bind(2, setup.shapes[s].radius_m).Bind(3, PointsJson(setup.shapes[s].vertices)).Run();
      Statement person(db, "INSERT INTO person VALUES(?, ?, ?, ?, ?, ?, ?)");
      for (std::size_t i = 0; i < setup.people.size(); ++i) {
        const Person& p = setup.people[i];
        person.Bind(1, static_cast<std::int64_t>(i + 1))
            .Bind(2, static_cast<std::int64_t>(p.shape))
            .Bind(3, p.mass_kg)
            .Bind(4, p.inertia_kg_m2)
            .Bind(5, p.desired_speed_m_per_s)
            .Bind(6, static_cast<std::int64_t>(p.group))
            .Bind(7, p.target)
            .Run();
      }
      Statement wall(db, "INSERT INTO wall VALUES(?, ?, ?, ?)");
      for (std::size_t k = 0; k < setup.walls.size(); ++k)
        wall.Bind(1, static_cast<std::int64_t>(k))
            .Bind(2, static_cast<std::int64_t>(setup.walls[k].closed))
            .Bind(3, setup.walls[k].radius_m)
            .Bind(4, PointsJson(setup.walls[k].points))
            .Run();
    }
    db.Exec("COMMIT");
  } catch (...) {
    w.impl_->db.reset();  // closes the file
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
    sqlite::RemoveSidecars(file);
    throw;
  }
  return w;
}

RunFileWriter RunFileWriter::Resume(const std::filesystem::path& file, std::int64_t last_frame) {
  if (!std::filesystem::exists(file)) throw InputError(file.string() + ": run file to resume does not exist");
  RunFileWriter w;
  w.impl_->db = std::make_unique<Database>(file, SQLITE_OPEN_READWRITE | kWriterMutexMode);
  Database& db = *w.impl_->db;
  db.Exec(kJournal);
  db.Exec("PRAGMA synchronous=NORMAL");
  db.Exec("BEGIN");
  const std::string after = std::to_string(last_frame);
  for (const char* table : {"trajectory_data", "frame_data", "frame_time", "person_state", "contact", "event"})
    db.Exec(std::string("DELETE FROM ") + table + " WHERE frame > " + after);
  ForgetDerived(db);
  w.impl_->has_person_load = sqlite::HasTable(db, "person_load");
  if (w.impl_->has_person_load) db.Exec("DELETE FROM person_load WHERE frame > " + after);
  for (const char* table : {"census", "contact_kept", "contact_forces"})
    if (sqlite::HasTable(db, table)) db.Exec(std::string("DELETE FROM ") + table + " WHERE frame > " + after);
  w.impl_->has_contact_summary = sqlite::HasTable(db, "contact_summary");
  if (w.impl_->has_contact_summary) db.Exec("DELETE FROM contact_summary WHERE frame > " + after);
  {
    Statement at(db, "SELECT value FROM run WHERE key = 'continues_at_frame'");
    if (at.Next()) w.impl_->continues_at = std::strtoll(at.Text(0).c_str(), nullptr, 10);
  }
  if (sqlite::HasTable(db, "contact_dropped")) db.Exec("DELETE FROM contact_dropped WHERE at_frame > " + after);
  w.impl_->last_frame = last_frame;
  const bool packed = sqlite::HasTable(db, "frame_pack");
  if (packed) {
    db.Exec("DELETE FROM frame_pack WHERE frame > " + after);
    w.impl_->packer = std::make_unique<detail::FramePacker>();  // its first frame a key frame
  }
  {
    Statement geo(db, "SELECT hash FROM geometry LIMIT 1");
    if (!geo.Next()) throw InputError(file.string() + ": not a crowdrecon run file (no geometry)");
    w.impl_->geometry_hash = geo.Int(0);
    Statement bounds(db, packed ? "SELECT MIN(xmin), MAX(xmax), MIN(ymin), MAX(ymax), COUNT(xmin) FROM frame_pack"
                                : "SELECT MIN(pos_x), MAX(pos_x), MIN(pos_y), MAX(pos_y), COUNT(*) FROM trajectory_data");
    if (bounds.Next() && bounds.Int(4) > 0) {
      w.impl_->xmin = bounds.Double(0);
      w.impl_->xmax = bounds.Double(1);
      w.impl_->ymin = bounds.Double(2);
      w.impl_->ymax = bounds.Double(3);
    }
  }
  db.Exec("INSERT OR REPLACE INTO run VALUES('status', 'running')");
  db.Exec("COMMIT");
  return w;
}

void RunFileWriter::StartSegment(const std::filesystem::path& file, const std::filesystem::path& previous,
                                 std::int64_t at_frame) {
  const RunFileReader before = RunFileReader::OneSegment(previous);
  const RunHeader header = before.Header();
  const RunSetup setup = before.Setup();
  // Its run values as they were (profile, people, ...), then the chain's.
  std::vector<std::pair<std::string, std::string>> values;
  {
    const Database db(previous.string(), SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);
    Statement s(db, "SELECT key, value FROM run ORDER BY key");
    while (s.Next()) values.emplace_back(s.Text(0), s.Text(1));
  }
  const std::string segment = std::to_string(static_cast<std::int64_t>(before.RunNumber("segment", 0.0, 0.0, 1e9)) + 1);
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::absolute(file, ec).parent_path();
  std::string from = std::filesystem::absolute(previous, ec).lexically_relative(folder).string();
  if (from.empty()) from = std::filesystem::absolute(previous, ec).string();
  RunFileWriter w = Create(file, header, setup);
  try {
    Database& db = *w.impl_->db;
    db.Exec("BEGIN");
    Statement put(db, "INSERT OR REPLACE INTO run VALUES(?, ?)");
    for (const auto& [key, value] : values)
      if (key != "status" && key != "segment_head") put.Bind(1, key).Bind(2, value).Run();  // (a head's mark is its own)
    ForgetDerived(db);  // (what an analysis stored describes the segment before)
    put.Bind(1, std::string("continues")).Bind(2, from).Run();
    put.Bind(1, std::string("continues_at_frame")).Bind(2, std::to_string(at_frame)).Run();
    put.Bind(1, std::string("segment")).Bind(2, segment).Run();
    put.Bind(1, std::string("status")).Bind(2, std::string("interrupted")).Run();
    db.Exec("COMMIT");
  } catch (...) {
    w.impl_->db.reset();
    std::filesystem::remove(file, ec);
    sqlite::RemoveSidecars(file);
    throw;
  }
}

void RunFileWriter::WriteFrame(const FrameSnapshot& f) {
  Database& db = *impl_->db;
  const std::int64_t frame = f.frame;
  impl_->last_frame = frame;
  db.Exec("BEGIN");
  {
    if (!impl_->trajectory) {
      impl_->trajectory = std::make_unique<sqlite::BatchInsert>(db, "trajectory_data", 6);
      impl_->person_state = std::make_unique<sqlite::BatchInsert>(db, "person_state", 8);
      impl_->contact = std::make_unique<sqlite::BatchInsert>(db, "contact", 11);
      if (impl_->has_person_load) impl_->person_load = std::make_unique<sqlite::BatchInsert>(db, "person_load", 4);
    }
    sqlite::BatchInsert& traj = *impl_->trajectory;
    sqlite::BatchInsert& state = *impl_->person_state;
    for (sqlite::BatchInsert* batch : {&traj, &state, impl_->contact.get()}) batch->Discard();
    if (impl_->person_load) impl_->person_load->Discard();
    if (impl_->packer) {
      const bool key = impl_->packed_frames % detail::kKeyInterval == 0;
      const std::string data = impl_->packer->Pack(f, key);
      ++impl_->packed_frames;
      Statement pack(db, "INSERT INTO frame_pack VALUES(?, ?, ?, ?, ?, ?, ?)");
      pack.Bind(1, frame).Bind(2, std::int64_t{key});
      if (f.person.empty()) {
        for (int c = 3; c <= 6; ++c) pack.BindNull(c);
      } else {
        double x0 = f.position_m[0].x, x1 = x0, y0 = f.position_m[0].y, y1 = y0;
        for (const Vec2& x : f.position_m) {
          x0 = std::min(x0, x.x);
          x1 = std::max(x1, x.x);
          y0 = std::min(y0, x.y);
          y1 = std::max(y1, x.y);
        }
        pack.Bind(3, x0).Bind(4, x1).Bind(5, y0).Bind(6, y1);
        impl_->xmin = std::min(impl_->xmin, x0);
        impl_->xmax = std::max(impl_->xmax, x1);
        impl_->ymin = std::min(impl_->ymin, y0);
        impl_->ymax = std::max(impl_->ymax, y1);
      }
      pack.BindBlob(7, data).Run();
    }
    for (std::size_t k = 0; !impl_->packer && k < f.person.size(); ++k) {
      const auto id = static_cast<std::int64_t>(f.person[k]) + 1;
      const Vec2 x = f.position_m[k];
      const double angle = f.angle_rad[k];
      const Vec2 ori = detail::OrientationOf(angle);
      traj.Add(frame).Add(id).Add(x.x).Add(x.y).Add(ori.x).Add(ori.y);
      state.Add(frame).Add(id)
          .Add(f.velocity_m_per_s[k].x).Add(f.velocity_m_per_s[k].y)
          .Add(angle).Add(f.angular_velocity_rad_per_s[k])
          .Add(static_cast<std::int64_t>(f.state[k])).Add(f.load_n[k]);
      impl_->xmin = std::min(impl_->xmin, x.x);
      impl_->xmax = std::max(impl_->xmax, x.x);
      impl_->ymin = std::min(impl_->ymin, x.y);
      impl_->ymax = std::max(impl_->ymax, x.y);
    }
    traj.Finish();
    state.Finish();
    if (!impl_->packer && impl_->person_load && f.chest_load_n.size() == f.person.size() &&
        f.lateral_load_n.size() == f.person.size()) {
      sqlite::BatchInsert& loads = *impl_->person_load;
      for (std::size_t k = 0; k < f.person.size(); ++k)
        if (f.chest_load_n[k] != 0.0 || f.lateral_load_n[k] != 0.0)
          loads.Add(frame).Add(static_cast<std::int64_t>(f.person[k]) + 1).Add(f.chest_load_n[k]).Add(f.lateral_load_n[k]);
      loads.Finish();
    }
    if (impl_->has_contact_summary) {
      const ContactSummary c = SummarizeContacts(f.contacts);
      Statement cs(db, "INSERT INTO contact_summary VALUES(?, ?, ?, ?, ?, ?)");
      cs.Bind(1, frame).Bind(2, c.contacts).Bind(3, c.wall_contacts).Bind(4, c.max_overlap_m)
          .Bind(5, static_cast<std::int64_t>(c.max_overlap_wall)).Bind(6, c.max_force_n).Run();
    }
    if (f.with_contacts) {
      sqlite::BatchInsert& contact = *impl_->contact;
      for (const Contact& c : f.contacts)
        contact.Add(frame).Add(static_cast<std::int64_t>(c.a + 1))
            .Add(static_cast<std::int64_t>(c.wall ? c.b : c.b + 1))
            .Add(static_cast<std::int64_t>(c.wall))
            .Add(c.point_m.x).Add(c.point_m.y).Add(c.normal.x).Add(c.normal.y)
            .Add(c.overlap_m).Add(c.normal_force_n).Add(c.tangential_force_n);
      contact.Finish();
    }
    if (f.lean_contacts) {
      db.Exec("CREATE TABLE IF NOT EXISTS contact_kept(frame INTEGER PRIMARY KEY, why TEXT NOT NULL)");
      db.Exec("CREATE TABLE IF NOT EXISTS contact_forces(frame INTEGER PRIMARY KEY, f0_n REAL NOT NULL, "
              "zero INTEGER NOT NULL, total INTEGER NOT NULL, bins TEXT NOT NULL)");
      DropContactRows(db, f.drop_contacts_of, impl_->continues_at, frame);
      if (f.with_contacts) {
        Statement kept(db, "INSERT INTO contact_kept VALUES(?, ?)");
        kept.Bind(1, frame).Bind(2, f.kept_because).Run();
      }
      std::string bins;
      for (const auto& [bin, count] : f.force_bins)
        bins += (bins.empty() ? "" : " ") + std::to_string(bin) + ":" + std::to_string(count);
      Statement forces(db, "INSERT INTO contact_forces VALUES(?, ?, ?, ?, ?)");
      forces.Bind(1, frame).Bind(2, f.force_f0_n).Bind(3, static_cast<std::int64_t>(f.force_zero))
          .Bind(4, static_cast<std::int64_t>(f.force_total)).Bind(5, bins).Run();
    }
    Statement ft(db, "INSERT INTO frame_time VALUES(?, ?)");
    ft.Bind(1, frame).Bind(2, f.time_s).Run();
    Statement fd(db, "INSERT INTO frame_data VALUES(?, ?)");
    fd.Bind(1, frame).Bind(2, impl_->geometry_hash).Run();
    if (f.with_census) {
      db.Exec("CREATE TABLE IF NOT EXISTS census(frame INTEGER PRIMARY KEY, time_s REAL NOT NULL, "
              "walking INTEGER NOT NULL, fallen INTEGER NOT NULL, removed INTEGER NOT NULL, queued INTEGER NOT NULL, "
              "entered INTEGER NOT NULL)");
      Statement c(db, "INSERT INTO census VALUES(?, ?, ?, ?, ?, ?, ?)");
      c.Bind(1, frame).Bind(2, f.time_s).Bind(3, f.census.walking).Bind(4, f.census.fallen)
          .Bind(5, f.census.removed).Bind(6, f.census.queued).Bind(7, f.census.entered).Run();
    }
    Statement ev(db, "INSERT INTO event VALUES(?, ?, ?, ?, ?, ?)");
    for (const Event& e : f.events)
      ev.Bind(1, frame).Bind(2, e.time_s).Bind(3, e.kind)
          .Bind(4, e.person >= 0 ? e.person + 1 : std::int64_t{0})
          .Bind(5, e.other >= 0 ? e.other + 1 : std::int64_t{0}).Bind(6, e.detail).Run();
    Statement meta(db, "INSERT OR REPLACE INTO metadata VALUES(?, ?)");
    if (std::isfinite(impl_->xmin)) {
      meta.Bind(1, std::string("xmin")).Bind(2, NumberText(impl_->xmin)).Run();
      meta.Bind(1, std::string("xmax")).Bind(2, NumberText(impl_->xmax)).Run();
      meta.Bind(1, std::string("ymin")).Bind(2, NumberText(impl_->ymin)).Run();
      meta.Bind(1, std::string("ymax")).Bind(2, NumberText(impl_->ymax)).Run();
    }
  }
  db.Exec("COMMIT");
}

void RunFileWriter::DropContacts(const std::vector<std::int64_t>& frames) {
  if (frames.empty()) return;
  Database& db = *impl_->db;
  db.Exec("BEGIN");
  DropContactRows(db, frames, impl_->continues_at, impl_->last_frame);
  db.Exec("COMMIT");
}

// ---------------------------------------------------------------------------

struct FrameWriterThread::Impl {
  RunFileWriter& writer;
  bool background;
  std::size_t capacity;
  FrameSnapshot direct;  // the frame being written when not on a thread
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::unique_ptr<FrameSnapshot>> queued;  // oldest first
  std::vector<std::unique_ptr<FrameSnapshot>> spare;  // written, storage kept for reuse
  bool busy = false;                                  // the thread is writing one
  bool stopping = false;
  std::exception_ptr error;
  std::thread thread;

  Impl(RunFileWriter& w, bool on_thread, std::size_t queue)
      : writer(w), background(on_thread), capacity(std::max<std::size_t>(1, queue)) {}

  void Loop() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return stopping || !queued.empty(); });
      if (queued.empty()) return;  // stopping, nothing left
      std::unique_ptr<FrameSnapshot> frame = std::move(queued.front());
      queued.pop_front();
      busy = true;
      lock.unlock();
      std::exception_ptr failure;
      if (!error) {  // after a failure, later frames are dropped (the run is stopping)
        try {
          writer.WriteFrame(*frame);
        } catch (...) {
          failure = std::current_exception();
        }
      }
      lock.lock();
      busy = false;
      if (failure && !error) error = failure;
      spare.push_back(std::move(frame));
      changed.notify_all();
    }
  }

  void RethrowLocked(std::unique_lock<std::mutex>& lock) {
    if (!error) return;
    std::exception_ptr e = error;
    lock.unlock();
    std::rethrow_exception(e);
  }
};

FrameWriterThread::FrameWriterThread(RunFileWriter& writer, bool background, std::size_t queue)
    : impl_(std::make_unique<Impl>(writer, background, queue)) {
  if (impl_->background) impl_->thread = std::thread([this] { impl_->Loop(); });
}

FrameWriterThread::~FrameWriterThread() {
  if (!impl_->background) return;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->changed.notify_all();
  impl_->thread.join();
}

void FrameWriterThread::Write(const std::function<void(FrameSnapshot&)>& fill) {
  if (!impl_->background) {
    fill(impl_->direct);
    impl_->writer.WriteFrame(impl_->direct);
    return;
  }
  std::unique_ptr<FrameSnapshot> snapshot;
  {
    std::unique_lock<std::mutex> lock(impl_->mutex);
    impl_->changed.wait(lock, [&] { return impl_->error || impl_->queued.size() < impl_->capacity; });
    impl_->RethrowLocked(lock);
    if (!impl_->spare.empty()) {
      snapshot = std::move(impl_->spare.back());
      impl_->spare.pop_back();
    }
  }
  if (!snapshot) snapshot = std::make_unique<FrameSnapshot>();
  fill(*snapshot);  // outside the lock: the thread may be writing
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->queued.push_back(std::move(snapshot));
  }
  impl_->changed.notify_all();
}

void FrameWriterThread::Flush() {
  if (!impl_->background) return;
  std::unique_lock<std::mutex> lock(impl_->mutex);
  impl_->changed.wait(lock, [&] { return impl_->error || (impl_->queued.empty() && !impl_->busy); });
  impl_->RethrowLocked(lock);
}

void RunFileWriter::WriteEvent(std::int64_t frame, const Event& e) {
  Statement ev(*impl_->db, "INSERT INTO event VALUES(?, ?, ?, ?, ?, ?)");
  ev.Bind(1, frame).Bind(2, e.time_s).Bind(3, e.kind)
      .Bind(4, e.person >= 0 ? e.person + 1 : std::int64_t{0})
      .Bind(5, e.other >= 0 ? e.other + 1 : std::int64_t{0}).Bind(6, e.detail).Run();
}

void RunFileWriter::SetStatus(const std::string& status) { SetRunValue("status", status); }

void RunFileWriter::SetRunValue(const std::string& key, const std::string& value) {
  Statement s(*impl_->db, "INSERT OR REPLACE INTO run VALUES(?, ?)");
  s.Bind(1, key).Bind(2, value).Run();
}

ContactSummary SummarizeContacts(const std::vector<Contact>& contacts) {
  ContactSummary s;
  for (const Contact& c : contacts) {
    ++s.contacts;
    s.wall_contacts += c.wall;
    if (s.contacts == 1 || c.overlap_m > s.max_overlap_m) {  // the first of the largest
      s.max_overlap_m = c.overlap_m;
      s.max_overlap_wall = c.wall;
    }
    s.max_force_n = std::max(s.max_force_n, Length(c.Force()));
  }
  return s;
}

}  // namespace crowdrecon::runfile
