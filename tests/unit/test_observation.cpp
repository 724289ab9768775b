// Observations (issue 22): the stop/surge detector on series with known
// changes; observations of trajectories made in memory with known speeds,
// shares, densities, peak speeds and crossings (two directions, a stalled direction, a
// periodic seam); JuPedSim files of versions 1-3 read and bad ones refused;
// the file format written and read back, and a changed CSV refused; specs
// refused with their JSON path; Weidmann's relation.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/observe/events.hpp"
#include "crowdrecon/observe/fundamental_diagram.hpp"
#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "scratch.hpp"

namespace crowdrecon::observe {
namespace {

using crowdrecon::testing::ScratchFile;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A series sampled every bin_s from `segments` of (duration, speed), with
// a small alternating ripple (a crowd is never perfectly steady).
struct Built {
  std::vector<double> t, v;
};
Built Stepped(double bin_s, const std::vector<std::pair<double, double>>& segments, double ripple = 0.03) {
  Built b;
  double t = 0.0;
  for (auto [duration, speed] : segments)
    for (double end = t + duration - 1e-9; t < end; t += bin_s) {
      b.t.push_back(t);
      b.v.push_back(std::max(0.0, speed + (b.t.size() % 2 ? ripple : -ripple)));
    }
  return b;
}

TEST(Events, AStopAndASurgeAreFoundWithinABinOfTheirChange) {
  const double bin = 0.2;
  const Built s = Stepped(bin, {{10.0, 1.0}, {5.0, 0.0}, {10.0, 0.6}});
  const std::vector<Event> e = DetectEvents(s.t, s.v, bin, 0.3, EventOptions{}, "r", "forward");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].kind, "stop");
  EXPECT_NEAR(e[0].time_s, 10.0, bin + 1e-9);
  EXPECT_FALSE(e[0].censored);
  EXPECT_EQ(e[1].kind, "surge");
  EXPECT_NEAR(e[1].time_s, 15.0, bin + 1e-9);
  EXPECT_NEAR(e[0].end_s, e[1].time_s, 1e-12);
  EXPECT_NEAR(e[1].peak_speed_m_per_s, 0.63, 1e-9);
  EXPECT_LE(e[1].rise_time_s, 2 * bin + 1e-9);
  EXPECT_TRUE(std::isnan(e[1].end_s));
  EXPECT_EQ(e[1].uncertainty_s, 0.3);
}

TEST(Events, ShortDipsAreNoStopsAndAFirstStopIsCensored) {
  const double bin = 0.2;
  // A 0.6 s dip (shorter than min_stop_s = 1 s): nothing.
  const Built dip = Stepped(bin, {{10.0, 1.0}, {0.6, 0.0}, {10.0, 1.0}});
  EXPECT_TRUE(DetectEvents(dip.t, dip.v, bin, 0.3, EventOptions{}, "r", "all").empty());
  // Stopped from the start, then a release: a censored stop and a surge.
  const Built start = Stepped(bin, {{6.0, 0.0}, {6.0, 0.8}});
  const std::vector<Event> e = DetectEvents(start.t, start.v, bin, 0.3, EventOptions{}, "r", "all");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_TRUE(e[0].censored);
  EXPECT_EQ(e[0].time_s, 0.0);
  EXPECT_NEAR(e[1].time_s, 6.0, bin + 1e-9);
  // Stop and go three times: three stops and three surges.
  const Built go = Stepped(bin, {{5, 1}, {3, 0}, {5, 1}, {3, 0}, {5, 1}, {3, 0}, {5, 1}});
  const std::vector<Event> g = DetectEvents(go.t, go.v, bin, 0.3, EventOptions{}, "r", "all");
  ASSERT_EQ(g.size(), 6u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(g[2 * k].time_s, 5.0 + 8.0 * k, bin + 1e-9);
    EXPECT_NEAR(g[2 * k + 1].time_s, 8.0 + 8.0 * k, bin + 1e-9);
  }
  // NaN bins (unusable frames) add no evidence and break nothing.
  Built holes = go;
  for (std::size_t i = 0; i < holes.v.size(); i += 7) holes.v[i] = std::nan("");
  EXPECT_EQ(DetectEvents(holes.t, holes.v, bin, 0.3, EventOptions{}, "r", "all").size(), 6u);
}

