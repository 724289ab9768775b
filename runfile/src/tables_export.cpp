// A run as one run file with tables (tables_export.hpp).
#include "crowdrecon/runfile/tables_export.hpp"

#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "frame_pack.hpp"

namespace crowdrecon::runfile {

namespace {

using sqlite::Database;
using sqlite::Statement;

std::string Quoted(const std::string& path) {
  std::string q = "'";
  for (const char c : path) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

// The per-frame tables copied row for row (the people's tables too, where a
// segment has them as tables); contact and contact_kept without the rows a
// later segment dropped.
constexpr const char* kCopied[] = {"trajectory_data", "person_state", "person_load", "frame_time", "frame_data",
                                   "contact",         "event",        "census",      "contact_summary",
                                   "contact_kept",    "contact_forces"};

// Writes `file` through its partial file: `write` fills the partial (absent
// when it starts), renamed over `file` when it returns, removed if it throws.
void WriteThroughPartial(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write) {
  const std::filesystem::path partial = PartialPath(file);
  std::error_code ec;
  std::filesystem::remove(partial, ec);
  sqlite::RemoveSidecars(partial);
  try {
    write(partial);
  } catch (...) {
    std::filesystem::remove(partial, ec);
    sqlite::RemoveSidecars(partial);
    throw;
  }
  std::filesystem::rename(partial, file);
}

}  // namespace

TablesExportSummary WriteRunTables(const RunFileReader& run, const std::filesystem::path& file) {
  TablesExportSummary summary;
  const std::vector<std::string> segments = run.SegmentFiles();
  summary.segments = static_cast<std::int64_t>(segments.size());
  WriteThroughPartial(file, [&](const std::filesystem::path& partial) {
    {  // The header as the run's, no frame.
      const RunFileReader last = RunFileReader::OneSegment(segments.back());
      RunHeader header = last.Header();
      header.packed = false;
      const RunSetup setup = last.Setup();
      (void)RunFileWriter::Create(partial, header, setup);
    }
    Database db(partial.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX);
    db.Exec("PRAGMA journal_mode=OFF");  // a partial file: renamed when whole, removed if not
    db.Exec("PRAGMA synchronous=OFF");
    // Rows of contacts that a later segment dropped.
    std::set<std::int64_t> dropped;
    for (const std::string& segment : segments) {
      const Database s(segment, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX);
      if (!sqlite::HasTable(s, "contact_dropped")) continue;
      Statement d(s, "SELECT frame FROM contact_dropped");
      while (d.Next()) dropped.insert(d.Int(0));
    }
    std::string excluded = "(";
    for (const std::int64_t f : dropped) excluded += (excluded.size() > 1 ? "," : "") + std::to_string(f);
    excluded += ")";
    {  // The run values of the last segment, less those of its storage and chain.
      db.Exec("ATTACH DATABASE " + Quoted(segments.back()) + " AS seg");
      db.Exec("INSERT OR REPLACE INTO main.run SELECT key, value FROM seg.run WHERE key NOT IN "
              "('frames', 'continues', 'continues_at_frame', 'segment')");
      db.Exec("DETACH DATABASE seg");
    }
    for (const std::string& segment : segments) {
      db.Exec("ATTACH DATABASE " + Quoted(segment) + " AS seg");
      db.Exec("BEGIN");
      for (const char* table : kCopied) {
        Statement has(db, "SELECT COUNT(*) FROM seg.sqlite_master WHERE type = 'table' AND name = ?");
        has.Bind(1, std::string(table));
        if (!has.Next() || has.Int(0) == 0) continue;
        db.Exec(std::string("CREATE TABLE IF NOT EXISTS main.") + table + " AS SELECT * FROM seg." + table + " WHERE 0");
        const bool droppable = std::string(table) == "contact" || std::string(table) == "contact_kept";
        db.Exec(std::string("INSERT INTO main.") + table + " SELECT * FROM seg." + table +
                (droppable && !dropped.empty() ? " WHERE frame NOT IN " + excluded : "") + " ORDER BY rowid");
      }
      db.Exec("COMMIT");
      db.Exec("DETACH DATABASE seg");
      // A packed segment's people, unpacked into the tables.
      const RunFileReader one = RunFileReader::OneSegment(segment);
      if (!one.packed()) continue;
      db.Exec("BEGIN");
      sqlite::BatchInsert traj(db, "trajectory_data", 6), state(db, "person_state", 8);
      PersonFrameStream frames = one.PersonFrames(run_limits::kFrame);
      PersonFrame f;
      while (frames.Next(&f)) {
        for (std::size_t k = 0; k < f.person.size(); ++k) {
          const auto id = static_cast<std::int64_t>(f.person[k]) + 1;
          const double angle = f.angle_rad[k];
          const Vec2 ori = detail::OrientationOf(angle);
          traj.Add(f.frame).Add(id).Add(f.position_m[k].x).Add(f.position_m[k].y).Add(ori.x).Add(ori.y);
          state.Add(f.frame).Add(id).Add(f.velocity_m_per_s[k].x).Add(f.velocity_m_per_s[k].y).Add(angle)
              .Add(f.angular_velocity_rad_per_s[k]).Add(static_cast<std::int64_t>(f.state[k])).Add(f.load_n[k]);
          ++summary.rows;
        }
        ++summary.frames;
      }
      traj.Finish();
      state.Finish();
      sqlite::BatchInsert loads(db, "person_load", 4);
      PersonLoadStream load_frames = one.PersonLoads(run_limits::kFrame);
      std::int64_t frame = 0;
      std::vector<PersonLoad> rows;
      while (load_frames.Next(&frame, &rows))
        for (const PersonLoad& l : rows) loads.Add(frame).Add(std::int64_t{l.person} + 1).Add(l.chest_n).Add(l.lateral_n);
      loads.Finish();
      db.Exec("COMMIT");
    }
    db.Exec("BEGIN");
    // JuPedSim's bounds over every frame.
    for (const char* bound : {"xmin", "xmax", "ymin", "ymax"}) {
      const std::string f = std::string(bound).substr(1) == "min" ? "MIN" : "MAX";
      const std::string column = bound[0] == 'x' ? "pos_x" : "pos_y";
      db.Exec(std::string("INSERT OR REPLACE INTO metadata SELECT '") + bound + "', printf('%.17g', " + f + "(" +
              column + ")) FROM trajectory_data WHERE EXISTS (SELECT 1 FROM trajectory_data)");
    }
    db.Exec("COMMIT");
  });
  return summary;
}

void WriteSegmentHead(const std::filesystem::path& segment, const std::filesystem::path& file) {
  WriteThroughPartial(file, [&](const std::filesystem::path& partial) {
    CopyRunFile(segment, partial);
    {
      Database db(partial.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX);
      db.Exec("BEGIN");
      // Every per-frame row but the last frame's time; the tables stay, empty
      // (a packed segment's head is packed too).
      std::vector<std::string> per_frame(std::begin(kCopied), std::end(kCopied));
      per_frame.insert(per_frame.end(), {"frame_pack", "contact_dropped"});
      for (const std::string& table : per_frame)
        if (sqlite::HasTable(db, table))
          db.Exec("DELETE FROM " + table + (table == "frame_time" ? " WHERE frame <> (SELECT MAX(frame) FROM frame_time)" : ""));
      Statement put(db, "INSERT OR REPLACE INTO run VALUES('segment_head', ?)");
      put.Bind(1, "its frames left out to carry the run to another machine (crowdrecon export --segment-head of " +
                      segment.filename().string() + ")")
          .Run();
      db.Exec("COMMIT");
      db.Exec("VACUUM");
    }
  });
}

}  // namespace crowdrecon::runfile
