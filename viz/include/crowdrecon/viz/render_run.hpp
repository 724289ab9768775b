// Pictures and videos of a run: every selected frame of a run file
// (runfile/run_file.hpp) drawn as the paper's Figure 6 -- the walkable area,
// the walls, each person's spheropolygon body coloured by group with a mark on
// the chest, and the contact force network: "a line from the center of mass
// of the pedestrian to the contact point, ... the magnitude of the force [as]
// the thickness of the line" (Alonso-Marroquin et al., Results, Figure 6).
//
//   viz::RenderOptions options;
//   options.output_dir = "frames";
//   options.frames = viz::ParseFrameSelection("every:10");
//   options.video = "run.mp4";
//   viz::RenderSummary summary = viz::RenderRun("run.sqlite", options);
//   std::puts(summary.BriefReport().c_str());
//
// Used by `crowdrecon render`. Errors a user can cause (a missing or foreign
// file, an empty run, a bad selection, an output that cannot be written) are
// InputError with a message naming the file or option.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::viz {

// Which frames of a run to draw, as given to --frames:
//   "all"                 every frame
//   "first,last", "0,50,last"   a list of frame numbers and the words first/last
//   "every:N"             every N-th frame, starting with the first
//   "T1:T2"               frames whose time lies in [T1, T2] seconds (either may be empty)
struct FrameSelection {
  enum class Kind { kAll, kList, kEvery, kTimeRange };
  // Stand-ins for "first" and "last" in `list`.
  static constexpr std::int64_t kFirst = std::numeric_limits<std::int64_t>::min();
  static constexpr std::int64_t kLast = std::numeric_limits<std::int64_t>::max();

  Kind kind = Kind::kAll;
  std::vector<std::int64_t> list;  // kList: frame numbers, kFirst, kLast
  std::int64_t stride = 1;         // kEvery
  double from_s = -std::numeric_limits<double>::infinity();  // kTimeRange
  double to_s = std::numeric_limits<double>::infinity();
  std::string text;  // as given, for messages
};

// Parses --frames; throws InputError ("--frames \"x\": ...; expected ...").
FrameSelection ParseFrameSelection(const std::string& text);

// The frames of `frames` (ascending frame numbers of a run) that `selection`
// picks, ascending and without repeats. `time_of_frame_s` gives a frame's time
// (only called for time ranges, O(log n) times: times grow with frames).
// A frame counts as inside a time range if it is within `tolerance_s` of it:
// a run writes a frame at the first step at or after its nominal time, so
// its time may exceed it by up to one time step.
// Throws InputError if a listed frame is not in the run or nothing is selected.
std::vector<std::int64_t> SelectFrames(const FrameSelection& selection,
                                       const std::vector<std::int64_t>& frames,
                                       const std::function<double(std::int64_t)>& time_of_frame_s,
                                       double tolerance_s = 1e-6);

// Progress of a render, for a terminal display.
struct RenderProgress {
  std::size_t done = 0;   // frames written so far
  std::size_t total = 0;  // frames selected
  std::int64_t frame = 0;  // the frame just written
  double time_s = 0.0;
};

struct RenderOptions {
  // Folder of the pictures frame_NNNNNN.png (and .svg); created if missing.
  std::filesystem::path output_dir;
  FrameSelection frames;  // default: all
  // Video of the selected frames: .avi (Motion-JPEG) or .mp4 (MPEG-4 part 2,
  // "mp4v"; if OpenCV cannot write that, the video goes to the same name with
  // .avi in Motion-JPEG and RenderSummary::notes says so). Empty: none.
  std::filesystem::path video;
  // Frames per second of the video; 0: the run's output rate (divided by N
  // for every:N), so that the video plays in real time.
  double video_fps = 0.0;
  // Width of each picture in pixels, margins included (the height follows
  // from the drawn region's aspect ratio).
  int width_px = 1280;
  // Force per pixel of line width in the force network (N/px); 0: chosen so
  // that the largest force among the selected frames is drawn about 0.12 m
  // wide. Lines are never thinner than kMinForceLineWidth_px.
  double force_n_per_px = 0.0;
  bool svg = false;  // also write frame_NNNNNN.svg
  // A crop: the world window [window_min_m, window_max_m] drawn instead of
  // the whole venue and everyone in it (a part of a large venue at a
  // readable scale, as the pile at an alley's foot); what lies outside is
  // clipped. The force scale is then chosen from the contacts inside it.
  bool has_window = false;
  Vec2 window_min_m, window_max_m;
  // A rectangle drawn over the picture (its lower-left and upper-right
  // corners, m): where a close-up lies, on the whole view beside it (the
  // injury-risk report's force network).
  bool has_mark = false;
  Vec2 mark_min_m, mark_max_m;
  // Called after each frame (may be empty).
  std::function<void(const RenderProgress&)> progress;

  // False, with "option: value, expected ..." in *error, if an option is out of range.
  bool IsValid(std::string* error) const;
};

// Parses --window "x0,y0,x1,y1" (metres) into options->window_*; throws
// InputError ("--window \"x\": ...; expected ...").
void ParseRenderWindow(const std::string& text, RenderOptions* options);

// Thinnest force line drawn (px), so that every contact stays visible.
inline constexpr double kMinForceLineWidth_px = 0.5;

struct RenderSummary {
  std::size_t frames_written = 0;
  std::int64_t first_frame = 0, last_frame = 0;
  std::filesystem::path first_picture;  // the first PNG written
  int width_px = 0, height_px = 0;      // size of every picture
  // The layout shared by every picture: world window, scale and margin.
  Vec2 world_min_m, world_max_m;
  double pixels_per_metre = 0.0;
  double margin_px = 0.0;
  bool cropped = false;                 // drawn in RenderOptions' window (world_min_m .. world_max_m)
  double max_contact_force_n = 0.0;     // over the selected frames (inside the window if cropped)
  double force_n_per_px = 0.0;          // the scale used
  std::size_t most_fallen = 0;          // most people drawn fallen in one frame (event `fall`)
  std::filesystem::path video_written;  // empty if none
  std::string video_codec;              // "mp4v" or "MJPG"
  double video_fps = 0.0;
  // Things the user should know: the video went to .avi, the walkable area
  // could not be read, ...
  std::vector<std::string> notes;
  // Periodic seams could not be unwrapped (the run does not record its
  // periodic box): contact lines longer than a body were left out.
  std::size_t branches_left_out = 0;

  std::string BriefReport() const;
  // Pixel position (from the top-left corner) of a world point in the pictures.
  Vec2 PixelOf(Vec2 world_m) const {
    return {margin_px + (world_m.x - world_min_m.x) * pixels_per_metre,
            margin_px + (world_max_m.y - world_m.y) * pixels_per_metre};
  }
};

// Draws the selected frames of `run_file` into options.output_dir (and the
// video). Throws InputError for a missing file, a file that is not a
// crowdrecon run, a run without frames, a bad selection or options, and
// outputs that cannot be written.
RenderSummary RenderRun(const std::filesystem::path& run_file, const RenderOptions& options);

// The picture file of a frame in `dir`: dir/frame_000123.png (extension ".png" or ".svg").
std::filesystem::path FramePicturePath(const std::filesystem::path& dir, std::int64_t frame,
                                       const std::string& extension);

// A previous frames folder: only frame_NNNNNN.png / .svg pictures and videos,
// which render -o writes into (common/output_path.hpp).
OutputKind FramesFolderOutput();

}  // namespace crowdrecon::viz