// Two groups in a 10 m x 4 m corridor (three backward people are enough
// moving floor, 0.3 m2, for their direction's speed to be defined) at 25 fps for 8 s: `forward` people
// at 1.2 m/s along +x, `backward` ones at `backward_speed` along -x.
Trajectories Corridor(int forward, int backward, double backward_speed, PeriodicBox box = {}) {
  Trajectories t;
  t.source = "corridor (in memory)";
  t.format = "test";
  t.fps = 25.0;
  t.box = box;
  std::uint32_t id = 1;
  for (int g = 0; g < 2; ++g)
    for (int i = 0; i < (g == 0 ? forward : backward); ++i, ++id) {
      const double speed = g == 0 ? 1.2 : -backward_speed;
      const double x0 = g == 0 ? 0.5 + 0.4 * i : 9.5 - 0.4 * i, y = 0.3 + 0.35 * i + (g ? 0.15 : 0.0);
      for (int f = 0; f < 200; ++f) {
        double x = x0 + speed * f / 25.0;
        if (box.x) x = box.min_m.x + std::fmod(std::fmod(x - box.min_m.x, 10.0) + 10.0, 10.0);
        t.points.push_back({id, f, {x, std::fmod(y, 4.0)}, 0.0});
      }
    }
  t.people = id - 1;
  t.first_frame = 0;
  t.last_frame = 199;
  return t;
}

ObservationSpec CorridorSpec() {
  ObservationSpec spec;
  spec.regions.push_back({"all", {{-100, 0}, {100, 0}, {100, 4}, {-100, 4}}});
  spec.lines.push_back({"x5", {5, 0}, {5, 4}});
  spec.bin_s = 0.4;
  return spec;
}

TEST(Observation, SpeedsSharesDensityAndFlowOfTwoKnownGroups) {
  const Trajectories t = Corridor(8, 3, 0.8);
  const Observation obs = ObserveTrajectories(t, CorridorSpec());
  EXPECT_EQ(obs.bins, 20u);
  const Series* f = obs.Find("speed", "all", "forward");
  const Series* b = obs.Find("speed", "all", "backward");
  const Series* c = obs.Find("counterflow_share", "all", "all");
  const Series* d = obs.Find("density", "all", "all");
  const Series* still = obs.Find("share_still", "all", "all");
  ASSERT_TRUE(f && b && c && d && still);
  for (std::size_t k = 0; k < obs.bins; ++k) {
    EXPECT_NEAR(f->points[k].value, 1.2, 1e-9);
    EXPECT_NEAR(b->points[k].value, 0.8, 1e-9);
    EXPECT_NEAR(f->points[k].uncertainty, 0.0, 1e-6);  // every forward sample is 1.2 m/s
    EXPECT_NEAR(c->points[k].value, 3.0 / 11.0, 1e-12);
    EXPECT_NEAR(d->points[k].value, 11.0 / 800.0, 1e-12);
    EXPECT_NEAR(still->points[k].value, 0.0, 1e-12);
  }
  // Crossings of x = 5: every forward person starting left of it that
  // reaches it in 8 s, every backward person likewise.
  double forward_crossings = 0, backward_crossings = 0;
  for (const SeriesPoint& p : obs.Find("flow", "x5", "forward")->points) forward_crossings += p.value * 0.4 * 4.0;
  for (const SeriesPoint& p : obs.Find("flow", "x5", "backward")->points) backward_crossings += p.value * 0.4 * 4.0;
  int expect_f = 0, expect_b = 0;
  for (int i = 0; i < 8; ++i) expect_f += (0.5 + 0.4 * i < 5.0 && 0.5 + 0.4 * i + 1.2 * 199 / 25.0 >= 5.0);
  for (int i = 0; i < 3; ++i) expect_b += (9.5 - 0.4 * i > 5.0 && 9.5 - 0.4 * i - 0.8 * 199 / 25.0 <= 5.0);
  EXPECT_NEAR(forward_crossings, expect_f, 1e-9);
  EXPECT_NEAR(backward_crossings, expect_b, 1e-9);
  EXPECT_TRUE(obs.events.empty());
}

