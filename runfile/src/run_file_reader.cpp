// Reading run files (run_file.hpp): the reader, its frames, tables and streams.
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
#include <set>
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

// A packed run's frames (frame_pack.hpp) in order, from `first` (a key
// frame) to `last`.
class PackedFrames {
 public:
  PackedFrames(const Database& db, const std::string& file, std::size_t people, std::int64_t first, std::int64_t last)
      : query_(db, "SELECT frame, data FROM frame_pack WHERE frame >= ?1 AND frame <= ?2 ORDER BY frame"),
        file_(file),
        people_(people) {
    query_.Bind(1, first).Bind(2, last).Describe("frame_pack", {0});
  }
  bool Next(std::int64_t* frame, detail::PackedPeople* out) {
    if (!query_.Next()) return false;
    *frame = query_.Integer(0, 0, run_limits::kFrame);
    if (query_.Type(1) != SQLITE_BLOB)
      throw InputError(file_ + ": table frame_pack, row frame " + std::to_string(*frame) +
                       ", column data: not a blob (the run file is damaged)");
    const auto [data, size] = query_.Blob(1);
    unpacker_.Unpack(*frame, data, size, people_, out, file_ + ": table frame_pack, row frame " + std::to_string(*frame));
    return true;
  }

 private:
  Statement query_;
  std::string file_;
  std::size_t people_;
  detail::FrameUnpacker unpacker_;
};


}  // namespace

struct RunFileReader::Impl {
  std::unique_ptr<Database> db;
  std::string file;
  bool frames_checked = false;  // Frame's one check of trajectory_data's frame column
  bool packed = false;          // table frame_pack holds the people
  std::size_t people = 0;       // the largest id of table person (a packed frame's bound)
  // Frame's last packed frame, so that frames asked for in order are each
  // unpacked once (`render`).
  std::unique_ptr<PackedFrames> cursor;
  std::int64_t cursor_frame = -1, cursor_key = -1;
  detail::PackedPeople cursor_people;
  // A run in segments, read from its last: every segment's own reader, first
  // to last, and each one's first and last frame (empty: a run in one file).
  std::vector<std::unique_ptr<RunFileReader>> segments;
  std::vector<std::pair<std::int64_t, std::int64_t>> ranges;
  // Frames of this segment whose contact rows a later segment dropped
  // (its table contact_dropped: a worst moment since superseded).
  std::set<std::int64_t> dropped;

  // The packed frames from the key frame at or before `first` to `last`.
  std::int64_t KeyAtOrBefore(std::int64_t frame) const {
    Statement k(*db, "SELECT MAX(frame) FROM frame_pack WHERE frame <= ?1 AND key = 1");
    k.Bind(1, frame);
    if (!k.Next() || k.Type(0) == SQLITE_NULL)
      throw InputError(file + ": table frame_pack has no key frame at or before frame " + std::to_string(frame) +
                       " (the run file is damaged)");
    return k.Int(0);
  }
  std::unique_ptr<PackedFrames> Packed(std::int64_t first, std::int64_t last) const {
    return std::make_unique<PackedFrames>(*db, file, people, first, last);
  }
  // The people of packed frame `frame`.
  const detail::PackedPeople& PackedFrame(std::int64_t frame) {
    if (cursor && cursor_frame == frame) return cursor_people;
    try {
      const std::int64_t key = KeyAtOrBefore(frame);
      if (!(cursor && cursor_frame < frame && key == cursor_key)) {
        cursor_key = key;
        cursor = Packed(key, run_limits::kFrame);
        cursor_frame = -1;
      }
      std::int64_t got = -1;
      while (cursor_frame < frame) {
        if (!cursor->Next(&got, &cursor_people)) break;
        cursor_frame = got;
      }
      if (cursor_frame != frame)
        throw InputError(file + ": table frame_pack has no row of frame " + std::to_string(frame) +
                         " though table frame_time has (the run file is damaged)");
    } catch (...) {
      cursor.reset();
      cursor_frame = -1;
      throw;
    }
    return cursor_people;
  }
};

