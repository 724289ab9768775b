#include "crowdrecon/scenario/run_file.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/scenario/sqlite.hpp"

namespace crowdrecon::scenario {

namespace {

using sqlite::Database;
using sqlite::Statement;

std::string NumberText(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// 64-bit FNV-1a of the WKT, as the geometry hash (JuPedSim uses Python's hash;
// any integer identifying the geometry will do for readers).
std::int64_t GeometryHash(const std::string& wkt) {
  return static_cast<std::int64_t>(Fnv1a(wkt.data(), wkt.size()) >> 1);
}

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

constexpr const char* kSchema = R"SQL(
CREATE TABLE trajectory_data(frame INTEGER NOT NULL, id INTEGER NOT NULL, pos_x REAL NOT NULL,
  pos_y REAL NOT NULL, ori_x REAL NOT NULL, ori_y REAL NOT NULL);
CREATE TABLE metadata(key TEXT NOT NULL UNIQUE PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE geometry(hash INTEGER NOT NULL, wkt TEXT NOT NULL);
CREATE TABLE frame_data(frame INTEGER NOT NULL, geometry_hash INTEGER NOT NULL);
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
CREATE TABLE event(frame INTEGER NOT NULL, time_s REAL NOT NULL, kind TEXT NOT NULL, person INTEGER NOT NULL,
  other INTEGER NOT NULL, detail TEXT NOT NULL);
)SQL";

}  // namespace

struct RunFileWriter::Impl {
  std::unique_ptr<Database> db;
  // The frame tables' inserts, prepared once (WriteFrame).
  std::unique_ptr<sqlite::BatchInsert> trajectory, person_state, contact;
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
  impl_->contact.reset();
  try {
    impl_->db->Exec("PRAGMA journal_mode=DELETE");  // see kJournal
  } catch (const std::exception&) {
    // Still a valid file in WAL mode; readers fold the log in.
  }
}

RunFileWriter RunFileWriter::Create(const std::filesystem::path& file, const RunHeader& header,
                                    const engine::Simulation& sim) {
  // The caller checked the path (CheckOutputs: a previous run file, or a
  // file --force lets us replace); a folder is never removed here.
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file.string() + ": exists and is " + DescribeExisting(file) +
                     ", not a crowdrecon run file; a folder is never replaced by a file");
  std::filesystem::remove(file, ec);
  for (const char* suffix : {"-journal", "-wal", "-shm"}) std::filesystem::remove(file.string() + suffix, ec);
  RunFileWriter w;
  w.impl_->db = std::make_unique<Database>(file, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | kWriterMutexMode);
  Database& db = *w.impl_->db;
  db.Exec(kJournal);
  db.Exec("PRAGMA synchronous=NORMAL");
  db.Exec("BEGIN");
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
    put("format_version", "1");
    put("scenario", header.scenario_json);
    put("scenario_file", header.scenario_origin);
    put("seed", std::to_string(header.seed));
    put("time_step_s", NumberText(header.time_step_s));
    put("output_fps", NumberText(header.output_fps));
    put("status", "running");
    const engine::PeriodicBox& box = sim.definition().periodic;
    if (box.x || box.y) {
      nlohmann::json j = {{"x", box.x}, {"y", box.y}, {"min_m", {box.min_m.x, box.min_m.y}},
                          {"max_m", {box.max_m.x, box.max_m.y}}};
      put("periodic_box", j.dump());
    }
  }
  const engine::WorldDef& def = sim.definition();
  {
    Statement shape(db, "INSERT INTO shape VALUES(?, ?, ?)");
    for (std::size_t s = 0; s < def.shapes.size(); ++s)
      shape.Bind(1, static_cast<std::int64_t>(s)).Bind(2, def.shapes[s].radius_m).Bind(3, PointsJson(def.shapes[s].vertices)).Run();
    Statement person(db, "INSERT INTO person VALUES(?, ?, ?, ?, ?, ?, ?)");
    const engine::BodyState& b = sim.bodies();
    for (std::size_t i = 0; i < b.size(); ++i) {
      const std::uint32_t t = b.target[i];
      person.Bind(1, static_cast<std::int64_t>(i + 1))
          .Bind(2, static_cast<std::int64_t>(b.shape[i]))
          .Bind(3, b.mass_kg[i])
          .Bind(4, b.inertia_kg_m2[i])
          .Bind(5, b.desired_speed_m_per_s[i])
          .Bind(6, static_cast<std::int64_t>(b.group[i]))
          .Bind(7, t < header.target_names.size() ? header.target_names[t] : std::to_string(t))
          .Run();
    }
    Statement wall(db, "INSERT INTO wall VALUES(?, ?, ?, ?)");
    for (std::size_t k = 0; k < def.walls.size(); ++k)
      wall.Bind(1, static_cast<std::int64_t>(k))
          .Bind(2, static_cast<std::int64_t>(def.walls[k].closed))
          .Bind(3, def.walls[k].radius_m)
          .Bind(4, PointsJson(def.walls[k].points))
          .Run();
  }
  db.Exec("COMMIT");
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

void FrameSnapshot::Take(std::int64_t frame_index, const engine::Simulation& sim, const std::vector<Event>& frame_events,
                         bool contacts_too) {
  const engine::BodyState& b = sim.bodies();
  frame = frame_index;
  time_s = sim.time_s();
  person.clear();
  position_m.clear();
  velocity_m_per_s.clear();
  angle_rad.clear();
  angular_velocity_rad_per_s.clear();
  state.clear();
  load_n.clear();
  // Per-person load: the sum of the magnitudes of the contact forces on the
  // person (the quantity compared with the 400 N threshold).
  std::vector<double>& load = load_n;
  load.assign(b.size(), 0.0);
  for (const engine::Contact& c : sim.contacts()) {
    const double f = Length(c.Force());
    load[c.a] += f;
    if (!c.wall) load[c.b] += f;
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.state[i] == engine::PersonState::kRemoved) continue;
    person.push_back(static_cast<std::uint32_t>(i));
    position_m.push_back(b.position_m[i]);
    velocity_m_per_s.push_back(b.velocity_m_per_s[i]);
    angle_rad.push_back(b.angle_rad[i]);
    angular_velocity_rad_per_s.push_back(b.angular_velocity_rad_per_s[i]);
    state.push_back(b.state[i]);
    load[kept++] = load[i];  // kept <= i: compacts in place
  }
  load.resize(kept);
  with_contacts = contacts_too;
  if (with_contacts) {
    contacts.assign(sim.contacts().begin(), sim.contacts().end());
  } else {
    contacts.clear();
  }
  events = frame_events;
}

