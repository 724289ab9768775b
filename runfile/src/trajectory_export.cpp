#include "crowdrecon/runfile/trajectory_export.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"
#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "jupedsim_tables.hpp"

namespace crowdrecon::runfile {

namespace {

namespace fs = std::filesystem;
using sqlite::Database;
using sqlite::Statement;

// After the JuPedSim tables (jupedsim_tables.hpp): the map from the
// export's ids to the run's people, with each person's group and target (so
// that a PedPy user splits by direction without opening the run file).
constexpr const char* kTrackSchema = R"SQL(
CREATE TABLE crowdrecon_track(id INTEGER PRIMARY KEY, person INTEGER NOT NULL, part INTEGER NOT NULL,
  first_frame INTEGER NOT NULL, last_frame INTEGER NOT NULL, grp INTEGER NOT NULL, target TEXT NOT NULL DEFAULT '');
)SQL";

// Rows per transaction: a commit per frame of a small run would cost more
// than its rows; committing now and then keeps few pages dirty in SQLite's
// cache, whatever the run's length.
constexpr std::int64_t kRowsPerTransaction = 200000;

using detail::GeometryHash;
using detail::NumberText;

std::string BoxJson(const PeriodicBox& box) {
  const nlohmann::json j = {{"x", box.x}, {"y", box.y}, {"min_m", {box.min_m.x, box.min_m.y}},
                            {"max_m", {box.max_m.x, box.max_m.y}}};
  return j.dump();
}

// The piece of a person's trajectory being written.
struct OpenPiece {
  bool seen = false;
  Vec2 last_m;  // the person's latest position, as stored (wrapped)
  std::int64_t id = 0, part = 0, first_frame = 0, last_frame = 0;
};

// The extent of the positions written (metadata xmin, xmax, ymin, ymax).
struct Bounds {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  void Add(Vec2 p) {
    xmin = std::min(xmin, p.x);
    xmax = std::max(xmax, p.x);
    ymin = std::min(ymin, p.y);
    ymax = std::max(ymax, p.y);
  }
};

// JuPedSim's keys, and crowdrecon's saying what the export did.
void WriteMetadata(const Database& db, const RunFileReader& run, double fps, const Bounds& bounds,
                   const ExportSummary& summary) {
  Statement meta(db, "INSERT INTO metadata VALUES(?, ?)");
  const auto put = [&meta](const std::string& key, const std::string& value) { meta.Bind(1, key).Bind(2, value).Run(); };
  put("version", "2");
  put("fps", NumberText(fps));
  if (summary.rows > 0) {
    put("xmin", NumberText(bounds.xmin));
    put("xmax", NumberText(bounds.xmax));
    put("ymin", NumberText(bounds.ymin));
    put("ymax", NumberText(bounds.ymax));
  }
  put("crowdrecon_export", "1");
  put("crowdrecon_source", fs::path(run.file()).filename().string());
  if (summary.box.any()) put("crowdrecon_periodic", BoxJson(summary.box));
  put("crowdrecon_split_at_seams", std::to_string(summary.splits));
  put("crowdrecon_people", std::to_string(summary.people));
  put("crowdrecon_tracks", std::to_string(summary.tracks));
}

// Streams the run into `db` (an empty file).
ExportSummary WriteExport(const RunFileReader& run, Database& db) {
  ExportSummary summary;
  summary.box = run.periodic_box();
  const std::string wkt = run.walkable_wkt();
  const std::int64_t geometry_hash = GeometryHash(wkt);
  const double fps = run.fps();
  // Ids of later pieces start above every person id, so that a first piece
  // keeps its person's id without ever meeting a later piece's.
  const std::vector<Person> people = run.People();
  std::vector<OpenPiece> pieces(people.size());
  std::int64_t next_id = static_cast<std::int64_t>(pieces.size()) + 1;

  // The file gets its name only when complete (ExportTrajectories), so a
  // journal and syncing would protect nothing.
  db.Exec("PRAGMA journal_mode=OFF");
  db.Exec("PRAGMA synchronous=OFF");
  db.Exec("BEGIN");
  db.Exec(detail::kJuPedSimSchema);
  db.Exec(kTrackSchema);
  {
    Statement geo(db, "INSERT INTO geometry VALUES(?, ?)");
    geo.Bind(1, geometry_hash).Bind(2, wkt).Run();
  }
  sqlite::BatchInsert trajectory(db, "trajectory_data", 6), frame_data(db, "frame_data", 2),
      track(db, "crowdrecon_track(id, person, part, first_frame, last_frame, grp)", 6);  // target: below
  const auto close_piece = [&track, &people](const OpenPiece& p, std::size_t person) {
    track.Add(p.id).Add(static_cast<std::int64_t>(person) + 1).Add(p.part).Add(p.first_frame).Add(p.last_frame);
    track.Add(static_cast<std::int64_t>(people[person].group));
  };
  Bounds bounds;

  // Every frame of frame_time gets its frame_data row, also one where nobody
  // is present; rows of a frame missing there (a damaged file) are still
  // copied, so that the export holds every row of the run.
  const std::vector<std::int64_t> frames = run.Frames();
  std::size_t k = 0;
  PersonFrameStream stream = run.PersonFrames(run_limits::kFrame);
  PersonFrame rows;
  bool have_rows = stream.Next(&rows);
  std::int64_t rows_in_transaction = 0;
  while (have_rows || k < frames.size()) {
    const std::int64_t frame =
        have_rows && (k == frames.size() || rows.frame <= frames[k]) ? rows.frame : frames[k];
    if (k < frames.size() && frames[k] == frame) ++k;
    frame_data.Add(frame).Add(geometry_hash);
    ++summary.frames;
    if (have_rows && rows.frame == frame) {
      for (std::size_t r = 0; r < rows.person.size(); ++r) {
        const std::size_t i = rows.person[r];
        if (i >= pieces.size())
          throw InputError(run.file() + ": table trajectory_data, row frame " + std::to_string(frame) + ", id " +
                           std::to_string(i + 1) + ": no such person; expected an id of table person (1.." +
                           std::to_string(pieces.size()) + ") (the run file is damaged)");
        OpenPiece& p = pieces[i];
        const Vec2 x = rows.position_m[r];
        if (!p.seen) {
          p.seen = true;
          p.id = static_cast<std::int64_t>(i) + 1;
          p.first_frame = frame;
          ++summary.people;
        } else {
          // A step across a seam is the only one whose minimum image differs
          // from the raw difference (which is then about a period long).
          const Vec2 step = x - p.last_m;
          if (!(summary.box.MinimumImage(step) == step)) {
            close_piece(p, i);
            p.id = next_id++;
            ++p.part;
            p.first_frame = frame;
            ++summary.splits;
          }
        }
        p.last_m = x;
        p.last_frame = frame;
        // The run file's orientation, as RunFileWriter::WriteFrame writes it.
        const double angle = rows.angle_rad[r];
        trajectory.Add(frame).Add(p.id).Add(x.x).Add(x.y).Add(std::cos(angle)).Add(std::sin(angle));
        bounds.Add(x);
      }
      summary.rows += static_cast<std::int64_t>(rows.person.size());
      rows_in_transaction += static_cast<std::int64_t>(rows.person.size());
      have_rows = stream.Next(&rows);
    }
    if (rows_in_transaction >= kRowsPerTransaction) {
      for (sqlite::BatchInsert* batch : {&trajectory, &frame_data, &track}) batch->Finish();
      db.Exec("COMMIT");
      db.Exec("BEGIN");
      rows_in_transaction = 0;
    }
  }
  for (std::size_t i = 0; i < pieces.size(); ++i)
    if (pieces[i].seen) close_piece(pieces[i], i);
  for (sqlite::BatchInsert* batch : {&trajectory, &frame_data, &track}) batch->Finish();
  summary.tracks = summary.people + summary.splits;
  // Each track's target by name, set in one statement from the people's.
  db.Exec("CREATE TEMP TABLE person_target(person INTEGER PRIMARY KEY, target TEXT NOT NULL)");
  {
    Statement put(db, "INSERT INTO person_target VALUES(?, ?)");
    for (std::size_t i = 0; i < people.size(); ++i)
      put.Bind(1, static_cast<std::int64_t>(i) + 1).Bind(2, people[i].target).Run();
  }
  db.Exec("UPDATE crowdrecon_track SET target = (SELECT target FROM person_target p WHERE p.person = crowdrecon_track.person)");
  db.Exec("DROP TABLE person_target");

  WriteMetadata(db, run, fps, bounds, summary);
  // After the rows: one sort instead of an index kept up to date row by row.
  db.Exec("CREATE INDEX frame_id_idx ON trajectory_data(frame, id)");
  db.Exec("COMMIT");
  return summary;
}

}  // namespace

