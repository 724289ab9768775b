// PeTrack trajectory files (issue 22): the three Jülich files of
// ../shared/data read with their frame rates and units, and bad files refused
// with the file, the line and what was expected.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/observe/petrack.hpp"

namespace crowdrecon::observe {
namespace {

const std::filesystem::path kData = std::filesystem::path(CROWDRECON_SHARED_DIR) / "data";

TEST(PeTrack, TheJuelichFilesReadWithTheirRatesAndUnits) {
  if (!std::filesystem::exists(kData)) GTEST_SKIP() << "no ../shared/data here";
  const Trajectories bottleneck = ReadPeTrack(kData / "juelich-bottleneck" / "040_c_56_h-.txt");
  EXPECT_EQ(bottleneck.fps, 25.0);
  EXPECT_EQ(bottleneck.unit, "m");
  EXPECT_EQ(bottleneck.points.front().id, 1u);
  EXPECT_EQ(bottleneck.points.front().frame, 0);
  EXPECT_NEAR(bottleneck.points.front().position_m.x, 2.1569, 1e-12);
  EXPECT_NEAR(bottleneck.points.front().z_m, 1.76, 1e-12);
  EXPECT_TRUE(bottleneck.notes.empty());
  // Centimetres: converted to metres.
  const Trajectories bfr = ReadPeTrack(kData / "juelich-bfr" / "bi_corr_400_b_03.txt");
  EXPECT_EQ(bfr.unit, "cm");
  EXPECT_EQ(bfr.fps, 25.0);
  for (const TrajectoryPoint& p : bfr.points) ASSERT_LT(std::abs(p.position_m.x), 50.0);
  // No unit stated: metres, with a note; "# framerate: 25.00" without "fps".
  const Trajectories uni = ReadPeTrack(kData / "juelich-uni" / "traj_UNI_CORR_500_01.txt");
  EXPECT_EQ(uni.fps, 25.0);
  ASSERT_EQ(uni.notes.size(), 1u);
  EXPECT_NE(uni.notes[0].find("metres assumed"), std::string::npos);
  for (const Trajectories* t : {&bottleneck, &bfr, &uni}) {
    EXPECT_GT(t->people, 50u) << t->source;
    EXPECT_GT(t->last_frame, t->first_frame) << t->source;
  }
}

TEST(PeTrack, UnitsScaleAndTheRateCanBeGiven) {
  const Trajectories t = ParsePeTrack("# id frame x/mm y/mm z/mm\n3 10 1500 -250 1700\n3\t11\t1510\t-250\n", "a.txt", 16.0);
  EXPECT_EQ(t.fps, 16.0);
  ASSERT_EQ(t.points.size(), 2u);
  EXPECT_NEAR(t.points[0].position_m.x, 1.5, 1e-12);
  EXPECT_NEAR(t.points[0].position_m.y, -0.25, 1e-12);
  EXPECT_NEAR(t.points[0].z_m, 1.7, 1e-12);
  EXPECT_EQ(t.points[1].z_m, 0.0);
  EXPECT_EQ(t.people, 1u);
}

TEST(PeTrack, BadFilesNameTheLineAndWhatWasExpected) {
  const auto refuse = [](const std::string& text, const std::string& expected) {
    try {
      ParsePeTrack(text, "t.txt");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refuse("# framerate: 25 fps\n1 0 1.0\n", "t.txt:2: \"1 0 1.0\": 3 fields; expected id frame x y [z]");
  refuse("# framerate: 25 fps\n1 zero 1 2\n", "t.txt:2: frame \"zero\"; expected a whole number");
  refuse("# framerate: 25 fps\n-1 0 1 2\n", "t.txt:2: id \"-1\"; expected a whole number in [0, 10000000]");
  refuse("# framerate: 25 fps\n1 0 nan 2\n", "t.txt:2: x \"nan\"; expected a number");
  refuse("# framerate: 25 fps\n1 0 1 1e9\n", "t.txt:2: y \"1e9\"; expected a number within");
  refuse("# framerate: fast\n1 0 1 2\n", "t.txt:1: frame rate \"# framerate: fast\"");
  refuse("1 0 1 2\n", "t.txt: no frame rate");
  refuse("# framerate: 25 fps\n# nothing else\n", "t.txt: no trajectory lines");
  refuse(std::string("# framerate: 25 fps\n1 0 1") + '\0' + " 2\n", "t.txt:2: a NUL byte");
  EXPECT_THROW(ReadPeTrack("/nonexistent/x.txt"), InputError);
}

// Issue 40: a file in centimetres without a header (as PedPy's own demo
// file) gave speeds of 207 m/s "with a note". Speeds beyond any human are
// refused, naming the likely unit; --unit (here `unit`) reads it right.
TEST(PeTrack, SpeedsBeyondHumanNameTheLikelyUnitAndTheUnitCanBeGiven) {
  std::string text = "# framerate: 25 fps\n";
  for (int frame = 0; frame < 10; ++frame) text += "1 " + std::to_string(frame) + " " + std::to_string(5 * frame) + " 100\n";
  try {
    ParsePeTrack(text, "uo.txt");
    ADD_FAILURE() << "125 m/s accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("uo.txt: people move at up to 125.0 m/s between frames, faster than any human (12 m/s) with "
                     "coordinates in metres (assumed: the file states no unit) at 25 fps; the coordinates are likely in cm"),
              std::string::npos) << m;
  }
  const Trajectories cm = ParsePeTrack(text, "uo.txt", 0.0, "cm");
  EXPECT_EQ(cm.unit, "cm");
  EXPECT_DOUBLE_EQ(cm.points[1].position_m.x, 0.05);
  EXPECT_DOUBLE_EQ(cm.points[1].position_m.y, 1.0);
  // In mm the same numbers are 0.125 m/s; a file in mm read as metres: mm named.
  EXPECT_EQ(ParsePeTrack(text, "uo.txt", 0.0, "mm").unit, "mm");
  std::string fast = "# framerate: 25 fps\n";
  for (int frame = 0; frame < 3; ++frame) fast += "1 " + std::to_string(frame) + " " + std::to_string(2000 * frame) + " 0\n";
  try {
    ParsePeTrack(fast, "mm.txt", 0.0, "m");
    ADD_FAILURE() << "50 km/s accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("with coordinates in m at 25 fps; the coordinates are likely in mm"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ParsePeTrack(text, "uo.txt", 0.0, "ft"), InputError);
}

}  // namespace
}  // namespace crowdrecon::observe