void RunFileWriter::WriteFrame(std::int64_t frame, const engine::Simulation& sim, const std::vector<Event>& events,
                               bool with_contacts) {
  FrameSnapshot snapshot;
  snapshot.Take(frame, sim, events, with_contacts);
  WriteFrame(snapshot);
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
    }
    sqlite::BatchInsert& traj = *impl_->trajectory;
    sqlite::BatchInsert& state = *impl_->person_state;
    for (sqlite::BatchInsert* batch : {&traj, &state, impl_->contact.get()}) batch->Discard();
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
    if (f.with_contacts) {
      sqlite::BatchInsert& contact = *impl_->contact;
      for (const engine::Contact& c : f.contacts)
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

void FrameWriterThread::Write(std::int64_t frame, const engine::Simulation& sim, const std::vector<Event>& events,
                              bool with_contacts) {
  if (!impl_->background) {
    impl_->direct.Take(frame, sim, events, with_contacts);
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
  snapshot->Take(frame, sim, events, with_contacts);  // outside the lock: the thread may be writing
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
RunFileReader::~RunFileReader() = default;

std::string RunFileReader::RunValue(const std::string& key) const {
  Statement s(*impl_->db, "SELECT value FROM run WHERE key = ?");
  s.Bind(1, key);
  return s.Next() ? s.Text(0) : "";
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

std::vector<std::int64_t> RunFileReader::Frames() const {
  std::vector<std::int64_t> frames;
  Statement s(*impl_->db, "SELECT frame FROM frame_time ORDER BY frame");
  s.Describe("frame_time", {0});
  while (s.Next()) frames.push_back(s.Integer(0, 0, run_limits::kFrame));
  return frames;
}

RunFrame RunFileReader::Frame(std::int64_t frame) const {
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
  Statement c(*impl_->db,
              "SELECT frame, rowid, a, b, wall, point_x, point_y, normal_x, normal_y, overlap_m, normal_force_n, "
              "tangential_force_n FROM contact WHERE frame = ? ORDER BY rowid");
  c.Bind(1, frame).Describe("contact", {0, 1});
  while (c.Next()) {
    engine::Contact k;
    k.a = static_cast<std::uint32_t>(c.Integer(2, 1, kPersonId) - 1);
    k.wall = c.Integer(4, 0, 1) != 0;
    k.b = static_cast<std::uint32_t>(k.wall ? c.Integer(3, 0, kPersonId) : c.Integer(3, 1, kPersonId) - 1);
    k.point_m = {c.Real(5, -kCoordinate_m, kCoordinate_m), c.Real(6, -kCoordinate_m, kCoordinate_m)};
    k.normal = {c.Real(7, -kUnit, kUnit), c.Real(8, -kUnit, kUnit)};
    k.overlap_m = c.Real(9, -kCoordinate_m, kCoordinate_m);
    k.normal_force_n = c.Real(10, -kForce_n, kForce_n);
    k.tangential_force_n = c.Real(11, -kForce_n, kForce_n);
    f.contacts.push_back(k);
  }
  return f;
}

std::vector<engine::BodyShape> RunFileReader::Shapes() const {
  std::vector<engine::BodyShape> shapes;
  Statement s(*impl_->db, "SELECT id, radius_m, vertices FROM shape ORDER BY id");
  s.Describe("shape", {0});
  while (s.Next()) {
    engine::BodyShape shape;
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

std::vector<engine::Wall> RunFileReader::Walls() const {
  std::vector<engine::Wall> walls;
  Statement s(*impl_->db, "SELECT id, closed, radius_m, points FROM wall ORDER BY id");
  s.Describe("wall", {0});
  while (s.Next()) {
    engine::Wall w;
    w.closed = s.Integer(1, 0, 1) != 0;
    w.radius_m = s.Real(2, 0.0, run_limits::kRadius_m);
    w.points = PointsFromJson(s.Text(3), impl_->file, "wall", "id " + s.Text(0), "points");
    walls.push_back(std::move(w));
  }
  return walls;
}

}  // namespace crowdrecon::scenario