// The chain of a run in segments, and what the readers of its segments
// share (run_file.hpp: RunFileReader).
struct ChainAccess {
  static void Open(RunFileReader& last, const std::filesystem::path& file) {
    // Each segment's first and last frame (-1 for none), read once.
    const auto range_of = [](const std::vector<FrameTime>& times) {
      return times.empty() ? std::pair<std::int64_t, std::int64_t>{-1, -1}
                           : std::pair<std::int64_t, std::int64_t>{times.front().frame, times.back().frame};
    };
    std::vector<std::unique_ptr<RunFileReader>> chain;
    chain.push_back(std::unique_ptr<RunFileReader>(new RunFileReader(file, false)));
    std::vector<std::pair<std::int64_t, std::int64_t>> ranges = {range_of(chain.back()->FrameTimes())};
    std::set<std::string> seen;
    std::error_code ec;
    seen.insert(std::filesystem::weakly_canonical(file, ec).string());
    for (;;) {
      const RunFileReader& after = *chain.back();
      const std::string next = after.RunValue("continues");
      if (next.empty()) break;
      const auto at = static_cast<std::int64_t>(after.RunNumber("continues_at_frame", -1.0, 0.0, double(run_limits::kFrame)));
      std::filesystem::path path = next;
      if (path.is_relative()) path = std::filesystem::path(after.file()).parent_path() / path;
      path = path.lexically_normal();
      if (!std::filesystem::exists(path, ec))
        throw InputError(after.file() + ": continues the run of " + path.string() + " (run value continues), which is "
                         "not there; a run in segments is read whole: keep its segments together, at the same "
                         "relative paths");
      if (!seen.insert(std::filesystem::weakly_canonical(path, ec).string()).second)
        throw InputError(after.file() + ": its chain of segments comes back to " + path.string() +
                         " (run values continues; the run file is damaged)");
      auto segment = std::unique_ptr<RunFileReader>(new RunFileReader(path, false));
      if (!segment->RunValue("segment_head").empty())
        throw InputError(after.file() + ": continues " + path.string() + ", which is a segment's head (" +
                         segment->RunValue("segment_head") + "): its frames are not there; a run in segments is read "
                         "whole: put the whole segment in its place");
      const std::vector<FrameTime> times = segment->FrameTimes();
      if (times.empty() || times.back().frame != at)
        throw InputError(after.file() + ": continues " + path.string() + " after its frame " + std::to_string(at) +
                         ", but that file's last frame is " +
                         (times.empty() ? std::string("none") : std::to_string(times.back().frame)) +
                         " (not the segment it continued: written again or resumed since)");
      if (segment->RunValue("scenario") != after.RunValue("scenario"))
        throw InputError(after.file() + ": continues " + path.string() + ", which is a run of another scenario");
      chain.push_back(std::move(segment));
      ranges.push_back(range_of(times));
    }
    std::reverse(chain.begin(), chain.end());
    std::reverse(ranges.begin(), ranges.end());
    // A later segment's dropped contact rows (superseded worst moments) are
    // of the segments before it.
    std::set<std::int64_t> later;
    for (std::size_t i = chain.size(); i-- > 0;) {
      chain[i]->impl_->dropped = later;
      if (sqlite::HasTable(*chain[i]->impl_->db, "contact_dropped")) {
        Statement d(*chain[i]->impl_->db, "SELECT frame FROM contact_dropped");
        while (d.Next()) later.insert(d.Int(0));
      }
    }
    std::int64_t previous_last = -1;
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const auto [first, end] = ranges[i];
      if (first >= 0 && first <= previous_last)
        throw InputError(chain[i]->file() + ": its first frame " + std::to_string(first) +
                         " is not after the last of the segment before it (" + std::to_string(previous_last) +
                         "; the run file is damaged)");
      if (first >= 0) previous_last = end;
    }
    last.impl_->ranges = std::move(ranges);
    last.impl_->segments = std::move(chain);
  }

  // The rows of one table of one segment into `hash` (TablesDigest).
  static void DigestRows(const RunFileReader& r, Sha256& hash, const std::string& name, const char* order);
  // One segment's velocities added to `sums` by group, in frame/id order.
  static void AddGroupVelocities(const RunFileReader& r, const std::vector<std::int64_t>& group, std::vector<Vec2>& sums);
};