// max_speed: the fastest sample of the bin, whichever way it moves; its
// uncertainty, the spec's speed resolution (the still speed).
TEST(Observation, MaxSpeedIsTheFastestSampleEitherWay) {
  const Observation one = ObserveTrajectories(Corridor(8, 1, 3.0), CorridorSpec());
  const Series* m = one.Find("max_speed", "all", "all");
  ASSERT_TRUE(m);
  EXPECT_EQ(m->unit, "m/s");
  for (const SeriesPoint& p : m->points) {
    EXPECT_NEAR(p.value, 3.0, 1e-9);  // the one backward runner
    EXPECT_EQ(p.uncertainty, 0.1);
  }
  const Observation three = ObserveTrajectories(Corridor(8, 3, 0.8), CorridorSpec());
  for (const SeriesPoint& p : three.Find("max_speed", "all", "all")->points)
    EXPECT_NEAR(p.value, 1.2, 1e-9);  // now a forward walker is the fastest
}

TEST(Observation, AStalledDirectionReadsAsStoppedNotAsItsJitter) {
  const Observation obs = ObserveTrajectories(Corridor(8, 3, 0.0), CorridorSpec());
  for (const SeriesPoint& p : obs.Find("speed", "all", "backward")->points) EXPECT_EQ(p.value, 0.0);
  for (const SeriesPoint& p : obs.Find("share_still", "all", "all")->points) EXPECT_NEAR(p.value, 3.0 / 11.0, 1e-12);
  for (const SeriesPoint& p : obs.Find("counterflow_share", "all", "all")->points) EXPECT_NEAR(p.value, 0.0, 1e-12);
  // The stalled direction is one censored stop that never ends.
  int stops = 0;
  for (const Event& e : obs.events)
    if (e.direction == "backward") {
      EXPECT_EQ(e.kind, "stop");
      EXPECT_TRUE(e.censored);
      ++stops;
    }
  EXPECT_EQ(stops, 1);
}

TEST(Observation, APeriodicSeamIsNoJump) {
  PeriodicBox box;
  box.x = true;
  box.min_m = {0, 0};
  box.max_m = {10, 4};
  Trajectories t = Corridor(8, 3, 0.8, box);
  const Observation obs = ObserveTrajectories(t, CorridorSpec());
  for (const SeriesPoint& p : obs.Find("speed", "all", "forward")->points) EXPECT_NEAR(p.value, 1.2, 1e-9);
  for (const SeriesPoint& p : obs.Find("speed", "all", "backward")->points) EXPECT_NEAR(p.value, 0.8, 1e-9);
  // Without the box the same positions jump by 10 m at the seam.
  t.box = {};
  const Observation naive = ObserveTrajectories(t, CorridorSpec());
  double worst = 0;
  for (const char* dir : {"forward", "backward"})
    for (const SeriesPoint& p : naive.Find("speed", "all", dir)->points) worst = std::max(worst, p.value);
  EXPECT_GT(worst, 2.0);
}

TEST(Observation, WrittenAndReadBackAndAChangedSeriesFileIsRefused) {
  Observation obs = ObserveTrajectories(Corridor(8, 3, 0.0), CorridorSpec());
  const auto file = ScratchFile("obs.json");
  WriteObservation(obs, file);
  const Observation back = ReadObservation(file);
  ASSERT_EQ(back.series.size(), obs.series.size());
  EXPECT_EQ(back.bins, obs.bins);
  for (std::size_t s = 0; s < obs.series.size(); ++s)
    for (std::size_t k = 0; k < obs.bins; ++k) {
      const SeriesPoint &a = obs.series[s].points[k], &b = back.series[s].points[k];
      if (std::isnan(a.value)) {
        EXPECT_TRUE(std::isnan(b.value));
        continue;
      }
      EXPECT_NEAR(a.value, b.value, 1e-8 * (1 + std::abs(a.value)));
      EXPECT_NEAR(a.uncertainty, b.uncertainty, 1e-8 * (1 + std::abs(a.uncertainty)));
    }
  ASSERT_EQ(back.events.size(), obs.events.size());
  EXPECT_EQ(back.events[0].censored, obs.events[0].censored);
  EXPECT_TRUE(std::isnan(back.events[0].end_s));
  // A changed CSV: refused, naming both files.
  std::ofstream(ObservationCsvPath(file), std::ios::app) << "0.2,speed,all,forward,m/s,1,0,1\n";
  const std::string error = ErrorOf([&] { ReadObservation(file); });
  EXPECT_NE(error.find("SHA-256"), std::string::npos) << error;
  EXPECT_NE(error.find("obs.csv"), std::string::npos) << error;
}

