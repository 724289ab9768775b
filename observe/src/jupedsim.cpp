// JuPedSim SQLite trajectory files, versions 1-3, and crowdrecon run files.
// Versions (JuPedSim's python_modules/jupedsim/jupedsim/sqlite_serialization.py
// and PedPy's loader): 1 has geometry(wkt); 2 has trajectory_data(frame, id,
// pos_x, pos_y, ori_x, ori_y), geometry(hash, wkt) and frame_data(frame,
// geometry_hash) -- the walkable area is the union of the geometries; 3 drops
// ori_x and ori_y. All keep metadata(key, value) with version and fps.
#include <sqlite3.h>

#include <cmath>
#include <set>
#include <unordered_set>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/runfile/sqlite.hpp"

namespace crowdrecon::observe {

namespace {

std::set<std::string> Columns(const sqlite::Database& db, const std::string& table) {
  std::set<std::string> out;
  sqlite::Statement s(db, "PRAGMA table_info(" + table + ")");
  while (s.Next()) out.insert(s.Text(1));
  return out;
}

std::string Metadata(const sqlite::Database& db, const std::string& key) {
  sqlite::Statement s(db, "SELECT value FROM metadata WHERE key = ?");
  s.Bind(1, key);
  return s.Next() ? s.Text(0) : "";
}

}  // namespace

Trajectories ReadJuPedSim(const std::filesystem::path& file, double fps_override) {
  const std::string name = file.string();
  if (!std::filesystem::is_regular_file(file)) throw InputError(name + ": no such trajectory file");
  Trajectories t;
  t.source = name;
  {
    sqlite::Database db(name, SQLITE_OPEN_READONLY);
    const auto fail = [&](const std::string& what) {
      throw InputError(name + ": " + what + " (expected a JuPedSim SQLite trajectory file, version 1, 2 or 3)");
    };
    // A file SQLite cannot read as a database fails on its first query.
    try {
      if (!sqlite::HasTable(db, "trajectory_data")) fail("no table trajectory_data");
    } catch (const InputError& e) {
      if (std::string(e.what()).find("expected a JuPedSim") != std::string::npos) throw;
      fail("not a readable SQLite database");
    }
    if (!sqlite::HasTable(db, "metadata")) fail("no table metadata");
    const std::set<std::string> columns = Columns(db, "trajectory_data");
    for (const char* c : {"frame", "id", "pos_x", "pos_y"})
      if (!columns.count(c)) fail(std::string("table trajectory_data has no column ") + c);

    const std::string version_text = Metadata(db, "version");
    int version = 0;
    if (version_text == "1" || version_text == "2" || version_text == "3") version = version_text[0] - '0';
    else fail("metadata version \"" + ShortText(version_text, 20) + "\"");
    const bool ours = sqlite::HasTable(db, "run");
    t.format = ours ? "crowdrecon-run" : "jupedsim-v" + std::to_string(version);

    const std::string fps_text = Metadata(db, "fps");
    double file_fps = 0.0;
    if (!fps_text.empty()) {
      char* end = nullptr;
      file_fps = std::strtod(fps_text.c_str(), &end);
      if (end != fps_text.c_str() + fps_text.size() || !(file_fps > 0.0 && file_fps <= 10000.0))
        fail("metadata fps \"" + ShortText(fps_text, 20) + "\" is not a frame rate in (0, 10000]");
    }
    t.fps = fps_override > 0.0 ? fps_override : file_fps;
    if (!(t.fps > 0.0)) throw InputError(name + ": metadata has no fps; give the frame rate with --fps");

    if (sqlite::HasTable(db, "geometry")) {
      sqlite::Statement g(db, "SELECT wkt FROM geometry");
      std::vector<std::string> wkts;
      while (g.Next()) wkts.push_back(g.Text(0));
      if (wkts.size() == 1) t.walkable_wkt = wkts.front();
      else if (wkts.size() > 1) {
        t.walkable_wkt = wkts.front();
        t.notes.push_back(std::to_string(wkts.size()) + " geometries (the walkable area changed during the run): the first is kept");
      }
    }

    sqlite::Statement s(db, "SELECT frame, id, pos_x, pos_y FROM trajectory_data ORDER BY frame, id");
    s.Describe("trajectory_data", {0, 1});
    std::unordered_set<std::uint32_t> ids;
    bool first = true;
    while (s.Next()) {
      // JuPedSim 1.x stores the frame as iteration / every_nth_frame, a
      // Python float: whole numbers stored as REAL are accepted.
      const int type = s.Type(0);
      const double frame_value = s.Double(0);
      if ((type != SQLITE_INTEGER && type != SQLITE_FLOAT) || frame_value != std::floor(frame_value) ||
          frame_value < 0 || frame_value > static_cast<double>(kMaxFrame))
        fail("table trajectory_data, column frame: \"" + ShortText(s.Text(0), 24) + "\" is not a whole number in [0, " +
             std::to_string(kMaxFrame) + "]");
      TrajectoryPoint p;
      p.frame = static_cast<std::int64_t>(frame_value);
      p.id = static_cast<std::uint32_t>(s.Integer(1, 0, kMaxPersonId));
      p.position_m = {s.Real(2, -kMaxCoordinate_m, kMaxCoordinate_m), s.Real(3, -kMaxCoordinate_m, kMaxCoordinate_m)};
      t.points.push_back(p);
      ids.insert(p.id);
      t.first_frame = first ? p.frame : std::min(t.first_frame, p.frame);
      t.last_frame = first ? p.frame : std::max(t.last_frame, p.frame);
      first = false;
    }
    if (t.points.empty()) throw InputError(name + ": table trajectory_data is empty; expected trajectories");
    t.people = ids.size();
  }
  if (t.format == "crowdrecon-run") {
    const runfile::RunFileReader run(file);
    t.box = run.periodic_box();
    const std::vector<std::uint32_t> groups = run.PersonGroups();
    for (std::size_t i = 0; i < groups.size(); ++i)
      t.groups.emplace_back(static_cast<std::uint32_t>(i + 1), groups[i]);
    if (t.box.any()) t.notes.push_back("periodic run: positions are wrapped; velocities are taken over minimum images");
  }
  return t;
}

}  // namespace crowdrecon::observe