RunFileReader::RunFileReader(const std::filesystem::path& file) : RunFileReader(file, true) {}

RunFileReader RunFileReader::OneSegment(const std::filesystem::path& file) { return RunFileReader(file, false); }

RunFileReader::RunFileReader(const std::filesystem::path& file, bool follow_segments) : impl_(std::make_unique<Impl>()) {
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
  impl_->packed = sqlite::HasTable(*impl_->db, "frame_pack");
  if (impl_->packed) {
    Statement people(*impl_->db, "SELECT MAX(id) FROM person");
    if (people.Next() && people.Type(0) == SQLITE_INTEGER)
      impl_->people = static_cast<std::size_t>(std::clamp<std::int64_t>(people.Int(0), 0, run_limits::kPersonId));
  }
  // A segment's head (WriteSegmentHead) holds no frames: it continues, it
  // is not read.
  if (follow_segments && !RunValue("segment_head").empty())
    throw InputError(impl_->file + ": is a segment's head (" + RunValue("segment_head") +
                     "): a run can be continued from it (simulate --continue-from), not read; put the whole segment "
                     "in its place");
  if (follow_segments && !RunValue("continues").empty()) ChainAccess::Open(*this, file);
}

bool RunFileReader::packed() const { return impl_->packed; }

RunHeader RunFileReader::Header() const {
  RunHeader header;
  header.scenario_json = RunValue("scenario");
  header.scenario_origin = RunValue("scenario_file");
  header.venue_json = venue_json();
  header.walkable_wkt = walkable_wkt();
  header.periodic_box = periodic_box();
  header.output_fps = fps();
  header.time_step_s = RunNumber("time_step_s", 0.0, 0.0, 1e6);
  header.seed = static_cast<std::uint64_t>(RunNumber("seed", 0.0, 0.0, 1.9e19));
  header.packed = packed();
  return header;
}

RunSetup RunFileReader::Setup() const {
  RunSetup setup;
  setup.shapes = Shapes();
  setup.people = People();
  setup.walls = Walls();
  return setup;
}

std::vector<std::string> RunFileReader::SegmentFiles() const {
  if (impl_->segments.empty()) return {impl_->file};
  std::vector<std::string> files;
  for (const auto& segment : impl_->segments) files.push_back(segment->file());
  return files;
}
RunFileReader::RunFileReader(RunFileReader&&) noexcept = default;

bool IsRunFile(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec) || !FileStartsWith(file, std::string("SQLite format 3\0", 16)))
    return false;
  try {
    return RunFileReader::OneSegment(file).RunValue("format") == "crowdrecon-run";
  } catch (const std::exception&) {  // unreadable or foreign: not ours
    return false;
  }
}

std::string DescribeNonRunFile(const std::filesystem::path& file) {
  const std::string what = DescribeExisting(file);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec) || !FileStartsWith(file, std::string("SQLite format 3\0", 16)))
    return what;
  try {
    (void)RunFileReader::OneSegment(file).RunValue("format");
  } catch (const std::exception& e) {
    const std::string why = e.what();
    const std::size_t at = why.find("SQLite error: ");
    if (at != std::string::npos) {
      std::string sqlite = why.substr(at + 14);
      if (const std::size_t end = sqlite.find(" (in: "); end != std::string::npos) sqlite.resize(end);
      for (const char* damaged : {"malformed", "disk I/O error", "not a database"})
        if (sqlite.find(damaged) != std::string::npos)
          return "a damaged SQLite file (SQLite: " + sqlite +
                 "; a run file cut short or damaged, which cannot be read or resumed)";
    }
  }
  return what;
}

OutputKind RunFileOutput() {
  OutputKind kind{"a crowdrecon run file", false, IsRunFile};
  kind.describe = DescribeNonRunFile;
  return kind;
}

