// Packed frames (issue 66; runfile/src/frame_pack.hpp): the same frames
// written with tables and packed read back bit for bit the same through every
// reader (frames in order and at random, loads, digest, group sums), also
// across key frames, after a resume, with people who come and go and with
// awkward values; a damaged or missing frame is an error naming it, never
// numbers predicted from the wrong frame.
#include <gtest/gtest.h>

#include <sqlite3.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::runfile {
namespace {

constexpr std::uint32_t kPeople = 30;

RunSetup Setup() {
  RunSetup setup;
  setup.shapes = {{0.05, {{0.1, 0.0}, {-0.1, 0.0}}}};
  for (std::uint32_t i = 0; i < kPeople; ++i) setup.people.push_back({0, 70.0, 2.0, 1.3, i % 3, "exit"});
  return setup;
}

// Frame k of a made-up run: people come and go, are listed in no particular
// order, walk, turn and are loaded; among the values -0, a subnormal, exact
// zeros and positions near the readers' bound; every third frame without
// chest loads.
FrameSnapshot MadeUpFrame(std::int64_t k) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(k) * 7919u + 3u);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  FrameSnapshot f;
  f.frame = k;
  f.time_s = 0.5 * static_cast<double>(k);
  for (std::uint32_t i = 0; i < kPeople; ++i)
    if ((i + static_cast<std::uint32_t>(k)) % 7 != 0 || i % 2 == 0) f.person.push_back(i);
  std::shuffle(f.person.begin(), f.person.end(), rng);
  const bool loads = k % 3 != 0;
  const double t = static_cast<double>(k);
  for (const std::uint32_t i : f.person) {
    const double s = static_cast<double>(i);
    f.position_m.push_back({s + 0.013 * t + 1e-3 * u(rng), i == 5 ? 1.9e7 - t : 0.5 * s - 0.007 * t});
    f.velocity_m_per_s.push_back({i == 1 ? -0.0 : 1.3 + 0.1 * u(rng), i == 2 ? 4.9e-324 : 0.2 * u(rng)});
    f.angle_rad.push_back(i == 3 ? 0.0 : 0.1 * s + 0.01 * t + 1e-4 * u(rng));
    f.angular_velocity_rad_per_s.push_back(i == 4 ? -0.0 : u(rng));
    f.state.push_back(i == 6 && k > 40 ? PersonStatus::kFallen : PersonStatus::kWalking);
    f.load_n.push_back(i % 4 == 0 ? 0.0 : 300.0 + 200.0 * u(rng));
    if (loads) {
      f.chest_load_n.push_back(i % 5 == 0 ? 0.0 : 400.0 + 300.0 * u(rng));
      f.lateral_load_n.push_back(i % 5 <= 1 ? 0.0 : 50.0 * (1.0 + u(rng)));  // 1: chest only
    }
  }
  if (k == 10) f.events.push_back({f.time_s, "fall", 6, -1, "made up"});
  return f;
}

std::filesystem::path Write(const std::string& name, bool packed, std::int64_t frames) {
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / name;
  RunHeader header;
  header.scenario_json = "{}";
  header.walkable_wkt = "POLYGON ((0 0, 40 0, 40 40, 0 40, 0 0))";
  header.output_fps = 2.0;
  header.packed = packed;
  RunFileWriter writer = RunFileWriter::Create(file, header, Setup());
  for (std::int64_t k = 0; k < frames; ++k) writer.WriteFrame(MadeUpFrame(k));
  writer.SetStatus("complete");
  return file;
}

bool Same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool Same(Vec2 a, Vec2 b) { return Same(a.x, b.x) && Same(a.y, b.y); }

void ExpectSamePersonFrames(const RunFileReader& a, const RunFileReader& b) {
  PersonFrameStream sa = a.PersonFrames(run_limits::kFrame), sb = b.PersonFrames(run_limits::kFrame);
  PersonFrame fa, fb;
  std::int64_t frames = 0;
  while (sa.Next(&fa)) {
    ASSERT_TRUE(sb.Next(&fb));
    ASSERT_EQ(fa.frame, fb.frame);
    ASSERT_EQ(fa.person, fb.person) << "frame " << fa.frame;
    for (std::size_t k = 0; k < fa.person.size(); ++k) {
      SCOPED_TRACE("frame " + std::to_string(fa.frame) + ", person " + std::to_string(fa.person[k]));
      EXPECT_TRUE(Same(fa.position_m[k], fb.position_m[k]));
      EXPECT_TRUE(Same(fa.velocity_m_per_s[k], fb.velocity_m_per_s[k]));
      EXPECT_TRUE(Same(fa.angle_rad[k], fb.angle_rad[k]));
      EXPECT_TRUE(Same(fa.angular_velocity_rad_per_s[k], fb.angular_velocity_rad_per_s[k]));
      EXPECT_EQ(fa.state[k], fb.state[k]);
      EXPECT_TRUE(Same(fa.load_n[k], fb.load_n[k]));
    }
    ++frames;
  }
  EXPECT_FALSE(sb.Next(&fb));
  EXPECT_GT(frames, 0);
}

