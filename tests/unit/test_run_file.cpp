// The run file's frame writing: on a thread of its own (FrameWriterThread)
// the same file as writing each frame in turn, a failure of the writing
// thread reaches the caller; the write-ahead log while the run is written.
#include <gtest/gtest.h>

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::scenario {
namespace {

using runfile::FrameSnapshot;
using runfile::FrameWriterThread;
using runfile::RunFileWriter;
using runfile::RunHeader;

// Every row of the frame tables, in a fixed order, as text.
std::string DumpFrames(const std::filesystem::path& file) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  std::string out;
  for (const char* sql : {"SELECT * FROM trajectory_data ORDER BY frame, id", "SELECT * FROM person_state ORDER BY frame, id",
                          "SELECT * FROM contact ORDER BY rowid", "SELECT * FROM frame_time ORDER BY frame",
                          "SELECT * FROM frame_data ORDER BY frame", "SELECT * FROM metadata ORDER BY key"}) {
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr), SQLITE_OK) << sql;
    while (sqlite3_step(stmt) == SQLITE_ROW) {
      for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
        const unsigned char* text = sqlite3_column_text(stmt, c);
        out += text ? reinterpret_cast<const char*>(text) : "NULL";
        out += c + 1 < sqlite3_column_count(stmt) ? "," : "\n";
      }
    }
    sqlite3_finalize(stmt);
  }
  sqlite3_close(db);
  return out;
}

RunHeader Header(const engine::Simulation& sim) {
  RunHeader header;
  header.scenario_json = "{\"test\": \"random gas\"}";
  header.scenario_origin = "tests/unit/test_run_file.cpp";
  header.walkable_wkt = "POLYGON ((0 0, 4 0, 4 4, 0 4, 0 0))";
  header.output_fps = 10.0;
  header.time_step_s = sim.time_step_s();
  return header;
}

// 64 bodies colliding in a periodic box: frames with contacts.
enum class Writing { kDirect, kOnThread, kInTurn };

std::filesystem::path WriteGas(const std::string& name, Writing how) {
  engine::Simulation sim(engine::testing::RandomGas(8, 0.5, 7, true));
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / name;
  RunFileWriter writer = CreateRunFile(file, Header(sim), sim, {});
  if (how != Writing::kDirect) {
    FrameWriterThread frames(writer, /*background=*/how == Writing::kOnThread, 2);
    for (int k = 0; k <= 20; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      frames.Write([&](FrameSnapshot& f) { TakeSnapshot(sim, k, {}, /*with_contacts=*/true, &f); });
    }
    frames.Flush();
  } else {
    for (int k = 0; k <= 20; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      WriteFrame(writer, sim, k, {}, /*with_contacts=*/true);
    }
  }
  writer.SetStatus("complete");
  return file;
}

TEST(FrameWriterThread, WritesExactlyWhatDirectWritesDo) {
  const std::string direct = DumpFrames(WriteGas("gas-direct.sqlite", Writing::kDirect));
  const std::string threaded = DumpFrames(WriteGas("gas-thread.sqlite", Writing::kOnThread));
  const std::string in_turn = DumpFrames(WriteGas("gas-in-turn.sqlite", Writing::kInTurn));
  EXPECT_NE(direct.find("\n20,"), std::string::npos);  // every frame is there
  EXPECT_GT(std::count(direct.begin(), direct.end(), '\n'), 21 * 64 * 2 + 21);  // and contacts
  EXPECT_EQ(direct, threaded);
  EXPECT_EQ(direct, in_turn);
}

TEST(FrameWriterThread, AFailureOfTheWritingThreadReachesTheCaller) {
  engine::Simulation sim(engine::testing::RandomGas(4, 0.5, 3, true));
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "gas-fail.sqlite";
  RunFileWriter writer = CreateRunFile(file, Header(sim), sim, {});
  FrameWriterThread frames(writer, /*background=*/true, 2);
  const auto frame_of = [&](std::int64_t k) {
    return [&sim, k](FrameSnapshot& f) { TakeSnapshot(sim, k, {}, true, &f); };
  };
  frames.Write(frame_of(0));
  frames.Flush();
  {
    // Another connection drops a table the frames go to.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "DROP TABLE person_state", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
  }
  std::string message;
  try {
    for (int k = 1; k <= 5; ++k) frames.Write(frame_of(k));
    frames.Flush();
  } catch (const std::exception& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("gas-fail.sqlite"), std::string::npos) << message;
  EXPECT_NE(message.find("person_state"), std::string::npos) << message;
}