void CopyRunFile(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code ec;
  if (std::filesystem::exists(to, ec)) throw InputError(to.string() + ": exists; a copy of a run file is written only anew");
  std::string quoted = "'";
  for (const char c : to.string()) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  quoted += "'";
  const Database db(from.string(), SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);  // (this thread's alone)
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
  const bool failed = status.rfind("failed", 0) == 0;
  const std::string why = status == "running"       ? "still being written, or killed"
                          : status == "interrupted" ? "stopped before its end"
                          : status.empty()          ? "no status recorded"
                          : failed                  ? "it went numerically wrong and stopped"
                                                    : "it did not finish";
  Statement last(*impl_->db, "SELECT MAX(time_s) FROM frame_time");
  bool has = last.Next() && last.Type(0) != SQLITE_NULL;
  double last_s = has ? last.Double(0) : 0.0;
  if (!impl_->segments.empty()) {  // the run's last frame, in whichever segment
    const std::vector<FrameTime> times = FrameTimes();
    has = !times.empty();
    last_s = has ? times.back().time_s : 0.0;
  }
  // A failed run cannot be resumed (simulate --resume refuses it: issue 65,
  // V03, the advice could not be followed); its frames up to the failure are
  // what it has.
  return impl_->file + " is unfinished (status \"" + status + "\": " + why + "): what follows covers " +
         (has ? "its frames up to t = " + FormatNumber(last_s) + " s only" : "no frame") +
         (failed ? "; it cannot be resumed: change what made it fail (its message above) and run it again"
                 : "; resume it with crowdrecon simulate --resume to finish it");
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
  if (!impl_->segments.empty()) {
    for (std::size_t i = 0; i < impl_->segments.size(); ++i)
      if (impl_->ranges[i].first <= frame && frame <= impl_->ranges[i].second) return impl_->segments[i]->Frame(frame);
    throw InputError(impl_->file + ": no frame " + std::to_string(frame) + " in the run's segments");
  }
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
  if (impl_->packed) {
    const detail::PackedPeople& p = impl_->PackedFrame(frame);
    for (std::size_t k = 0; k < p.person.size(); ++k) {
      f.ids.push_back(std::int64_t{p.person[k]} + 1);
      f.position_m.push_back(p.position_m[k]);
      f.orientation.push_back(detail::OrientationOf(p.angle_rad[k]));
    }
  }
  Statement s(*impl_->db,
              "SELECT frame, id, pos_x, pos_y, ori_x, ori_y FROM trajectory_data WHERE frame = ? ORDER BY id");
  s.Bind(1, frame).Describe("trajectory_data", {0, 1});
  while (!impl_->packed && s.Next()) {
    f.ids.push_back(s.Integer(1, 1, kPersonId));
    f.position_m.push_back({s.Real(2, -kCoordinate_m, kCoordinate_m), s.Real(3, -kCoordinate_m, kCoordinate_m)});
    f.orientation.push_back({s.Real(4, -kUnit, kUnit), s.Real(5, -kUnit, kUnit)});
  }
  Statement c(*impl_->db, std::string(kContactColumns) + " FROM contact WHERE frame = ? ORDER BY rowid");
  c.Bind(1, frame).Describe("contact", {0, 1});
  while (c.Next()) f.contacts.push_back(ReadContact(c));
  if (impl_->dropped.count(frame)) f.contacts.clear();  // a later segment dropped them
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
  if (sqlite::HasTable(*impl_->db, "contact_summary")) tables.emplace_back("contact_summary", "frame");
  for (const char* table : {"contact_kept", "contact_forces"})
    if (sqlite::HasTable(*impl_->db, table)) tables.emplace_back(table, "frame");
  for (const auto& [table, order] : tables) {
    hash.Update(table, std::strlen(table) + 1);
    if (impl_->segments.empty()) {
      ChainAccess::DigestRows(*this, hash, table, order);
    } else {  // a run in segments: the rows of each, in order, as the run made in one go has them
      for (const auto& segment : impl_->segments) ChainAccess::DigestRows(*segment, hash, table, order);
    }
  }
  return hash.HexDigest();
}