void ExpectSameLoads(const RunFileReader& a, const RunFileReader& b) {
  PersonLoadStream la = a.PersonLoads(run_limits::kFrame), lb = b.PersonLoads(run_limits::kFrame);
  std::int64_t fa = 0, fb = 0;
  std::vector<PersonLoad> ra, rb;
  std::int64_t frames = 0;
  while (la.Next(&fa, &ra)) {
    ASSERT_TRUE(lb.Next(&fb, &rb));
    ASSERT_EQ(fa, fb);
    ASSERT_EQ(ra.size(), rb.size()) << "frame " << fa;
    for (std::size_t k = 0; k < ra.size(); ++k) {
      EXPECT_EQ(ra[k].person, rb[k].person);
      EXPECT_TRUE(Same(ra[k].chest_n, rb[k].chest_n));
      EXPECT_TRUE(Same(ra[k].lateral_n, rb[k].lateral_n));
    }
    ++frames;
  }
  EXPECT_FALSE(lb.Next(&fb, &rb));
  EXPECT_GT(frames, 0);
}

void ExpectSameFrame(const RunFileReader& a, const RunFileReader& b, std::int64_t frame) {
  SCOPED_TRACE("Frame(" + std::to_string(frame) + ")");
  const RunFrame fa = a.Frame(frame), fb = b.Frame(frame);
  ASSERT_EQ(fa.ids, fb.ids);
  EXPECT_TRUE(Same(fa.time_s, fb.time_s));
  for (std::size_t k = 0; k < fa.ids.size(); ++k) {
    EXPECT_TRUE(Same(fa.position_m[k], fb.position_m[k]));
    EXPECT_TRUE(Same(fa.orientation[k], fb.orientation[k]));
  }
}

TEST(PackedFrames, ReadBackAsTheTablesBitForBit) {
  constexpr std::int64_t kFrames = 150;  // three key frames (0, 64, 128)
  const RunFileReader tables(Write("pack-tables.sqlite", false, kFrames));
  const RunFileReader packed(Write("pack-packed.sqlite", true, kFrames));
  EXPECT_FALSE(tables.packed());
  EXPECT_TRUE(packed.packed());
  EXPECT_EQ(tables.TablesDigest(), packed.TablesDigest());
  ExpectSamePersonFrames(tables, packed);
  ExpectSameLoads(tables, packed);
  const std::vector<Vec2> sa = tables.GroupVelocitySums(), sb = packed.GroupVelocitySums();
  ASSERT_EQ(sa.size(), 3u);
  ASSERT_EQ(sa.size(), sb.size());
  for (std::size_t g = 0; g < sa.size(); ++g) EXPECT_TRUE(Same(sa[g], sb[g])) << "group " << g;
  // At random, forwards, backwards, across key frames and the same twice.
  std::vector<std::int64_t> order;
  for (std::int64_t k = 0; k < kFrames; ++k) order.push_back(k);
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  for (const std::int64_t k : {std::int64_t{0}, std::int64_t{63}, std::int64_t{64}, std::int64_t{65},
                               std::int64_t{149}, std::int64_t{149}, std::int64_t{2}})
    order.push_back(k);
  for (const std::int64_t k : order) ExpectSameFrame(tables, packed, k);
  // -0 is read as SQLite gives it back: 0.
  PersonFrameStream s = packed.PersonFrames(0);
  PersonFrame f;
  ASSERT_TRUE(s.Next(&f));
  const auto one = std::find(f.person.begin(), f.person.end(), 1u) - f.person.begin();
  EXPECT_FALSE(std::signbit(f.velocity_m_per_s[static_cast<std::size_t>(one)].x));
}

