// Pictures of runs (viz/render_run.hpp): frame selection, and a small engine
// run written to a run file and rendered, checked pixel by pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/media/media.hpp"  // imread/imwrite/video through the codecs module (tests start without it)

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/viz/canvas.hpp"
#include "crowdrecon/viz/chart.hpp"
#include "crowdrecon/viz/render_run.hpp"
#include "crowdrecon/viz/timeline_figure.hpp"
#include "render_scene.hpp"
#include "ticks.hpp"

namespace crowdrecon::viz {
namespace {

using testing_util::ErrorOf;

using engine::testing::CorridorScene;

// A scratch folder per test, removed afterwards.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("crowdrecon-render-" + name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Writes the counter-flow corridor (12 thorax-like bodies, periodic along x,
// walls along both sides) with `frames` frames at 10 fps.
std::filesystem::path WriteRun(const std::filesystem::path& dir, int frames, bool record_periodic_box = true) {
  const CorridorScene scene;
  engine::Simulation sim(engine::testing::CounterFlowCorridor(engine::testing::ThoraxLikeShape(), scene));
  const std::filesystem::path file = dir / "run.sqlite";
  engine::testing::WriteCorridorRun(file, sim, scene, frames, 10.0, record_periodic_box);
  return file;
}

// The recorded marks' labels over a timeline: each in the first row where it
// does not overlap the row's last label (0.56 of the size per character and
// a 6-px gap), at most the rows given (then the row that ends first). The
// Itaewon marks at 156, 180 and 204 s of 270 overlapped with two rows taken
// in turn.
// The timeline's time axis has ticks at every length of run (issue 65, T08:
// a 6 s run had one tick, "0 s"): about five below a minute, whole tens of
// seconds or minutes above.
TEST(TimeAxis, EveryRunGetsSeveralTicks) {
  for (const double span : {2.0, 6.0, 25.0, 59.0, 60.0, 300.0, 599.0, 3600.0, 6 * 3600.0}) {
    const double tick = viz::detail::TimeAxisTick(span);
    EXPECT_GE(span / tick, 3.0) << "span " << span << " s, tick " << tick << " s";
    EXPECT_LE(span / tick, 13.0) << "span " << span << " s, tick " << tick << " s";
  }
  EXPECT_EQ(viz::detail::TimeAxisTick(6.0), 1.0);
  EXPECT_EQ(viz::detail::TimeAxisTick(2.0), 0.5);
}

TEST(LabelRows, ALabelGoesWhereItDoesNotOverlap) {
  const std::vector<std::string> labels{"22:11 last police call before the crush (/10)", "22:15 swept down (/10)",
                                        "22:19 first rescue team (/10)", "22:43 (/10)"};
  // 10-px text: the first is 45 characters, 252 px (+6) wide.
  EXPECT_EQ(LabelRows({100, 200, 300, 400}, labels, 10, 3), (std::vector<int>{0, 1, 2, 0}));
  EXPECT_EQ(LabelRows({100, 400, 700, 900}, labels, 10, 3), (std::vector<int>{0, 0, 0, 0}));
  // No row free: the one whose last label ends first.
  EXPECT_EQ(LabelRows({100, 110, 120}, {"aaaaaaaaaa", "bbbbbbbbbbbbbbbbbbbb", "c"}, 10, 2), (std::vector<int>{0, 1, 0}));
  EXPECT_TRUE(LabelRows({}, {}, 10, 3).empty());
}

TEST(RenderFrameSelection, ParsesEveryForm) {
  EXPECT_EQ(ParseFrameSelection("all").kind, FrameSelection::Kind::kAll);
  const FrameSelection list = ParseFrameSelection("first, 7,last");
  ASSERT_EQ(list.kind, FrameSelection::Kind::kList);
  EXPECT_EQ(list.list, (std::vector<std::int64_t>{FrameSelection::kFirst, 7, FrameSelection::kLast}));
  const FrameSelection every = ParseFrameSelection("every:5");
  EXPECT_EQ(every.kind, FrameSelection::Kind::kEvery);
  EXPECT_EQ(every.stride, 5);
  const FrameSelection range = ParseFrameSelection("0.5:1.5");
  EXPECT_EQ(range.kind, FrameSelection::Kind::kTimeRange);
  EXPECT_DOUBLE_EQ(range.from_s, 0.5);
  EXPECT_DOUBLE_EQ(range.to_s, 1.5);
  EXPECT_TRUE(std::isinf(ParseFrameSelection(":3").from_s));
  EXPECT_TRUE(std::isinf(ParseFrameSelection("3:").to_s));
}

TEST(RenderFrameSelection, RejectsMalformedSelections) {
  for (const char* bad : {"", "every:0", "every:x", "5:2", ":", "a:b", "1,,2", "first,middle", "-3", "1.5"}) {
    const std::string message = ErrorOf([&] { ParseFrameSelection(bad); });
    EXPECT_NE(message.find("--frames \"" + std::string(bad) + "\""), std::string::npos) << message;
    EXPECT_NE(message.find("expected all"), std::string::npos) << message;
  }
}

TEST(RenderFrameSelection, SelectsFramesOfTheRun) {
  const std::vector<std::int64_t> frames{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  const auto time_of = [](std::int64_t f) { return 0.1 * static_cast<double>(f); };  // 10 fps, inexact sums
  EXPECT_EQ(SelectFrames(ParseFrameSelection("all"), frames, time_of), frames);
  EXPECT_EQ(SelectFrames(ParseFrameSelection("last,first,last"), frames, time_of),
            (std::vector<std::int64_t>{0, 10}));
  EXPECT_EQ(SelectFrames(ParseFrameSelection("every:4"), frames, time_of), (std::vector<std::int64_t>{0, 4, 8}));
  EXPECT_EQ(SelectFrames(ParseFrameSelection("0.3:0.6"), frames, time_of),
            (std::vector<std::int64_t>{3, 4, 5, 6}));
  EXPECT_EQ(SelectFrames(ParseFrameSelection("0.95:"), frames, time_of), (std::vector<std::int64_t>{10}));
  EXPECT_NE(ErrorOf([&] { SelectFrames(ParseFrameSelection("3,11"), frames, time_of); })
                .find("frame 11 is not in the run (the run has 11 frames, 0 to 10)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { SelectFrames(ParseFrameSelection("2:3"), frames, time_of); })
                .find("no frame lies between 2 s and 3 s (the run covers 0 s to 1 s)"),
            std::string::npos);
}

TEST(RenderRun, DrawsBodiesWallsAndForcesIntoPngFramesAndAVideo) {
  const ScratchDir dir("draw");
  const std::filesystem::path run = WriteRun(dir.path(), 21);

  RenderOptions options;
  options.output_dir = dir.path() / "frames";
  options.width_px = 800;
  options.svg = true;
  options.video = dir.path() / "run.avi";
  std::size_t progress_calls = 0;
  options.progress = [&](const RenderProgress& p) {
    ++progress_calls;
    EXPECT_EQ(p.total, 21u);
  };
  const RenderSummary summary = RenderRun(run, options);

  EXPECT_EQ(summary.frames_written, 21u);
  EXPECT_EQ(progress_calls, 21u);
  EXPECT_EQ(summary.first_frame, 0);
  EXPECT_EQ(summary.last_frame, 20);
  EXPECT_EQ(summary.width_px, 800);
  // Head-on collisions of the counter-flow: there are contact forces to draw,
  // and with the periodic box recorded every branch across the seam is drawn.
  EXPECT_GT(summary.max_contact_force_n, 10.0);
  EXPECT_GT(summary.force_n_per_px, 0.0);
  EXPECT_EQ(summary.branches_left_out, 0u);
  EXPECT_EQ(summary.video_written, dir.path() / "run.avi");
  {
    // The video holds every frame at the picture size (padded to even sizes)
    // and plays at the run's 10 frames per second.
    const std::unique_ptr<media::VideoReader> video = media::MakeVideoReader();
    ASSERT_TRUE(video->Open((dir.path() / "run.avi").string(), cv::CAP_ANY));
    EXPECT_EQ(video->Get(cv::CAP_PROP_FRAME_COUNT), 21.0);
    EXPECT_EQ(video->Get(cv::CAP_PROP_FPS), 10.0);
    EXPECT_EQ(video->Get(cv::CAP_PROP_FRAME_WIDTH), double(summary.width_px + summary.width_px % 2));
    EXPECT_EQ(video->Get(cv::CAP_PROP_FRAME_HEIGHT), double(summary.height_px + summary.height_px % 2));
  }

  for (std::int64_t f = 0; f <= 20; ++f) {
    const std::filesystem::path png = FramePicturePath(options.output_dir, f, ".png");
    ASSERT_TRUE(std::filesystem::exists(png)) << png;
    EXPECT_TRUE(std::filesystem::exists(FramePicturePath(options.output_dir, f, ".svg")));
    const cv::Mat image = media::ReadImage(png.string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << png;
    EXPECT_EQ(image.cols, summary.width_px);
    EXPECT_EQ(image.rows, summary.height_px);
  }

  // Frame 0 has no contacts yet (people stand on a lattice): a point inside
  // each body, between centroid and back, shows its group's colour -- blue
  // (group 0) or orange (group 1) -- and not the floor or the background.
  runfile::RunFileReader reader(run);
  const runfile::RunFrame frame0 = reader.Frame(0);
  ASSERT_TRUE(frame0.contacts.empty());
  const std::vector<std::uint32_t> groups = reader.PersonGroups();
  const cv::Mat image = media::ReadImage(FramePicturePath(options.output_dir, 0, ".png").string(), cv::IMREAD_COLOR);
  for (std::size_t i = 0; i < frame0.ids.size(); ++i) {
    const Vec2 inside = frame0.position_m[i] - frame0.orientation[i] * 0.06;
    const Vec2 px = summary.PixelOf(inside);
    const cv::Vec3b bgr = image.at<cv::Vec3b>(static_cast<int>(px.y), static_cast<int>(px.x));
    const int blue = bgr[0], red = bgr[2];
    const bool group0 = groups[static_cast<std::size_t>(frame0.ids[i] - 1)] == 0;
    EXPECT_FALSE(bgr[0] > 230 && bgr[1] > 225 && bgr[2] > 225) << "background at person " << frame0.ids[i];
    if (group0) EXPECT_GT(blue, red + 20) << "person " << frame0.ids[i];
    else EXPECT_GT(red, blue + 20) << "person " << frame0.ids[i];
  }
  // Far from every body, inside the corridor: the floor colour.
  const Vec2 floor_px = summary.PixelOf({1.5, 0.02});
  const cv::Vec3b floor = image.at<cv::Vec3b>(static_cast<int>(floor_px.y), static_cast<int>(floor_px.x));
  EXPECT_GT(floor[2], 220);
  EXPECT_LT(std::abs(int(floor[2]) - int(floor[0])), 20);
}

TEST(RenderRun, StrongerForcesDrawThickerLines) {
  // With a fixed scale, the darkest (force-coloured) pixel count grows with the
  // force scale's inverse: the same frame at 5 N/px has more force pixels than at 50 N/px.
  const ScratchDir dir("thickness");
  const std::filesystem::path run = WriteRun(dir.path(), 11);
  const auto force_pixels = [&](double n_per_px, const std::string& sub) {
    RenderOptions options;
    options.output_dir = dir.path() / sub;
    options.frames = ParseFrameSelection("last");
    options.force_n_per_px = n_per_px;
    const RenderSummary summary = RenderRun(run, options);
    EXPECT_DOUBLE_EQ(summary.force_n_per_px, n_per_px);
    const cv::Mat image = media::ReadImage(summary.first_picture.string(), cv::IMREAD_COLOR);
    int count = 0;
    for (int y = 0; y < image.rows - static_cast<int>(summary.margin_px); ++y)  // leave out the legend's sample lines
      for (int x = 0; x < image.cols; ++x) {
        const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
        if (p[2] > 100 && p[2] < 190 && p[1] < 60 && p[0] < 60) ++count;  // dark red
      }
    return count;
  };
  const int thin = force_pixels(50.0, "thin"), thick = force_pixels(5.0, "thick");
  EXPECT_GT(thin, 0);
  EXPECT_GT(thick, 2 * thin);
}

// A person who fell (event `fall`) is drawn grey with a cross from then on,
// and counted in the legend and the summary; before it, in their group's colour.
TEST(RenderRun, TheFallenAreDrawnGreyFromTheirFall) {
  const ScratchDir dir("fallen");
  const std::filesystem::path run = WriteRun(dir.path(), 11);
  {
    runfile::RunFileWriter writer = runfile::RunFileWriter::Resume(run, 10);
    runfile::Event e;
    e.time_s = 0.5;
    e.kind = "fall";
    for (std::int64_t person : {2, 7}) {
      e.person = person;
      writer.WriteEvent(5, e);
    }
    writer.SetStatus("complete");
  }
  const auto grey_pixels = [&](const std::string& frames, const std::string& sub, RenderSummary* summary) {
    RenderOptions options;
    options.output_dir = dir.path() / sub;
    options.frames = ParseFrameSelection(frames);
    *summary = RenderRun(run, options);
    const cv::Mat image = media::ReadImage(summary->first_picture.string(), cv::IMREAD_COLOR);
    int count = 0;
    for (int y = static_cast<int>(summary->margin_px); y < image.rows - static_cast<int>(summary->margin_px); ++y)
      for (int x = 0; x < image.cols; ++x) {
        const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
        // The fallen's fill: 0x3a3a3a lightened 45 % toward white (about 0x939393).
        if (std::abs(p[0] - 147) < 8 && std::abs(p[1] - 147) < 8 && std::abs(p[2] - 147) < 8) ++count;
      }
    return count;
  };
  RenderSummary before, after;
  const int grey_before = grey_pixels("0", "before", &before), grey_after = grey_pixels("last", "after", &after);
  EXPECT_EQ(before.most_fallen, 0u);
  EXPECT_LT(grey_before, 20);  // (a few edge pixels of other colours blend to it)
  EXPECT_EQ(after.most_fallen, 2u);
  EXPECT_GT(grey_after, 10 * std::max(grey_before, 5));
  EXPECT_NE(after.BriefReport().find("fallen: up to 2 in a frame"), std::string::npos) << after.BriefReport();
}

// A window (--window) draws a part of the venue at the picture's width: its
// corners are the picture's world window exactly, a body inside it is drawn in
// its group's colour where the layout says, and a body that straddles its edge
// is clipped there, not drawn into the margin beside it.
// Options that draw a run's first frame at a width into the scratch folder.
RenderOptions FirstFrameAt(const ScratchDir& dir, int width_px) {
  RenderOptions options;
  options.output_dir = dir.path() / "frames";
  options.frames = ParseFrameSelection("0");
  options.width_px = width_px;
  return options;
}

TEST(RenderRun, AWindowDrawsAPartOfTheVenueClippedAtItsEdge) {
  const ScratchDir dir("window");
  const std::filesystem::path run = WriteRun(dir.path(), 3);
  RenderOptions options = FirstFrameAt(dir, 800);
  ParseRenderWindow("0, 0, 1.2, 1.5", &options);
  const RenderSummary summary = RenderRun(run, options);
  EXPECT_TRUE(summary.cropped);
  EXPECT_EQ(summary.world_min_m, (Vec2{0.0, 0.0}));
  EXPECT_EQ(summary.world_max_m, (Vec2{1.2, 1.5}));
  EXPECT_EQ(summary.width_px, 800);
  EXPECT_NEAR(summary.pixels_per_metre, (800.0 - 2.0 * summary.margin_px) / 1.2, 1e-6);
  EXPECT_NE(summary.BriefReport().find("window: (0, 0) to (1.2, 1.5) m"), std::string::npos) << summary.BriefReport();

  const cv::Mat image = media::ReadImage(summary.first_picture.string(), cv::IMREAD_COLOR);
  const auto coloured = [](const cv::Vec3b& p) {  // a group's fill: blue or orange, not grey, white or black
    return std::abs(int(p[0]) - int(p[2])) > 40;
  };
  runfile::RunFileReader reader(run);
  const runfile::RunFrame frame0 = reader.Frame(0);
  int inside = 0, straddling = 0;
  for (std::size_t i = 0; i < frame0.ids.size(); ++i) {
    const Vec2 x = frame0.position_m[i];
    if (x.x < 1.0) {  // wholly inside the window
      const Vec2 px = summary.PixelOf(x - frame0.orientation[i] * 0.06);
      EXPECT_TRUE(coloured(image.at<cv::Vec3b>(static_cast<int>(px.y), static_cast<int>(px.x)))) << frame0.ids[i];
      ++inside;
    } else if (x.x < 1.2) {
      ++straddling;  // the column at 1.125 m reaches past 1.2 m
    }
  }
  EXPECT_EQ(inside, 3);
  EXPECT_EQ(straddling, 3);
  // The straddling bodies and the floor stop at the window's edge: the right
  // margin is the background, though the bodies reach about 0.045 m (26 px)
  // and the floor 1.8 m into it.
  const int edge_px = static_cast<int>(std::ceil(summary.PixelOf({1.2, 0.0}).x)) + 1;
  int beyond = 0, before = 0;
  for (int y = static_cast<int>(summary.margin_px); y < image.rows - static_cast<int>(summary.margin_px); ++y) {
    for (int x = edge_px; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      beyond += !(p[0] > 250 && p[1] > 250 && p[2] > 250);
    }
    for (int x = edge_px - 20; x < edge_px - 2; ++x) before += coloured(image.at<cv::Vec3b>(y, x));
  }
  EXPECT_EQ(beyond, 0);
  EXPECT_GT(before, 100);  // and they are drawn up to it

  EXPECT_NE(ErrorOf([&] { ParseRenderWindow("0,0,1", &options); }).find("--window \"0,0,1\": 3 numbers; expected x0,y0,x1,y1"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ParseRenderWindow("1,0,0,1", &options); }).find("not lower-left then upper-right"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ParseRenderWindow("0,0,a,1", &options); }).find("\"a\" is not a number"), std::string::npos);
  // A window far taller than wide: the pictures would be too tall, said with the way out.
  RenderOptions tall = options;
  tall.width_px = 8000;
  ParseRenderWindow("0, 0, 0.05, 1.5", &tall);
  EXPECT_NE(ErrorOf([&] { RenderRun(run, tall); }).find("px tall (at most 20000): give a smaller --width or a wider --window"),
            std::string::npos);
  RenderOptions flat = options;
  flat.window_max_m.y = flat.window_min_m.y;
  EXPECT_NE(ErrorOf([&] { RenderRun(run, flat); }).find("--window: (0, 0) to (1.2, 0) m, expected"), std::string::npos);
}

TEST(RenderRun, ANarrowPicturesLegendShrinksToItsWidth) {
  // The legend's two lines (time, people, contacts, the largest force; the
  // groups and the key) are some 800 px long at their sizes: on a narrower
  // picture they shrink rather than run off its right edge.
  const ScratchDir dir("narrow");
  const RenderSummary summary = RenderRun(WriteRun(dir.path(), 3), FirstFrameAt(dir, 480));
  const cv::Mat image = media::ReadImage(summary.first_picture.string(), cv::IMREAD_COLOR);
  const int margin = static_cast<int>(summary.margin_px);
  int drawn_in_margin = 0, drawn_in_legend = 0;
  for (int y = 0; y < margin; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      const bool background = p[0] > 250 && p[1] > 250 && p[2] > 250;
      (x >= image.cols - margin / 2 ? drawn_in_margin : drawn_in_legend) += !background;
    }
  EXPECT_EQ(drawn_in_margin, 0);
  EXPECT_GT(drawn_in_legend, 500);
}

TEST(RenderRun, WithoutAPeriodicBoxLeavesOutBranchesAcrossTheSeam) {
  const ScratchDir dir("seam");
  const std::filesystem::path run = WriteRun(dir.path(), 11, /*record_periodic_box=*/false);
  RenderOptions options;
  options.output_dir = dir.path() / "frames";
  const RenderSummary summary = RenderRun(run, options);
  EXPECT_EQ(summary.frames_written, 11u);
  // The corridor's people meet across x = 0 (columns at 0.375 and 2.625 m).
  EXPECT_GT(summary.branches_left_out, 0u);
  EXPECT_NE(summary.BriefReport().find("left out"), std::string::npos);
}

TEST(RenderRun, ReportsUserErrorsClearly) {
  const ScratchDir dir("errors");
  RenderOptions options;
  options.output_dir = dir.path() / "out";

  EXPECT_NE(ErrorOf([&] { RenderRun(dir.path() / "missing.sqlite", options); })
                .find("missing.sqlite: run file does not exist"),
            std::string::npos);

  const std::filesystem::path text = dir.path() / "notes.txt";
  std::ofstream(text) << "not a database, just text that is long enough to have a header page\n";
  EXPECT_NE(ErrorOf([&] { RenderRun(text, options); }).find("notes.txt: not a crowdrecon run file"),
            std::string::npos);

  const std::filesystem::path empty = dir.path() / "empty";
  std::filesystem::create_directories(empty);
  const std::filesystem::path empty_run = WriteRun(empty, 0);
  EXPECT_NE(ErrorOf([&] { RenderRun(empty_run, options); }).find("the run has no frames to draw (status: complete)"),
            std::string::npos);

  const std::filesystem::path run = WriteRun(dir.path(), 3);
  RenderOptions bad_frames = options;
  bad_frames.frames = ParseFrameSelection("0,9");
  EXPECT_NE(ErrorOf([&] { RenderRun(run, bad_frames); }).find("frame 9 is not in the run"), std::string::npos);

  RenderOptions under_a_file = options;
  under_a_file.output_dir = text / "frames";
  EXPECT_NE(ErrorOf([&] { RenderRun(run, under_a_file); }).find("cannot create the output folder"),
            std::string::npos);

  RenderOptions bad_video = options;
  bad_video.video = dir.path() / "run.gif";
  EXPECT_NE(ErrorOf([&] { RenderRun(run, bad_video); }).find("unknown video format \".gif\""), std::string::npos);

  RenderOptions narrow = options;
  narrow.width_px = 10;
  EXPECT_NE(ErrorOf([&] { RenderRun(run, narrow); }).find("--width: 10 px"), std::string::npos);
}

// A picture is drawn into a hidden partial file and renamed over the final
// name only when complete (issue 40: a kill during a figure truncated the
// previous picture to 0 bytes): a canvas given up before Finish leaves the
// previous picture as it was and nothing else behind, in every format.
// A recorded mark that is not an avalanche (a police call, a rescue team:
// kind "other") is drawn and named as what it is, not as a recorded
// avalanche (the Itaewon evening's 22:11 and 22:19 were drawn as
// avalanches); the legend names only the kinds the marks have.
TEST(TimelineFigure, EachKindOfRecordedMarkIsDrawnAndNamedAsItself) {
  EXPECT_EQ(viz::RecordedMarkKinds({{60, "call", "other"}, {120, "crush", "fatal"}, {900, "later", "avalanche"}}, 0, 200),
            (std::vector<std::string>{"fatal", "other"}));
  const viz::RecordedMarkStyle avalanche = viz::RecordedMarkStyleOf("avalanche"),
                               fatal = viz::RecordedMarkStyleOf("fatal"), other = viz::RecordedMarkStyleOf("other");
  EXPECT_NE(other.color.r, avalanche.color.r);
  EXPECT_NE(fatal.color.r, avalanche.color.r);
  EXPECT_FALSE(fatal.dashed);

  const ScratchDir dir("timeline-marks");
  analysis::TimelineSeries ts;
  for (int i = 0; i <= 200; ++i) {
    ts.time_s.push_back(i);
    ts.density_per_m2.push_back(1.0 + 0.01 * i);
  }
  ts.clock.start = "21:45";
  ts.recorded = {{60, "22:46 police call", "other"}, {120, "22:47 the crush", "fatal"}};
  const std::filesystem::path svg = dir.path() / "t.svg";
  viz::DrawTimelineFigure(ts, "marks", svg);
  std::ifstream in(svg);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Cairo writes text as glyphs: the strokes' colours tell the kinds apart.
  const auto percent = [](double v) {  // as Cairo writes it: %f without trailing zeros
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%f", 100 * v);
    std::string digits = buffer;
    digits.erase(digits.find_last_not_of('0') + 1);
    if (digits.back() == '.') digits.pop_back();
    return digits + "%";
  };
  const auto stroke = [&](const viz::Color& c) {
    return "stroke:rgb(" + percent(c.r) + "," + percent(c.g) + "," + percent(c.b) + ")";
  };
  EXPECT_NE(text.find(stroke(other.color)), std::string::npos) << stroke(other.color);
  EXPECT_NE(text.find(stroke(fatal.color)), std::string::npos) << stroke(fatal.color);
  EXPECT_EQ(text.find(stroke(avalanche.color)), std::string::npos) << "no mark is an avalanche";
}

TEST(Canvas, APictureReplacesThePreviousOneOnlyWhenComplete) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crowdrecon-canvas-atomic";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const char* name : {"figure.png", "figure.svg", "figure.pdf"}) {
    const std::filesystem::path file = dir / name;
    { std::ofstream(file) << "the previous picture"; }
    {
      Canvas abandoned(file, {0, 0}, {2, 1}, 100, 10);
      abandoned.FillPolygon({{0, 0}, {1, 0}, {1, 1}}, Color::Black());
    }  // no Finish: a command that failed while drawing
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, "the previous picture") << name;
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator{}), 1) << name;
    Canvas finished(file, {0, 0}, {2, 1}, 100, 10);
    finished.FillPolygon({{0, 0}, {1, 0}, {1, 1}}, Color::Black());
    finished.Finish();
    EXPECT_GT(std::filesystem::file_size(file), 100u) << name;
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator{}), 1) << name;
    std::filesystem::remove(file);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace crowdrecon::viz