void ChainAccess::DigestRows(const RunFileReader& r, Sha256& hash, const std::string& name, const char* order) {
  const RunFileReader::Impl* impl_ = r.impl_.get();
  if (!sqlite::HasTable(*impl_->db, name)) return;
  if (impl_->packed && (name == "trajectory_data" || name == "person_state" || name == "person_load")) {
    // The rows the tables would hold, value for value (frame_pack.hpp).
    const auto real = [](std::string& row, double v) {
      char text[32];
      std::snprintf(text, sizeof text, "r%.17g;", v);
      row += text;
    };
    const std::unique_ptr<PackedFrames> frames = impl_->Packed(0, run_limits::kFrame);
    std::int64_t frame = 0;
    detail::PackedPeople p;
    std::string row;
    while (frames->Next(&frame, &p))
      for (std::size_t k = 0; k < p.person.size(); ++k) {
        row = "i" + std::to_string(frame) + ";i" + std::to_string(std::int64_t{p.person[k]} + 1) + ";";
        if (name == "trajectory_data") {
          real(row, p.position_m[k].x);
          real(row, p.position_m[k].y);
          const Vec2 ori = detail::OrientationOf(p.angle_rad[k]);
          real(row, ori.x);
          real(row, ori.y);
        } else if (name == "person_state") {
          real(row, p.velocity_m_per_s[k].x);
          real(row, p.velocity_m_per_s[k].y);
          real(row, p.angle_rad[k]);
          real(row, p.angular_velocity_rad_per_s[k]);
          row += "i" + std::to_string(static_cast<int>(p.state[k])) + ";";
          real(row, p.load_n[k]);
        } else {
          if (!p.has_loads || (p.chest_n[k] == 0.0 && p.lateral_n[k] == 0.0)) continue;
          real(row, p.chest_n[k]);
          real(row, p.lateral_n[k]);
        }
        row += '\n';
        hash.Update(row.data(), row.size());
      }
    return;
  }
  // Rows a later segment dropped (contacts of a superseded worst moment) are not the run's.
  const bool droppable = !impl_->dropped.empty() && (name == "contact" || name == "contact_kept");
  Statement s(*impl_->db, "SELECT * FROM " + name + " ORDER BY " + order);
  while (s.Next()) {
    if (droppable && impl_->dropped.count(s.Int(0))) continue;
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

std::vector<FrameTime> RunFileReader::FrameTimes() const {
  std::vector<FrameTime> times;
  if (!impl_->segments.empty()) {  // (ChainAccess::Open checked that each segment's frames follow the last's)
    for (const auto& segment : impl_->segments) {
      const std::vector<FrameTime> part = segment->FrameTimes();
      if (!part.empty() && !times.empty() && !(part.front().time_s > times.back().time_s))
        throw InputError(segment->file() + ": table frame_time, row frame " + std::to_string(part.front().frame) +
                         ": time_s " + FormatNumber(part.front().time_s) + " s is not after the segment before it (" +
                         FormatNumber(times.back().time_s) + " s; the run file is damaged)");
      times.insert(times.end(), part.begin(), part.end());
    }
    return times;
  }
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
  std::vector<PersonFrameStream> parts;  // a run in segments: each one's stream, in order
  std::size_t part = 0;
  std::unique_ptr<Statement> query;
  std::unique_ptr<PackedFrames> packed;  // a packed run's frames instead of `query`
  detail::PackedPeople people;
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
  for (; impl_->part < impl_->parts.size(); ++impl_->part)
    if (impl_->parts[impl_->part].Next(out)) return true;
  if (!impl_->parts.empty()) return false;
  if (impl_->packed) {
    detail::PackedPeople& p = impl_->people;
    if (!impl_->packed->Next(&out->frame, &p)) return false;
    out->person = p.person;
    out->position_m = p.position_m;
    out->velocity_m_per_s = p.velocity_m_per_s;
    out->angle_rad = p.angle_rad;
    out->angular_velocity_rad_per_s = p.angular_velocity_rad_per_s;
    out->state = p.state;
    out->load_n = p.load_n;
    return true;
  }
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
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) stream.impl_->parts.push_back(segment->PersonFrames(last_frame));
    return stream;
  }
  if (impl_->packed) {
    stream.impl_->packed = impl_->Packed(0, last_frame);
    return stream;
  }
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
  std::vector<ContactFrameStream> parts;  // a run in segments: each one's stream, in order
  std::size_t part = 0;
  std::unique_ptr<Statement> query;
  bool have_row = false;
  const std::set<std::int64_t>* dropped = nullptr;  // frames whose rows a later segment dropped
};

