#include "crowdrecon/runfile/run_file.hpp"

#include <algorithm>
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

// A JSON point list [[x, y], ...] of column `column` of the row of `table`
// named `row`; anything else is a damaged file.
std::vector<Vec2> PointsFromJson(const std::string& text, const std::string& file, const std::string& table,
                                 const std::string& row, const std::string& column) {
  std::vector<Vec2> points;
  try {
    for (const auto& p : nlohmann::json::parse(text)) {
      points.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
      if (!(std::abs(points.back().x) <= run_limits::kCoordinate_m && std::abs(points.back().y) <= run_limits::kCoordinate_m))
        throw std::out_of_range("a coordinate beyond +-" + FormatNumber(run_limits::kCoordinate_m) + " m");
    }
  } catch (const std::exception& e) {
    throw InputError(file + ": table " + table + ", row " + row + ", column " + column +
                     ": malformed point list (" + ShortText(e.what(), 120) + "): " + ShortText(text) +
                     "; expected [[x, y], ...] in metres");
  }
  return points;
}

// The number in the text column `value` of the key-value row `key` of `table`
// (run, metadata); anything else is a damaged file.
double NumberFromText(const std::string& text, const std::string& file, const std::string& table,
                      const std::string& key, double min, double max) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v >= min && v <= max))
    throw InputError(file + ": table " + table + ", row key " + key + ", column value: found \"" + ShortText(text) +
                     "\"; expected a number in [" + FormatNumber(min) + ", " + FormatNumber(max) +
                     "] (the run file is damaged or was not written by crowdrecon)");
  return v;
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
)SQL";

}  // namespace