// Issue 40: an observation whose files contradict each other or hold values
// no observation has is refused, naming the file and line (before: observe
// compare took them all).
TEST(Observation, AFileThatContradictsItselfIsRefused) {
  const Observation obs = ObserveTrajectories(Corridor(8, 3, 0.0), CorridorSpec());
  const auto file = ScratchFile("contradicts.json");
  const auto csv = ObservationCsvPath(file);
  // Writes the observation, changes its JSON and its CSV (the CSV's
  // checksum made to match, as a careful forger would), and returns the
  // reader's error.
  const auto refused = [&](const std::function<void(nlohmann::json&)>& change_json,
                           const std::function<void(std::vector<std::string>&)>& change_csv) {
    WriteObservation(obs, file);
    std::ifstream in(csv);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    in.close();
    change_csv(lines);
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    std::ofstream(csv, std::ios::trunc) << text;
    std::ifstream j(file);
    nlohmann::json json = nlohmann::json::parse(j);
    j.close();
    json["series_file"]["sha256"] = Sha256Hex(text);
    change_json(json);
    std::ofstream(file, std::ios::trunc) << json.dump(1);
    return ErrorOf([&] { ReadObservation(file); });
  };
  const auto no_json = [](nlohmann::json&) {};
  const auto no_csv = [](std::vector<std::string>&) {};
  // The first row with a value, and one of its fields replaced.
  const auto with_field = [](std::size_t field, const std::string& value) {
    return [field, value](std::vector<std::string>& lines) {
      for (std::size_t r = 1; r < lines.size(); ++r) {
        std::vector<std::string> f;
        std::stringstream ss(lines[r]);
        for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
        if (f.size() != 8 || f[5].empty()) continue;
        f[field] = value;
        std::string joined;
        for (std::size_t i = 0; i < f.size(); ++i) joined += (i ? "," : "") + f[i];
        lines[r] = joined;
        return;
      }
    };
  };
  EXPECT_EQ(refused(no_json, no_csv), "") << "the unchanged files are read";
  const std::string bins = refused([](nlohmann::json& j) { j["time"]["bin_s"] = j["time"]["bin_s"].get<double>() * 1.5; }, no_csv);
  EXPECT_TRUE(bins.find("is not the centre of a bin") != std::string::npos || bins.find("is outside the") != std::string::npos)
      << bins;
  EXPECT_NE(refused(no_json, [](std::vector<std::string>& l) { l.resize(1); }).find("no rows of series"), std::string::npos);
  EXPECT_NE(refused(no_json, with_field(5, "1e300")).find("value 1e300 is beyond 1000000 in magnitude"), std::string::npos);
  EXPECT_NE(refused(no_json, with_field(6, "-1")).find("uncertainty -1; expected a number in [0, 1000000]"), std::string::npos);
  EXPECT_NE(refused(no_json, with_field(4, "km/h")).find("unit \"km/h\" for"), std::string::npos);
  EXPECT_NE(refused([](nlohmann::json& j) { j["series"][0]["unit"] = "km/h"; }, no_csv).find("expected \"m/s\""),
            std::string::npos);
  EXPECT_NE(refused(no_json, [](std::vector<std::string>& l) { l.push_back(l[1]); }).find("a second time"),
            std::string::npos);
  ASSERT_FALSE(obs.events.empty());
  const std::string ends = refused(
      [](nlohmann::json& j) { j["events"][0]["end_s"] = j["events"][0]["time_s"].get<double>() - 1.0; }, no_csv);
  EXPECT_NE(ends.find("before it begins"), std::string::npos) << ends;
}

// Issue 40: a region named with a comma, quotes or letters beyond ASCII is
// written as RFC 4180 CSV and read back (before: an unquoted CSV that the
// tools then refused).
TEST(Observation, ARegionNamedWithCommasAndQuotesIsReadBack) {
  ObservationSpec spec = CorridorSpec();
  spec.regions.front().name = "exit end, \"north\" — Zürich";
  const Observation obs = ObserveTrajectories(Corridor(8, 3, 0.0), spec);
  const auto file = ScratchFile("quoted.json");
  WriteObservation(obs, file);
  const Observation back = ReadObservation(file);
  const Series* speed = back.Find("speed", "exit end, \"north\" — Zürich", "forward");
  ASSERT_NE(speed, nullptr);
  const Series* original = obs.Find("speed", "exit end, \"north\" — Zürich", "forward");
  for (std::size_t k = 0; k < obs.bins; ++k) {
    if (!std::isnan(original->points[k].value)) {
      EXPECT_NEAR(speed->points[k].value, original->points[k].value, 1e-8);
    }
  }
}