ContactFrameStream::ContactFrameStream() : impl_(std::make_unique<Impl>()) {}
ContactFrameStream::ContactFrameStream(ContactFrameStream&&) noexcept = default;
ContactFrameStream::~ContactFrameStream() = default;

bool ContactFrameStream::Next(std::int64_t* frame, std::vector<Contact>* out) {
  for (; impl_->part < impl_->parts.size(); ++impl_->part)
    if (impl_->parts[impl_->part].Next(frame, out)) return true;
  if (!impl_->parts.empty()) return false;
  for (;;) {
    if (!impl_->have_row) return false;
    Statement& q = *impl_->query;
    *frame = q.Int(0);
    out->clear();
    while (impl_->have_row && q.Int(0) == *frame) {
      out->push_back(ReadContact(q));
      impl_->have_row = q.Next();
    }
    if (!(impl_->dropped && impl_->dropped->count(*frame))) return true;
  }
}

struct PersonLoadStream::Impl {
  std::vector<PersonLoadStream> parts;  // a run in segments: each one's stream, in order
  std::size_t part = 0;
  std::unique_ptr<Statement> query;
  std::unique_ptr<PackedFrames> packed;  // a packed run's frames instead of `query`
  detail::PackedPeople people;
  bool have_row = false;
};

PersonLoadStream::PersonLoadStream() : impl_(std::make_unique<Impl>()) {}
PersonLoadStream::PersonLoadStream(PersonLoadStream&&) noexcept = default;
PersonLoadStream::~PersonLoadStream() = default;

bool PersonLoadStream::Next(std::int64_t* frame, std::vector<PersonLoad>* out) {
  using namespace run_limits;
  for (; impl_->part < impl_->parts.size(); ++impl_->part)
    if (impl_->parts[impl_->part].Next(frame, out)) return true;
  if (!impl_->parts.empty()) return false;
  if (impl_->packed) {
    // The rows table person_load would hold: people with a load, frames with one.
    detail::PackedPeople& p = impl_->people;
    out->clear();
    while (out->empty()) {
      if (!impl_->packed->Next(frame, &p)) return false;
      if (!p.has_loads) continue;
      for (std::size_t k = 0; k < p.person.size(); ++k)
        if (p.chest_n[k] != 0.0 || p.lateral_n[k] != 0.0) out->push_back({p.person[k], p.chest_n[k], p.lateral_n[k]});
    }
    return true;
  }
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
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) stream.impl_->parts.push_back(segment->PersonLoads(last_frame));
    return stream;
  }
  if (impl_->packed) {
    stream.impl_->packed = impl_->Packed(0, last_frame);
    return stream;
  }
  stream.impl_->query = std::make_unique<Statement>(
      *impl_->db, "SELECT frame, id, chest_n, lateral_n FROM person_load WHERE frame <= ?1 ORDER BY frame, id");
  stream.impl_->query->Bind(1, last_frame).Describe("person_load", {0, 1});
  stream.impl_->have_row = stream.impl_->query->Next();
  return stream;
}

ContactFrameStream RunFileReader::ContactFrames(std::int64_t last_frame) const {
  ContactFrameStream stream;
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) stream.impl_->parts.push_back(segment->ContactFrames(last_frame));
    return stream;
  }
  if (!impl_->dropped.empty()) stream.impl_->dropped = &impl_->dropped;
  stream.impl_->query = std::make_unique<Statement>(
      *impl_->db, std::string(kContactColumns) + " FROM contact WHERE frame <= ?1 ORDER BY frame, rowid");
  stream.impl_->query->Bind(1, last_frame).Describe("contact", {0, 1});
  stream.impl_->have_row = stream.impl_->query->Next();
  return stream;
}

bool RunFileReader::HasContactSummary() const { return sqlite::HasTable(*impl_->db, "contact_summary"); }

bool RunFileReader::KeepsSomeContacts() const { return sqlite::HasTable(*impl_->db, "contact_kept"); }

