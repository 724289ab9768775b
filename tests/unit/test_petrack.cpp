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

}  // namespace
}  // namespace crowdrecon::observe