struct RunFileWriter::Impl {
  std::unique_ptr<Database> db;
  // The frame tables' inserts, prepared once (WriteFrame).
  std::unique_ptr<sqlite::BatchInsert> trajectory, person_state, contact, person_load;
  bool has_person_load = true;  // false for a resumed run file written before the table existed
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
    db.Exec(kJournal);
    db.Exec("PRAGMA synchronous=NORMAL");
    db.Exec("BEGIN");
    db.Exec(detail::kJuPedSimSchema);
    db.Exec(kSchema);
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
  w.impl_->has_person_load = sqlite::HasTable(db, "person_load");
  if (w.impl_->has_person_load) db.Exec("DELETE FROM person_load WHERE frame > " + after);
  if (sqlite::HasTable(db, "census")) db.Exec("DELETE FROM census WHERE frame > " + after);
  {
    Statement geo(db, "SELECT hash FROM geometry LIMIT 1");
    if (!geo.Next()) throw InputError(file.string() + ": not a crowdrecon run file (no geometry)");
    w.impl_->geometry_hash = geo.Int(0);
    Statement bounds(db, "SELECT MIN(pos_x), MAX(pos_x), MIN(pos_y), MAX(pos_y), COUNT(*) FROM trajectory_data");
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

void RunFileWriter::WriteFrame(const FrameSnapshot& f) {
  Database& db = *impl_->db;
  const std::int64_t frame = f.frame;
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
    for (std::size_t k = 0; k < f.person.size(); ++k) {
      const auto id = static_cast<std::int64_t>(f.person[k]) + 1;
      const Vec2 x = f.position_m[k];
      const double angle = f.angle_rad[k];
      traj.Add(frame).Add(id).Add(x.x).Add(x.y).Add(std::cos(angle)).Add(std::sin(angle));
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
    if (impl_->person_load && f.chest_load_n.size() == f.person.size() && f.lateral_load_n.size() == f.person.size()) {
      sqlite::BatchInsert& loads = *impl_->person_load;
      for (std::size_t k = 0; k < f.person.size(); ++k)
        if (f.chest_load_n[k] != 0.0 || f.lateral_load_n[k] != 0.0)
          loads.Add(frame).Add(static_cast<std::int64_t>(f.person[k]) + 1).Add(f.chest_load_n[k]).Add(f.lateral_load_n[k]);
      loads.Finish();
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

// ---------------------------------------------------------------------------

struct RunFileReader::Impl {
  std::unique_ptr<Database> db;
  std::string file;
  bool frames_checked = false;  // Frame's one check of trajectory_data's frame column
};

RunFileReader::RunFileReader(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()) {
  impl_->file = file.string();
  if (!std::filesystem::exists(file)) throw InputError(impl_->file + ": run file does not exist");
  if (std::filesystem::is_directory(file)) throw InputError(impl_->file + ": is a folder, not a run file");
  impl_->db = std::make_unique<Database>(file, SQLITE_OPEN_READONLY);
  // SQLite opens any file lazily and fails on the first query, so a foreign
  // file surfaces here as "file is not a database": say what that means.
  bool ok = false;
  try {
    Statement check(*impl_->db, "SELECT COUNT(*) FROM sqlite_master WHERE name IN ('trajectory_data', 'run', 'person')");
    ok = check.Next() && check.Int(0) == 3;
  } catch (const InputError& e) {
    std::string why = e.what();
    if (why.rfind(impl_->file + ": ", 0) == 0) why = why.substr(impl_->file.size() + 2);
    throw InputError(impl_->file + ": not a crowdrecon run file (" + why + ")");
  }
  if (!ok) throw InputError(impl_->file + ": not a crowdrecon run file (missing tables trajectory_data, run or person)");
}
RunFileReader::RunFileReader(RunFileReader&&) noexcept = default;

bool IsRunFile(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec) || !FileStartsWith(file, std::string("SQLite format 3\0", 16)))
    return false;
  try {
    return RunFileReader(file).RunValue("format") == "crowdrecon-run";
  } catch (const std::exception&) {  // unreadable or foreign: not ours
    return false;
  }
}

OutputKind RunFileOutput() { return {"a crowdrecon run file", false, IsRunFile}; }

void CopyRunFile(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code ec;
  if (std::filesystem::exists(to, ec)) throw InputError(to.string() + ": exists; a copy of a run file is written only anew");
  std::string quoted = "'";
  for (const char c : to.string()) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  quoted += "'";
  const Database db(from.string(), SQLITE_OPEN_READONLY | kWriterMutexMode);
  db.Exec("VACUUM INTO " + quoted);
}
RunFileReader::~RunFileReader() = default;

std::string RunFileReader::RunValue(const std::string& key) const {
  Statement s(*impl_->db, "SELECT value FROM run WHERE key = ?");
  s.Bind(1, key);
  return s.Next() ? s.Text(0) : "";
}

std::string RunFileReader::UnfinishedNote() const {
  const std::string status = RunValue("status");
  if (status == "complete") return "";
  const std::string why = status == "running"       ? "still being written, or killed"
                          : status == "interrupted" ? "stopped before its end"
                          : status.empty()          ? "no status recorded"
                                                    : "it did not finish";
  Statement last(*impl_->db, "SELECT MAX(time_s) FROM frame_time");
  const bool has = last.Next() && last.Type(0) != SQLITE_NULL;
  return impl_->file + " is unfinished (status \"" + status + "\": " + why + "): what follows covers " +
         (has ? "its frames up to t = " + FormatNumber(last.Double(0)) + " s only" : "no frame") +
         "; resume it with crowdrecon simulate --resume to finish it";
}

double RunFileReader::RunNumber(const std::string& key, double fallback, double min, double max) const {
  Statement s(*impl_->db, "SELECT value FROM run WHERE key = ?");
  s.Bind(1, key);
  return s.Next() ? NumberFromText(s.Text(0), impl_->file, "run", key, min, max) : fallback;
}

double RunFileReader::fps() const {
  Statement s(*impl_->db, "SELECT value FROM metadata WHERE key = 'fps'");
  if (!s.Next()) throw InputError(impl_->file + ": run file has no fps in metadata");
  return NumberFromText(s.Text(0), impl_->file, "metadata", "fps", 1e-6, 1e6);
}

std::string RunFileReader::walkable_wkt() const {
  Statement s(*impl_->db, "SELECT wkt FROM geometry LIMIT 1");
  return s.Next() ? s.Text(0) : "";
}

// From FrameTimes, so that every command that lists the frames also checks
// their times.
std::vector<std::int64_t> RunFileReader::Frames() const {
  std::vector<std::int64_t> frames;
  for (const FrameTime& t : FrameTimes()) frames.push_back(t.frame);
  return frames;
}

namespace {
// The columns of a contact row, as ReadContact reads them.
constexpr const char* kContactColumns =
    "SELECT frame, rowid, a, b, wall, point_x, point_y, normal_x, normal_y, overlap_m, normal_force_n, "
    "tangential_force_n";

Contact ReadContact(Statement& c) {
  using namespace run_limits;
  Contact k;
  k.a = static_cast<std::uint32_t>(c.Integer(2, 1, kPersonId) - 1);
  k.wall = c.Integer(4, 0, 1) != 0;
  k.b = static_cast<std::uint32_t>(k.wall ? c.Integer(3, 0, kPersonId) : c.Integer(3, 1, kPersonId) - 1);
  k.point_m = {c.Real(5, -kCoordinate_m, kCoordinate_m), c.Real(6, -kCoordinate_m, kCoordinate_m)};
  k.normal = {c.Real(7, -kUnit, kUnit), c.Real(8, -kUnit, kUnit)};
  k.overlap_m = c.Real(9, -kCoordinate_m, kCoordinate_m);
  k.normal_force_n = c.Real(10, -kForce_n, kForce_n);
  k.tangential_force_n = c.Real(11, -kForce_n, kForce_n);
  return k;
}
}  // namespace

RunFrame RunFileReader::Frame(std::int64_t frame) const {
  if (!impl_->frames_checked) {
    // Frame by frame, a row whose frame is not a whole number is never
    // asked for: look for one once (a scan of the frame index).
    Statement odd(*impl_->db, "SELECT frame, id FROM trajectory_data WHERE typeof(frame) != 'integer' LIMIT 1");
    if (odd.Next())
      throw InputError(impl_->file + ": table trajectory_data, row frame " + odd.Text(0) + ", id " + odd.Text(1) +
                       ": the frame is not a whole number (the run file is damaged)");
    impl_->frames_checked = true;
  }
  RunFrame f;
  f.frame = frame;
  {
    Statement t(*impl_->db, "SELECT frame, time_s FROM frame_time WHERE frame = ?");
    t.Bind(1, frame).Describe("frame_time", {0});
    if (!t.Next()) throw InputError(impl_->file + ": no frame " + std::to_string(frame));
    f.time_s = t.Real(1, 0.0, run_limits::kTime_s);
  }
  using namespace run_limits;
  Statement s(*impl_->db,
              "SELECT frame, id, pos_x, pos_y, ori_x, ori_y FROM trajectory_data WHERE frame = ? ORDER BY id");
  s.Bind(1, frame).Describe("trajectory_data", {0, 1});
  while (s.Next()) {
    f.ids.push_back(s.Integer(1, 1, kPersonId));
    f.position_m.push_back({s.Real(2, -kCoordinate_m, kCoordinate_m), s.Real(3, -kCoordinate_m, kCoordinate_m)});
    f.orientation.push_back({s.Real(4, -kUnit, kUnit), s.Real(5, -kUnit, kUnit)});
  }
  Statement c(*impl_->db, std::string(kContactColumns) + " FROM contact WHERE frame = ? ORDER BY rowid");
  c.Bind(1, frame).Describe("contact", {0, 1});
  while (c.Next()) f.contacts.push_back(ReadContact(c));
  return f;
}

std::vector<Shape> RunFileReader::Shapes() const {
  std::vector<Shape> shapes;
  Statement s(*impl_->db, "SELECT id, radius_m, vertices FROM shape ORDER BY id");
  s.Describe("shape", {0});
  while (s.Next()) {
    Shape shape;
    shape.radius_m = s.Real(1, 0.0, run_limits::kRadius_m);
    shape.vertices = PointsFromJson(s.Text(2), impl_->file, "shape", "id " + s.Text(0), "vertices");
    shapes.push_back(std::move(shape));
  }
  return shapes;
}

std::vector<std::uint32_t> RunFileReader::PersonShapes() const {
  std::vector<std::uint32_t> out;
  Statement s(*impl_->db, "SELECT id, shape, (SELECT COUNT(*) FROM shape) FROM person ORDER BY id");
  s.Describe("person", {0});
  while (s.Next()) out.push_back(static_cast<std::uint32_t>(s.Integer(1, 0, s.Int(2) - 1)));
  return out;
}

std::vector<std::uint32_t> RunFileReader::PersonGroups() const {
  std::vector<std::uint32_t> out;
  Statement s(*impl_->db, "SELECT id, grp FROM person ORDER BY id");
  s.Describe("person", {0});
  while (s.Next()) out.push_back(static_cast<std::uint32_t>(s.Integer(1, 0, run_limits::kGroup)));
  return out;
}

std::vector<Wall> RunFileReader::Walls() const {
  std::vector<Wall> walls;
  Statement s(*impl_->db, "SELECT id, closed, radius_m, points FROM wall ORDER BY id");
  s.Describe("wall", {0});
  while (s.Next()) {
    Wall w;
    w.closed = s.Integer(1, 0, 1) != 0;
    w.radius_m = s.Real(2, 0.0, run_limits::kRadius_m);
    w.points = PointsFromJson(s.Text(3), impl_->file, "wall", "id " + s.Text(0), "points");
    walls.push_back(std::move(w));
  }
  return walls;
}

const std::string& RunFileReader::file() const { return impl_->file; }

std::string RunFileReader::venue_json() const { return RunValue("venue"); }

PeriodicBox RunFileReader::periodic_box() const {
  PeriodicBox box;
  const std::string text = RunValue("periodic_box");
  if (text.empty()) return box;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    box.x = j.value("x", false);
    box.y = j.value("y", false);
    box.min_m = {j.at("min_m").at(0).get<double>(), j.at("min_m").at(1).get<double>()};
    box.max_m = {j.at("max_m").at(0).get<double>(), j.at("max_m").at(1).get<double>()};
  } catch (const std::exception& e) {
    throw InputError(impl_->file + ": table run, row key periodic_box, column value: malformed (" +
                     ShortText(e.what(), 120) + "): " + ShortText(text) +
                     "; expected {\"x\": true|false, \"y\": true|false, \"min_m\": [x, y], \"max_m\": [x, y]}");
  }
  // Only the periodic axes need an extent (the engine leaves the others 0).
  for (int axis = 0; axis < 2; ++axis) {
    const bool periodic = axis == 0 ? box.x : box.y;
    const double lo = axis == 0 ? box.min_m.x : box.min_m.y, hi = axis == 0 ? box.max_m.x : box.max_m.y;
    if (periodic && !(hi > lo && lo >= -run_limits::kCoordinate_m && hi <= run_limits::kCoordinate_m))
      throw InputError(impl_->file + ": table run, row key periodic_box, column value: " + ShortText(text) +
                       "; expected max_m > min_m within +-" + FormatNumber(run_limits::kCoordinate_m) +
                       " m along the periodic axis " + (axis == 0 ? "x" : "y"));
  }
  return box;
}

std::string RunFileReader::TablesDigest() const {
  Sha256 hash;
  std::vector<std::pair<const char*, const char*>> tables = {
      {"trajectory_data", "frame, id"}, {"person_state", "frame, id"}, {"contact", "frame, rowid"},
      {"frame_time", "frame"},          {"event", "frame, rowid"}};
  if (sqlite::HasTable(*impl_->db, "person_load")) tables.emplace_back("person_load", "frame, id");
  if (sqlite::HasTable(*impl_->db, "census")) tables.emplace_back("census", "frame");
  for (const auto& [table, order] : tables) {
    hash.Update(table, std::strlen(table) + 1);
    Statement s(*impl_->db, std::string("SELECT * FROM ") + table + " ORDER BY " + order);
    while (s.Next()) {
      std::string row;
      for (int c = 0; c < s.ColumnCount(); ++c) {
        switch (s.Type(c)) {
          case SQLITE_INTEGER: row += "i" + std::to_string(s.Int(c)); break;
          case SQLITE_FLOAT: {
            char text[32];
            std::snprintf(text, sizeof text, "r%.17g", s.Double(c));
            row += text;
            break;
          }
          case SQLITE_NULL: row += "n"; break;
          default: {  // text and blobs: their length, then their bytes
            const std::string v = s.Text(c);
            row += "t" + std::to_string(v.size()) + ":" + v;
          }
        }
        row += ';';
      }
      row += '\n';
      hash.Update(row.data(), row.size());
    }
  }
  return hash.HexDigest();
}

std::vector<FrameTime> RunFileReader::FrameTimes() const {
  std::vector<FrameTime> times;
  Statement s(*impl_->db, "SELECT frame, time_s FROM frame_time ORDER BY frame");
  s.Describe("frame_time", {0});
  while (s.Next()) {
    const FrameTime t{s.Integer(0, 0, run_limits::kFrame), s.Real(1, 0.0, run_limits::kTime_s)};
    if (!times.empty() && !(t.time_s > times.back().time_s))
      throw InputError(impl_->file + ": table frame_time, row frame " + std::to_string(t.frame) + ": time_s " +
                       FormatNumber(t.time_s) + " s is not after frame " + std::to_string(times.back().frame) + "'s " +
                       FormatNumber(times.back().time_s) + " s; expected times that increase with the frame (the run "
                       "file is damaged)");
    times.push_back(t);
  }
  return times;
}

struct PersonFrameStream::Impl {
  std::unique_ptr<Statement> query;
  bool have_row = false;
  // For the check at the end that the join with person_state left no row
  // of trajectory_data out (a damaged file: an id or frame person_state lacks).
  sqlite::Database* db = nullptr;
  std::string file;
  std::int64_t last_frame = 0;
  std::int64_t rows = 0;
};

namespace {

// Every row of trajectory_data up to `last_frame` has its person_state row:
// otherwise the stream would have dropped it without a word.
void RequireEveryTrajectoryRowStreamed(sqlite::Database& db, const std::string& file, std::int64_t last_frame,
                                       std::int64_t streamed) {
  Statement count(db, "SELECT COUNT(*) FROM trajectory_data WHERE frame <= ?1");
  count.Bind(1, last_frame);
  if (count.Next() && count.Int(0) == streamed) return;
  Statement orphan(db,
                   "SELECT t.frame, t.id FROM trajectory_data t LEFT JOIN person_state s ON s.frame = t.frame AND "
                   "s.id = t.id WHERE t.frame <= ?1 AND s.id IS NULL LIMIT 1");
  orphan.Bind(1, last_frame);
  const std::string row = orphan.Next() ? "row frame " + orphan.Text(0) + ", id " + orphan.Text(1) : "a row";
  throw InputError(file + ": table trajectory_data, " + row +
                   ": no row of person_state with that frame and id; expected whole-number frames and ids that "
                   "person_state also has (the run file is damaged)");
}

}  // namespace

PersonFrameStream::PersonFrameStream() : impl_(std::make_unique<Impl>()) {}
PersonFrameStream::PersonFrameStream(PersonFrameStream&&) noexcept = default;
PersonFrameStream::~PersonFrameStream() = default;

bool PersonFrameStream::Next(PersonFrame* out) {
  using namespace run_limits;
  if (!impl_->have_row) return false;
  Statement& q = *impl_->query;
  out->frame = q.Integer(0, 0, kFrame);
  out->person.clear();
  out->position_m.clear();
  out->velocity_m_per_s.clear();
  out->angle_rad.clear();
  out->angular_velocity_rad_per_s.clear();
  out->state.clear();
  out->load_n.clear();
  while (impl_->have_row && q.Int(0) == out->frame) {
    out->person.push_back(static_cast<std::uint32_t>(q.Integer(1, 1, kPersonId) - 1));
    out->position_m.push_back({q.Real(2, -kCoordinate_m, kCoordinate_m), q.Real(3, -kCoordinate_m, kCoordinate_m)});
    out->velocity_m_per_s.push_back({q.Real(4, -kSpeed_m_per_s, kSpeed_m_per_s), q.Real(5, -kSpeed_m_per_s, kSpeed_m_per_s)});
    out->angle_rad.push_back(q.Real(6, -kAngle_rad, kAngle_rad));
    out->angular_velocity_rad_per_s.push_back(q.Real(7, -kAngularSpeed_rad_per_s, kAngularSpeed_rad_per_s));
    out->state.push_back(static_cast<PersonStatus>(q.Integer(8, 0, 2)));
    out->load_n.push_back(q.Real(9, 0.0, kForce_n));
    ++impl_->rows;
    impl_->have_row = q.Next();
    if (impl_->have_row) q.Integer(0, 0, kFrame);  // a frame of 7.5 is refused, not read as 7
  }
  if (!impl_->have_row) RequireEveryTrajectoryRowStreamed(*impl_->db, impl_->file, impl_->last_frame, impl_->rows);
  return true;
}

PersonFrameStream RunFileReader::PersonFrames(std::int64_t last_frame) const {
  PersonFrameStream stream;
  // Column aliases name person_state's columns, so that a damaged value is
  // reported in the table it was read from.
  stream.impl_->query = std::make_unique<Statement>(
      *impl_->db,
      "SELECT t.frame AS frame, t.id AS id, t.pos_x AS pos_x, t.pos_y AS pos_y, "
      "s.vel_x AS \"person_state.vel_x\", s.vel_y AS \"person_state.vel_y\", "
      "s.angle_rad AS \"person_state.angle_rad\", s.omega_rad_per_s AS \"person_state.omega_rad_per_s\", "
      "s.state AS \"person_state.state\", s.load_n AS \"person_state.load_n\" FROM trajectory_data t "
      "JOIN person_state s ON s.frame = t.frame AND s.id = t.id WHERE t.frame <= ?1 "
      "ORDER BY t.frame, t.id");
  stream.impl_->query->Bind(1, last_frame).Describe("trajectory_data", {0, 1});
  stream.impl_->db = impl_->db.get();
  stream.impl_->file = impl_->file;
  stream.impl_->last_frame = last_frame;
  stream.impl_->have_row = stream.impl_->query->Next();
  if (!stream.impl_->have_row) RequireEveryTrajectoryRowStreamed(*impl_->db, impl_->file, last_frame, 0);
  return stream;
}

struct ContactFrameStream::Impl {
  std::unique_ptr<Statement> query;
  bool have_row = false;
};

ContactFrameStream::ContactFrameStream() : impl_(std::make_unique<Impl>()) {}
ContactFrameStream::ContactFrameStream(ContactFrameStream&&) noexcept = default;
ContactFrameStream::~ContactFrameStream() = default;

bool ContactFrameStream::Next(std::int64_t* frame, std::vector<Contact>* out) {
  if (!impl_->have_row) return false;
  Statement& q = *impl_->query;
  *frame = q.Int(0);
  out->clear();
  while (impl_->have_row && q.Int(0) == *frame) {
    out->push_back(ReadContact(q));
    impl_->have_row = q.Next();
  }
  return true;
}

struct PersonLoadStream::Impl {
  std::unique_ptr<Statement> query;
  bool have_row = false;
};

PersonLoadStream::PersonLoadStream() : impl_(std::make_unique<Impl>()) {}
PersonLoadStream::PersonLoadStream(PersonLoadStream&&) noexcept = default;
PersonLoadStream::~PersonLoadStream() = default;

bool PersonLoadStream::Next(std::int64_t* frame, std::vector<PersonLoad>* out) {
  using namespace run_limits;
  if (!impl_->have_row) return false;
  Statement& q = *impl_->query;
  *frame = q.Int(0);
  out->clear();
  while (impl_->have_row && q.Int(0) == *frame) {
    out->push_back({static_cast<std::uint32_t>(q.Integer(1, 1, kPersonId) - 1), q.Real(2, 0.0, kForce_n),
                    q.Real(3, 0.0, kForce_n)});
    impl_->have_row = q.Next();
  }
  return true;
}

bool RunFileReader::HasPersonLoads() const { return sqlite::HasTable(*impl_->db, "person_load"); }

PersonLoadStream RunFileReader::PersonLoads(std::int64_t last_frame) const {
  PersonLoadStream stream;
  stream.impl_->query = std::make_unique<Statement>(
      *impl_->db, "SELECT frame, id, chest_n, lateral_n FROM person_load WHERE frame <= ?1 ORDER BY frame, id");
  stream.impl_->query->Bind(1, last_frame).Describe("person_load", {0, 1});
  stream.impl_->have_row = stream.impl_->query->Next();
  return stream;
}

ContactFrameStream RunFileReader::ContactFrames(std::int64_t last_frame) const {
  ContactFrameStream stream;
  stream.impl_->query = std::make_unique<Statement>(
      *impl_->db, std::string(kContactColumns) + " FROM contact WHERE frame <= ?1 ORDER BY frame, rowid");
  stream.impl_->query->Bind(1, last_frame).Describe("contact", {0, 1});
  stream.impl_->have_row = stream.impl_->query->Next();
  return stream;
}

std::optional<RunFileReader::LargestOverlap> RunFileReader::LargestContactOverlap() const {
  Statement q(*impl_->db, "SELECT frame, rowid, overlap_m, wall FROM contact ORDER BY overlap_m DESC, frame, rowid LIMIT 1");
  q.Describe("contact", {0, 1});
  if (!q.Next()) return std::nullopt;
  LargestOverlap largest;
  largest.frame = q.Int(0);
  largest.overlap_m = q.Real(2, -run_limits::kCoordinate_m, run_limits::kCoordinate_m);
  largest.wall = q.Integer(3, 0, 1) != 0;
  return largest;
}

std::vector<Vec2> RunFileReader::GroupVelocitySums() const {
  std::vector<Vec2> sums;
  Statement q(*impl_->db,
              "SELECT p.grp, SUM(s.vel_x), SUM(s.vel_y) FROM person_state s JOIN person p ON p.id = s.id "
              "GROUP BY p.grp ORDER BY p.grp");
  while (q.Next()) {
    const std::int64_t g = q.Int(0);
    if (g < 0 || g > run_limits::kGroup) continue;  // PersonGroups() reports such a row
    if (static_cast<std::size_t>(g) >= sums.size()) sums.resize(static_cast<std::size_t>(g) + 1);
    sums[static_cast<std::size_t>(g)] = {q.Double(1), q.Double(2)};
  }
  return sums;
}

std::vector<Event> RunFileReader::Events() const {
  std::vector<Event> events;
  Statement s(*impl_->db, "SELECT frame, rowid, time_s, kind, person, other, detail FROM event ORDER BY frame, rowid");
  s.Describe("event", {0, 1});
  while (s.Next()) {
    Event e;
    e.time_s = s.Real(2, 0.0, run_limits::kTime_s);
    e.kind = s.Text(3);
    e.person = s.Integer(4, 0, run_limits::kPersonId) - 1;
    e.other = s.Integer(5, 0, run_limits::kPersonId) - 1;
    e.detail = s.Text(6);
    events.push_back(std::move(e));
  }
  return events;
}

std::vector<CensusRow> RunFileReader::CensusRows() const {
  std::vector<CensusRow> rows;
  if (!sqlite::HasTable(*impl_->db, "census")) return rows;
  Statement s(*impl_->db,
              "SELECT frame, time_s, walking, fallen, removed, queued, entered FROM census ORDER BY frame");
  s.Describe("census", {0});
  while (s.Next()) {
    CensusRow r;
    r.frame = s.Integer(0, 0, run_limits::kFrame);
    r.time_s = s.Real(1, 0.0, run_limits::kTime_s);
    r.census.walking = s.Integer(2, 0, run_limits::kPersonId);
    r.census.fallen = s.Integer(3, 0, run_limits::kPersonId);
    r.census.removed = s.Integer(4, 0, run_limits::kPersonId);
    r.census.queued = s.Integer(5, 0, run_limits::kPersonId);
    r.census.entered = s.Integer(6, 0, run_limits::kPersonId);
    rows.push_back(r);
  }
  return rows;
}

std::vector<Person> RunFileReader::People() const {
  std::vector<Person> people;
  using namespace run_limits;
  Statement s(*impl_->db,
              "SELECT id, shape, mass_kg, inertia_kg_m2, desired_speed_m_per_s, grp, target, "
              "(SELECT COUNT(*) FROM shape) FROM person ORDER BY id");
  s.Describe("person", {0});
  while (s.Next()) {
    const std::int64_t id = s.Integer(0, 1, kPersonId);
    if (static_cast<std::size_t>(id) > people.size()) people.resize(static_cast<std::size_t>(id));
    Person& p = people[static_cast<std::size_t>(id - 1)];
    p.shape = static_cast<std::uint32_t>(s.Integer(1, 0, std::max<std::int64_t>(0, s.Int(7) - 1)));
    p.mass_kg = s.Real(2, 0.0, kMass_kg);
    p.inertia_kg_m2 = s.Real(3, 0.0, kMass_kg * kRadius_m * kRadius_m);
    p.desired_speed_m_per_s = s.Real(4, 0.0, kSpeed_m_per_s);
    p.group = static_cast<std::uint32_t>(s.Integer(5, 0, kGroup));
    p.target = s.Text(6);
  }
  return people;
}

}  // namespace crowdrecon::runfile