std::vector<std::pair<std::int64_t, std::string>> RunFileReader::ContactKeptFrames() const {
  std::vector<std::pair<std::int64_t, std::string>> kept;
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) {
      const auto part = segment->ContactKeptFrames();
      kept.insert(kept.end(), part.begin(), part.end());
    }
    return kept;
  }
  if (!KeepsSomeContacts()) return kept;
  Statement s(*impl_->db, "SELECT frame, why FROM contact_kept ORDER BY frame");
  s.Describe("contact_kept", {0});
  while (s.Next())
    if (const std::int64_t frame = s.Integer(0, 0, run_limits::kFrame); !impl_->dropped.count(frame))
      kept.emplace_back(frame, s.Text(1));
  return kept;
}

std::optional<ContactForceBins> RunFileReader::ContactForces(std::int64_t last_frame, std::size_t bins) const {
  if (!impl_->segments.empty()) {
    std::optional<ContactForceBins> sum;
    for (const auto& segment : impl_->segments) {
      const auto part = segment->ContactForces(last_frame, bins);
      if (!part) continue;
      if (!sum) {
        sum = part;
        continue;
      }
      if (part->total > 0 && sum->total > 0 && part->f0_n != sum->f0_n)
        throw InputError(segment->file() + ": table contact_forces bins by " + FormatNumber(part->f0_n) +
                         " N, the segment before it by " + FormatNumber(sum->f0_n) + " N (the run file is damaged)");
      if (sum->total == 0) sum->f0_n = part->f0_n;
      sum->zero += part->zero;
      sum->total += part->total;
      for (std::size_t b = 0; b < bins; ++b) sum->counts[b] += part->counts[b];
    }
    return sum;
  }
  if (!sqlite::HasTable(*impl_->db, "contact_forces")) return std::nullopt;
  ContactForceBins sum;
  sum.counts.assign(bins, 0);
  Statement s(*impl_->db, "SELECT frame, f0_n, zero, total, bins FROM contact_forces WHERE frame <= ?1 ORDER BY frame");
  s.Bind(1, last_frame).Describe("contact_forces", {0});
  constexpr std::int64_t kCount = std::int64_t{1} << 40;
  bool first = true;
  while (s.Next()) {
    const double f0 = s.Real(1, 1e-9, run_limits::kForce_n);
    if (!first && f0 != sum.f0_n)
      throw InputError(impl_->file + ": table contact_forces, row frame " + s.Text(0) + ", column f0_n: " +
                       FormatNumber(f0) + " N, but earlier frames are binned by " + FormatNumber(sum.f0_n) +
                       " N (the run file is damaged)");
    sum.f0_n = f0;
    first = false;
    const std::uint64_t zero = static_cast<std::uint64_t>(s.Integer(2, 0, kCount));
    const std::uint64_t total = static_cast<std::uint64_t>(s.Integer(3, 0, kCount));
    std::uint64_t binned = 0;
    const std::string text = s.Text(4);
    std::size_t at = 0;
    while (at < text.size()) {
      std::size_t end = text.find(' ', at);
      if (end == std::string::npos) end = text.size();
      const std::string pair = text.substr(at, end - at);
      unsigned long long bin = 0, count = 0;
      char tail = 0;
      if (std::sscanf(pair.c_str(), "%llu:%llu%c", &bin, &count, &tail) != 2 || bin >= bins ||
          count > static_cast<unsigned long long>(kCount))
        throw InputError(impl_->file + ": table contact_forces, row frame " + s.Text(0) + ", column bins: \"" +
                         ShortText(pair, 40) + "\"; expected BIN:COUNT pairs with bins below " +
                         std::to_string(bins) + " (the run file is damaged)");
      sum.counts[bin] += count;
      binned += count;
      at = end + 1;
    }
    if (binned + zero != total)
      throw InputError(impl_->file + ": table contact_forces, row frame " + s.Text(0) + ": " + std::to_string(binned) +
                       " forces binned and " + std::to_string(zero) + " of zero, but a total of " +
                       std::to_string(total) + " (the run file is damaged)");
    sum.zero += zero;
    sum.total += total;
  }
  return sum;
}

