// The run file's frame writing: on a thread of its own (FrameWriterThread)
// the same file as writing each frame in turn, a failure of the writing
// thread reaches the caller; the write-ahead log while the run is written.
#include <gtest/gtest.h>

#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "crowdrecon/scenario/run_file.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::scenario {
namespace {

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
  RunFileWriter writer = RunFileWriter::Create(file, Header(sim), sim);
  if (how != Writing::kDirect) {
    FrameWriterThread frames(writer, /*background=*/how == Writing::kOnThread, 2);
    for (int k = 0; k <= 20; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      frames.Write(k, sim, {}, /*with_contacts=*/true);
    }
    frames.Flush();
  } else {
    for (int k = 0; k <= 20; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      writer.WriteFrame(k, sim, {}, /*with_contacts=*/true);
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
  RunFileWriter writer = RunFileWriter::Create(file, Header(sim), sim);
  FrameWriterThread frames(writer, /*background=*/true, 2);
  frames.Write(0, sim, {}, true);
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
    for (int k = 1; k <= 5; ++k) frames.Write(k, sim, {}, true);
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
    RunFileWriter writer = RunFileWriter::Create(file, Header(sim), sim);
    for (int k = 0; k <= 3; ++k) {
      if (k > 0) sim.AdvanceTo(k / 10.0);
      writer.WriteFrame(k, sim, {}, true);
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

}  // namespace
}  // namespace crowdrecon::scenario