// While a run is written its file is in write-ahead-log mode: committed frames
// are readable by another (read-only) connection at once; closing the writer
// leaves one plain file in rollback-journal mode, without -wal or -shm.
TEST(RunFileWriter, FramesAreReadableWhileWrittenAndTheFileIsPlainWhenClosed) {
  engine::Simulation sim(engine::testing::RandomGas(4, 0.5, 5, true));
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "gas-wal.sqlite";
  const auto query = [&](const char* sql) {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    std::string value;
    if (sqlite3_step(stmt) == SQLITE_ROW) value = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    return value;
  };
  {
    RunFileWriter writer = CreateRunFile(file, Header(sim), sim, {});
    for (int k = 0; k <= 3; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      WriteFrame(writer, sim, k, {}, true);
    }
    EXPECT_EQ(query("PRAGMA journal_mode"), "wal");
    EXPECT_EQ(query("SELECT COUNT(*) FROM frame_time"), "4");
    EXPECT_TRUE(std::filesystem::exists(file.string() + "-wal"));
    writer.SetStatus("complete");
  }
  EXPECT_EQ(query("PRAGMA journal_mode"), "delete");
  EXPECT_EQ(query("SELECT COUNT(*) FROM trajectory_data"), std::to_string(4 * 16));
  EXPECT_FALSE(std::filesystem::exists(file.string() + "-wal"));
  EXPECT_FALSE(std::filesystem::exists(file.string() + "-shm"));
}

// The reader gives back what the writer stored: people, frames with every
// person's state, events, the venue; and it needs no engine (the records here
// are written without a simulation).
TEST(RunFileReader, GivesBackEveryTableTheWriterFilled) {
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "records.sqlite";
  RunHeader header;
  header.scenario_json = "{}";
  header.venue_json = "{\"version\": 1}";
  header.walkable_wkt = "POLYGON ((0 0, 4 0, 4 4, 0 4, 0 0))";
  header.periodic_box = {true, false, {0.0, 0.0}, {4.0, 0.0}};
  runfile::RunSetup setup;
  setup.shapes = {{0.05, {{0.1, 0.0}, {-0.1, 0.0}}}};
  setup.people = {{0, 80.0, 2.5, 1.3, 0, "east"}, {0, 70.0, 2.0, 1.1, 1, "west"}};
  {
    RunFileWriter writer = RunFileWriter::Create(file, header, setup);
    for (std::int64_t k = 0; k < 3; ++k) {
      FrameSnapshot f;
      f.frame = k;
      f.time_s = 0.1 * static_cast<double>(k);
      f.person = {0, 1};
      f.position_m = {{1.0 + 0.1 * static_cast<double>(k), 1.0}, {3.0, 2.0}};
      f.velocity_m_per_s = {{1.0, 0.0}, {-0.5, 0.25}};
      f.angle_rad = {0.0, 3.0};
      f.angular_velocity_rad_per_s = {0.0, -0.5};
      f.state = {runfile::PersonStatus::kWalking, k == 2 ? runfile::PersonStatus::kFallen : runfile::PersonStatus::kWalking};
      f.load_n = {12.5, 410.0};
      if (k == 2) f.events.push_back({0.2, "fall", 1, -1, "pushed"});
      if (k == 1) {  // the first person leaves
        f.person = {1};
        f.position_m = {{3.0, 2.0}};
        f.velocity_m_per_s = {{-0.5, 0.25}};
        f.angle_rad = {3.0};
        f.angular_velocity_rad_per_s = {-0.5};
        f.state = {runfile::PersonStatus::kWalking};
        f.load_n = {410.0};
      }
      writer.WriteFrame(f);
    }
    writer.SetStatus("complete");
  }
  const runfile::RunFileReader run(file);
  EXPECT_EQ(run.venue_json(), "{\"version\": 1}");
  const PeriodicBox box = run.periodic_box();
  EXPECT_TRUE(box.x);
  EXPECT_FALSE(box.y);
  EXPECT_NEAR(box.MinimumImage({3.8, 0.5}).x, -0.2, 1e-12);
  const std::vector<runfile::Person> people = run.People();
  ASSERT_EQ(people.size(), 2u);
  EXPECT_EQ(people[1].group, 1u);
  EXPECT_EQ(people[1].target, "west");
  EXPECT_DOUBLE_EQ(people[0].mass_kg, 80.0);
  EXPECT_DOUBLE_EQ(people[1].desired_speed_m_per_s, 1.1);
  const std::vector<runfile::FrameTime> times = run.FrameTimes();
  ASSERT_EQ(times.size(), 3u);
  EXPECT_DOUBLE_EQ(times[2].time_s, 0.2);
  runfile::PersonFrameStream stream = run.PersonFrames(1);  // frames 0 and 1 only
  runfile::PersonFrame rows;
  ASSERT_TRUE(stream.Next(&rows));
  EXPECT_EQ(rows.frame, 0);
  EXPECT_EQ(rows.person, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_DOUBLE_EQ(rows.load_n[1], 410.0);
  EXPECT_DOUBLE_EQ(rows.velocity_m_per_s[1].y, 0.25);
  ASSERT_TRUE(stream.Next(&rows));
  EXPECT_EQ(rows.frame, 1);
  EXPECT_EQ(rows.person, (std::vector<std::uint32_t>{1}));
  EXPECT_FALSE(stream.Next(&rows));
  runfile::PersonFrameStream all = run.PersonFrames(2);
  while (all.Next(&rows)) {
  }
  EXPECT_EQ(rows.state[1], runfile::PersonStatus::kFallen);
  const std::vector<runfile::Event> events = run.Events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, "fall");
  EXPECT_EQ(events[0].person, 1);
  EXPECT_EQ(events[0].other, -1);
  const std::vector<Vec2> sums = run.GroupVelocitySums();
  ASSERT_EQ(sums.size(), 2u);
  EXPECT_DOUBLE_EQ(sums[0].x, 2.0);  // person 0 in frames 0 and 2
  EXPECT_DOUBLE_EQ(sums[1].x, -1.5);
}