std::optional<RunFileReader::LargestOverlap> RunFileReader::LargestContactOverlap() const {
  if (!impl_->segments.empty()) {  // the largest; of equal ones the earliest
    std::optional<LargestOverlap> best;
    for (const auto& segment : impl_->segments)
      if (const auto o = segment->LargestContactOverlap(); o && (!best || o->overlap_m > best->overlap_m)) best = o;
    return best;
  }
  // From the frames' briefs where the run has them (issue 66: every frame,
  // whether or not its contacts were written; the same contact as the scan
  // of table contact below finds: the largest, the earliest frame, the
  // first row); else from every contact.
  const bool brief = HasContactSummary();
  Statement q(*impl_->db, brief ? "SELECT frame, 0, max_overlap_m, max_overlap_wall FROM contact_summary "
                                  "WHERE contacts > 0 ORDER BY max_overlap_m DESC, frame LIMIT 1"
                                : "SELECT frame, rowid, overlap_m, wall FROM contact ORDER BY overlap_m DESC, frame, rowid LIMIT 1");
  q.Describe(brief ? "contact_summary" : "contact", {0, 1});
  if (!q.Next()) return std::nullopt;
  LargestOverlap largest;
  largest.frame = q.Int(0);
  largest.overlap_m = q.Real(2, -run_limits::kCoordinate_m, run_limits::kCoordinate_m);
  largest.wall = q.Integer(3, 0, 1) != 0;
  return largest;
}

std::vector<Vec2> RunFileReader::GroupVelocitySums() const {
  // Added in the order of frames and ids, from either storage and across
  // segments, so that every way of writing a run gives the same sums to the
  // last bit (SQLite's SUM adds in an order its query plan chooses).
  std::vector<std::int64_t> group;
  {
    Statement q(*impl_->db, "SELECT id, grp FROM person");
    while (q.Next()) {
      const std::int64_t id = q.Int(0);
      if (id < 1 || id > run_limits::kPersonId) continue;  // People() reports such a row
      if (static_cast<std::size_t>(id) > group.size()) group.resize(static_cast<std::size_t>(id), -1);
      group[static_cast<std::size_t>(id - 1)] = q.Int(1);
    }
  }
  std::vector<Vec2> sums;
  if (impl_->segments.empty()) ChainAccess::AddGroupVelocities(*this, group, sums);
  for (const auto& segment : impl_->segments) ChainAccess::AddGroupVelocities(*segment, group, sums);
  return sums;
}

void ChainAccess::AddGroupVelocities(const RunFileReader& r, const std::vector<std::int64_t>& group,
                                     std::vector<Vec2>& sums) {
  const auto add = [&](std::int64_t id, Vec2 v) {
    if (id < 1 || static_cast<std::size_t>(id) > group.size()) return;
    const std::int64_t g = group[static_cast<std::size_t>(id - 1)];
    if (g < 0 || g > run_limits::kGroup) return;  // PersonGroups() reports such a row
    if (static_cast<std::size_t>(g) >= sums.size()) sums.resize(static_cast<std::size_t>(g) + 1);
    sums[static_cast<std::size_t>(g)] += v;
  };
  if (r.impl_->packed) {
    const std::unique_ptr<PackedFrames> frames = r.impl_->Packed(0, run_limits::kFrame);
    std::int64_t frame = 0;
    detail::PackedPeople p;
    while (frames->Next(&frame, &p))
      for (std::size_t k = 0; k < p.person.size(); ++k) add(std::int64_t{p.person[k]} + 1, p.velocity_m_per_s[k]);
    return;
  }
  Statement q(*r.impl_->db, "SELECT id, vel_x, vel_y FROM person_state ORDER BY frame, id");
  while (q.Next()) add(q.Int(0), {q.Double(1), q.Double(2)});
}

std::vector<Event> RunFileReader::Events() const {
  std::vector<Event> events;
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) {
      std::vector<Event> part = segment->Events();
      events.insert(events.end(), std::make_move_iterator(part.begin()), std::make_move_iterator(part.end()));
    }
    return events;
  }
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
  if (!impl_->segments.empty()) {
    for (const auto& segment : impl_->segments) {
      const std::vector<CensusRow> part = segment->CensusRows();
      rows.insert(rows.end(), part.begin(), part.end());
    }
    return rows;
  }
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