ExportSummary ExportTrajectories(const RunFileReader& run, const fs::path& file) {
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw InputError(file.string() + ": " + folder.string() +
                     (fs::exists(folder, ec) ? " is " + DescribeExisting(folder) + ", not a folder"
                                             : " does not exist") +
                     "; expected an existing folder to write the export into");
  const fs::path partial = PartialPath(file);
  fs::remove(partial, ec);
  const RemoveOnInterrupt remove_on_interrupt(partial);
  std::vector<std::string> removed_partials;
  for (const fs::path& p : RemoveStalePartialsOf(file)) removed_partials.push_back(p.string());
  ExportSummary summary;
  try {
    {
      Database db(partial.string(), SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
      summary = WriteExport(run, db);
    }  // closed before it is renamed
    // A killed writer's log beside the file replaced would be applied to
    // the export by every reader.
    summary.removed_sidecars = sqlite::RemoveSidecars(file);
    summary.removed_partials = removed_partials;
    fs::rename(partial, file, ec);
    if (ec)
      throw InputError(file.string() + ": cannot write the export (renaming " + partial.string() + ": " +
                       ec.message() + ")");
  } catch (...) {
    std::error_code ignored;
    fs::remove(partial, ignored);
    throw;
  }
  return summary;
}

OutputKind TrajectoryExportOutput() {
  return {"a crowdrecon trajectory export", false, [](const fs::path& file) {
            if (!FileStartsWith(file, std::string("SQLite format 3\0", 16))) return false;
            try {
              const Database db(file.string(), SQLITE_OPEN_READONLY);
              Statement s(db, "SELECT value FROM metadata WHERE key = 'crowdrecon_export'");
              return s.Next();
            } catch (const std::exception&) {  // unreadable or foreign: not ours
              return false;
            }
          }};
}

}  // namespace crowdrecon::runfile