TEST(PackedFrames, AResumedRunIsTheRunWrittenInOneGo) {
  const std::filesystem::path whole = Write("pack-whole.sqlite", true, 140);
  const std::filesystem::path file = Write("pack-resumed.sqlite", true, 100);
  {
    RunFileWriter writer = RunFileWriter::Resume(file, 70);  // frames 71..99 dropped and written again
    for (std::int64_t k = 71; k < 140; ++k) writer.WriteFrame(MadeUpFrame(k));
    writer.SetStatus("complete");
  }
  const RunFileReader a(whole), b(file);
  EXPECT_EQ(a.TablesDigest(), b.TablesDigest());
  ExpectSamePersonFrames(a, b);
  for (const std::int64_t k : {70, 71, 72, 100, 139}) ExpectSameFrame(a, b, k);
}

// Runs SQL on a run file (as damage from outside would).
void Damage(const std::filesystem::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// Changes byte `at` of frame `frame`'s packed bytes to `value`.
void SetByte(const std::filesystem::path& file, std::int64_t frame, int at, unsigned char value) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  sqlite3_stmt* get = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT data FROM frame_pack WHERE frame = ?", -1, &get, nullptr), SQLITE_OK);
  sqlite3_bind_int64(get, 1, frame);
  ASSERT_EQ(sqlite3_step(get), SQLITE_ROW);
  const auto* bytes = static_cast<const unsigned char*>(sqlite3_column_blob(get, 0));
  std::vector<unsigned char> data(bytes, bytes + sqlite3_column_bytes(get, 0));
  sqlite3_finalize(get);
  ASSERT_LT(static_cast<std::size_t>(at), data.size());
  ASSERT_NE(data[static_cast<std::size_t>(at)], value);
  data[static_cast<std::size_t>(at)] = value;
  sqlite3_stmt* put = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE frame_pack SET data = ? WHERE frame = ?", -1, &put, nullptr), SQLITE_OK);
  sqlite3_bind_blob(put, 1, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
  sqlite3_bind_int64(put, 2, frame);
  EXPECT_EQ(sqlite3_step(put), SQLITE_DONE);
  sqlite3_finalize(put);
  sqlite3_close(db);
}

std::string ReadingError(const std::filesystem::path& file) {
  try {
    const RunFileReader run(file);
    PersonFrameStream s = run.PersonFrames(run_limits::kFrame);
    PersonFrame f;
    while (s.Next(&f)) {
    }
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PackedFrames, ADamagedOrMissingFrameIsAnErrorNamingIt) {
  struct Case {
    const char* name;
    std::string sql;  // or, when empty, byte `at` of frame `frame` set to `value`
    std::vector<std::string> said;
    std::int64_t frame = 0;
    int at = 0;
    unsigned char value = 0;
  };
  const std::vector<Case> cases = {
      {"byte", "", {"frame_pack", "frame 5", "do not decompress", "damaged"}, 5, 30, 0x5a},
      {"version", "", {"frame 1", "version 9"}, 1, 1, 9},
      {"flags", "", {"frame 66", "unknown flags"}, 66, 2, 0x40},
      {"cut", "UPDATE frame_pack SET data = substr(data, 1, length(data) - 3) WHERE frame = 7", {"frame_pack", "frame 7"}},
      {"not-a-pack", "UPDATE frame_pack SET data = x'00010203' WHERE frame = 3", {"frame 3", "not a packed frame"}},
      {"missing", "DELETE FROM frame_pack WHERE frame = 20", {"frame 21", "continues frame 20", "missing"}},
      {"missing-key", "DELETE FROM frame_pack WHERE frame = 64", {"frame 65", "continues frame 64"}},
      {"text", "UPDATE frame_pack SET data = 'text' WHERE frame = 2", {"frame 2", "not a blob"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::filesystem::path file = Write(std::string("pack-damaged-") + c.name + ".sqlite", true, 80);
    if (c.sql.empty()) SetByte(file, c.frame, c.at, c.value);
    else Damage(file, c.sql);
    const std::string message = ReadingError(file);
    ASSERT_FALSE(message.empty());
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    for (const std::string& s : c.said) EXPECT_NE(message.find(s), std::string::npos) << message;
  }
  // A frame asked for alone after its key frame was removed.
  const std::filesystem::path file = Write("pack-no-key.sqlite", true, 10);
  Damage(file, "DELETE FROM frame_pack WHERE frame = 0");
  try {
    (void)RunFileReader(file).Frame(4);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no key frame at or before frame 4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace crowdrecon::runfile