TEST(Csv, FieldsAreQuotedWhereTheyMustBeAndReadBack) {
  EXPECT_EQ(CsvField("plain"), "plain");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  const std::string text = "h1,h2,h3\r\n" + CsvField("a,b") + "," + CsvField("two\nlines") + ",\n\nx," +
                           CsvField("q\"") + ",z\n";
  const std::vector<CsvRecord> r = ParseCsv(text, "t.csv");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1].line, 2u);
  EXPECT_EQ(r[1].fields, (std::vector<std::string>{"a,b", "two\nlines", ""}));
  EXPECT_EQ(r[2].line, 5u);
  EXPECT_EQ(r[2].fields, (std::vector<std::string>{"x", "q\"", "z"}));
  EXPECT_NE(ErrorOf([] { ParseCsv("a,\"open\n", "t.csv"); }).find("t.csv:1: a quoted field is never closed"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseCsv("a,b\"c\n", "t.csv"); }).find("t.csv:1: a double quote inside an unquoted field"),
            std::string::npos);
}

TEST(ObservationSpec, BadSpecsAreRefusedWithTheirJsonPath) {
  const auto error = [](const std::string& text) { return ErrorOf([&] { ParseObservationSpec(text, "s.json"); }); };
  const std::string head = R"({"format": "crowdrecon-observation-spec", "version": 1, )";
  EXPECT_NE(error(head + R"("regions": []})").find("s.json: /regions"), std::string::npos);
  EXPECT_NE(error(head + R"("regions": [{"name": "a", "polygon": [[0,0],[1,1],[2,2]]}]})").find("/regions/0/polygon"),
            std::string::npos);
  EXPECT_NE(error(head + R"("regions": [{"name": "a", "polygon": [[0,0],[1,0],[1,1]]}], "bin": 1})").find("bin"),
            std::string::npos);
  EXPECT_NE(error(head + R"("axis": [0, 0], "regions": [{"name": "a", "polygon": [[0,0],[1,0],[1,1]]}]})").find("/axis"),
            std::string::npos);
  EXPECT_NE(error(head + R"("regions": [{"name": "a", "polygon": [[0,0],[1,0],[1,1]]}], "bin_s": 0})").find("/bin_s"),
            std::string::npos);
  EXPECT_NE(error(head + R"("regions": [{"name": "a", "polygon": [[0,0],[1,0],[1,1]]}], "lines": [{"name": "a", "a": [0,0], "b": [1,0]}]})")
                .find("a name no other region or line has"),
            std::string::npos);
  const ObservationSpec ok = ParseObservationSpec(head + R"("axis": [0, -2], "regions": [{"name": "a", "polygon": [[0,0],[1,0],[1,1]]}]})", "s.json");
  EXPECT_NEAR(ok.axis.y, -1.0, 1e-15);
  EXPECT_NEAR(ok.regions[0].Area_m2(), 0.5, 1e-15);
}

// A JuPedSim file of the given version with two people over three frames.
void WriteJuPedSim(const std::filesystem::path& file, int version, bool with_fps = true, bool real_frames = false) {
  std::filesystem::remove(file);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  std::string sql = "CREATE TABLE metadata(key TEXT PRIMARY KEY, value TEXT);"
                    "INSERT INTO metadata VALUES('version', '" + std::to_string(version) + "');";
  if (with_fps) sql += "INSERT INTO metadata VALUES('fps', '8');";
  sql += version == 2 ? "CREATE TABLE trajectory_data(frame INTEGER, id INTEGER, pos_x REAL, pos_y REAL, ori_x REAL, ori_y REAL);"
                      : "CREATE TABLE trajectory_data(frame INTEGER, id INTEGER, pos_x REAL, pos_y REAL);";
  sql += version == 1 ? "CREATE TABLE geometry(wkt TEXT); INSERT INTO geometry VALUES('POLYGON ((0 0, 4 0, 4 2, 0 2, 0 0))');"
                      : "CREATE TABLE geometry(hash INTEGER, wkt TEXT); INSERT INTO geometry VALUES(1, 'POLYGON ((0 0, 4 0, 4 2, 0 2, 0 0))');";
  for (int f = 0; f < 3; ++f)
    for (int id = 1; id <= 2; ++id) {
      const std::string frame = real_frames ? std::to_string(f) + ".0" : std::to_string(f);
      sql += "INSERT INTO trajectory_data VALUES(" + frame + ", " + std::to_string(id) + ", " + std::to_string(0.5 * f) +
             ", " + std::to_string(id) + (version == 2 ? ", 1, 0" : "") + ");";
    }
  char* message = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message), SQLITE_OK) << (message ? message : "");
  sqlite3_close(db);
}

