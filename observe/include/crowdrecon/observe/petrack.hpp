// PeTrack trajectory text files (the Jülich experiments of ../shared/data):
// comment lines (#) carry the frame rate ("# framerate: 25 fps") and the
// columns' units ("# id frame x/m y/m z/m", x/cm, x/mm; none stated: metres),
// then one line per person and frame: id frame x y [z], separated by spaces
// or tabs. Issue 22 (observations): the first source read into observations.
//
//   observe::Trajectories t = observe::ReadPeTrack("040_c_56_h-.txt");
//   t.fps, t.points[k].position_m ...
//
// Every problem is an InputError naming the file, the line and what was
// expected; nothing is guessed silently (a missing unit is a note).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::observe {

struct TrajectoryPoint {
  std::uint32_t id = 0;      // the person's id in the file
  std::int64_t frame = 0;
  Vec2 position_m;
  double z_m = 0.0;          // height or 3D position, as the file says (0 without the column)
};

struct Trajectories {
  std::string source;        // the file's name, for messages
  double fps = 0.0;
  std::string unit = "m";    // of the coordinates in the file: m, cm or mm
  std::vector<TrajectoryPoint> points;  // in file order
  std::size_t people = 0;    // distinct ids
  std::int64_t first_frame = 0, last_frame = 0;
  std::vector<std::string> notes;  // what the reader assumed (a unit not stated, ...)
};

// Limits of what a file may hold (an error names them).
inline constexpr std::uint32_t kMaxPersonId = 10'000'000;
inline constexpr std::int64_t kMaxFrame = 1'000'000'000;
inline constexpr double kMaxCoordinate_m = 1e5;

// `fps_override` > 0 replaces the file's frame rate (a file without one needs it).
Trajectories ParsePeTrack(std::string_view text, const std::string& source, double fps_override = 0.0);
Trajectories ReadPeTrack(const std::filesystem::path& file, double fps_override = 0.0);

}  // namespace crowdrecon::observe