// Issue 66: the largest overlap from the frames' briefs (table
// contact_summary, written every frame) is the contact the scan of every
// contact row finds (the largest, the earliest frame, the first row), each
// brief counts its frame's rows, and a run written without its contacts
// knows the same largest overlap.
TEST(RunFileReader, TheLargestOverlapFromTheFramesBriefsIsTheScansOne) {
  std::optional<runfile::RunFileReader::LargestOverlap> with, without;
  std::string counts, brief_counts;
  std::int64_t scan_frame = -1;
  double scan_overlap = 0.0;
  bool scan_wall = false;
  for (const bool contacts : {true, false}) {
    engine::Simulation sim(engine::testing::RandomGas(8, 0.5, 7, true));
    const std::filesystem::path file =
        std::filesystem::path(::testing::TempDir()) / (contacts ? "brief-with.sqlite" : "brief-without.sqlite");
    std::filesystem::remove(file);
    {
      RunFileWriter writer = CreateRunFile(file, Header(sim), sim, {});
      for (int k = 0; k <= 20; ++k) {
        if (k > 0) sim.AdvanceTo(k / 10.0);
        WriteFrame(writer, sim, k, {}, contacts);
      }
      writer.SetStatus("complete");
    }
    (contacts ? with : without) = runfile::RunFileReader(file).LargestContactOverlap();
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    auto rows = [&](const char* sql) {
      std::string out;
      sqlite3_stmt* stmt = nullptr;
      EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr), SQLITE_OK) << sql;
      while (sqlite3_step(stmt) == SQLITE_ROW)
        for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
          const unsigned char* text = sqlite3_column_text(stmt, c);
          out += text ? reinterpret_cast<const char*>(text) : "NULL";
          out += c + 1 < sqlite3_column_count(stmt) ? "," : "\n";
        }
      sqlite3_finalize(stmt);
      return out;
    };
    if (contacts) {
      sqlite3_stmt* stmt = nullptr;
      ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT frame, overlap_m, wall FROM contact ORDER BY overlap_m DESC, frame, rowid LIMIT 1",
                                   -1, &stmt, nullptr), SQLITE_OK);
      ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
      scan_frame = sqlite3_column_int64(stmt, 0);
      scan_overlap = sqlite3_column_double(stmt, 1);
      scan_wall = sqlite3_column_int(stmt, 2) != 0;
      sqlite3_finalize(stmt);
      counts = rows("SELECT frame, COUNT(*), SUM(wall) FROM contact GROUP BY frame ORDER BY frame");
      brief_counts = rows("SELECT frame, contacts, wall_contacts FROM contact_summary WHERE contacts > 0 ORDER BY frame");
    } else {
      EXPECT_EQ(rows("SELECT COUNT(*) FROM contact"), "0\n");  // the rows are not written, their brief is
    }
    sqlite3_close(db);
  }
  ASSERT_TRUE(with.has_value());
  ASSERT_TRUE(without.has_value());
  EXPECT_EQ(with->frame, scan_frame);
  EXPECT_EQ(with->overlap_m, scan_overlap);
  EXPECT_EQ(with->wall, scan_wall);
  EXPECT_GT(with->overlap_m, 0.0);
  EXPECT_EQ(counts, brief_counts);
  EXPECT_EQ(without->frame, with->frame);
  EXPECT_EQ(without->overlap_m, with->overlap_m);
  EXPECT_EQ(without->wall, with->wall);
}

// A damaged periodic box names the file, the table, the row and what was expected.
TEST(RunFileReader, ADamagedPeriodicBoxIsReported) {
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "box.sqlite";
  const auto error_of = [&](const std::string& value) {
    {
      RunHeader header;
      RunFileWriter writer = RunFileWriter::Create(file, header, {});
      writer.SetRunValue("periodic_box", value);
    }
    try {
      (void)runfile::RunFileReader(file).periodic_box();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("{\"x\": true}").find("box.sqlite: table run, row key periodic_box, column value: malformed"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"x": true, "y": false, "min_m": [5, 0], "max_m": [4, 0]})").find("expected max_m > min_m"),
            std::string::npos);
  EXPECT_EQ(error_of(""), "no error");
}

}  // namespace
}  // namespace crowdrecon::scenario