TEST(JuPedSim, VersionsOneToThreeAreRead) {
  for (int version : {1, 2, 3}) {
    const auto file = ScratchFile("v" + std::to_string(version) + ".sqlite");
    WriteJuPedSim(file, version, true, version == 3);
    const Trajectories t = ReadTrajectories(file);
    EXPECT_EQ(t.format, "jupedsim-v" + std::to_string(version));
    EXPECT_EQ(t.fps, 8.0);
    EXPECT_EQ(t.people, 2u);
    EXPECT_EQ(t.points.size(), 6u);
    EXPECT_EQ(t.last_frame, 2);
    EXPECT_NE(t.walkable_wkt.find("POLYGON"), std::string::npos);
    Vec2 v;
    ASSERT_TRUE(VelocityAt(TracksOf(t)[0], 1, 1, t.fps, t.box, &v));
    EXPECT_NEAR(v.x, 4.0, 1e-12);  // 0.5 m per frame at 8 fps
  }
}

TEST(JuPedSim, BadFilesAreRefusedByName) {
  const auto file = ScratchFile("bad.sqlite");
  WriteJuPedSim(file, 7);
  EXPECT_NE(ErrorOf([&] { ReadTrajectories(file); }).find("metadata version \"7\""), std::string::npos);
  WriteJuPedSim(file, 2, false);
  EXPECT_NE(ErrorOf([&] { ReadTrajectories(file); }).find("no fps"), std::string::npos);
  EXPECT_EQ(ReadTrajectories(file, 10.0).fps, 10.0);
  // Not a database: read as PeTrack text, which says what it expected.
  const auto text = ScratchFile("x.sqlite");
  std::ofstream(text) << "SQLite format 3\0garbage";
  EXPECT_NE(ErrorOf([&] { ReadTrajectories(text); }).find("x.sqlite"), std::string::npos);
  sqlite3* db = nullptr;
  const auto empty = ScratchFile("empty.sqlite");
  std::filesystem::remove(empty);
  sqlite3_open(empty.c_str(), &db);
  sqlite3_exec(db, "CREATE TABLE other(a);", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  EXPECT_NE(ErrorOf([&] { ReadTrajectories(empty); }).find("no table trajectory_data"), std::string::npos);
}

TEST(FundamentalDiagram, WeidmannsRelationAndAUniformCrowd) {
  const WeidmannRelation w;
  EXPECT_NEAR(w.SpeedAt(1.0), 1.34 * (1 - std::exp(-1.913 * (1 - 1 / 5.4))), 1e-12);
  EXPECT_EQ(w.SpeedAt(5.4), 0.0);
  EXPECT_EQ(w.SpeedAt(8.0), 0.0);
  EXPECT_NEAR(w.SpeedAt(1e-6), 1.34, 1e-9);
  // Eleven people always in the corridor (periodic), at 1.2 and 0.8 m/s.
  PeriodicBox box;
  box.x = true;
  box.max_m = {10, 4};
  const FundamentalDiagram fd =
      ComputeFundamentalDiagram(Corridor(8, 3, 0.8, box), {"all", {{0, 0}, {10, 0}, {10, 4}, {0, 4}}}, 0.2, 5);
  ASSERT_EQ(fd.points.size(), 40u);
  for (const FundamentalDiagramPoint& p : fd.points) {
    EXPECT_NEAR(p.density_per_m2, 11.0 / 40.0, 1e-12);
    EXPECT_NEAR(p.speed_m_per_s, (8 * 1.2 + 3 * 0.8) / 11.0, 1e-9);
  }
  ASSERT_EQ(fd.classes.size(), 1u);
  EXPECT_EQ(fd.classes[0].frames, 40u);
}

}  // namespace
}  // namespace crowdrecon::observe
