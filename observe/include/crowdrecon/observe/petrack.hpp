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

#include <filesystem>
#include <string>
#include <string_view>

#include "crowdrecon/observe/trajectories.hpp"

namespace crowdrecon::observe {

// `fps_override` > 0 replaces the file's frame rate (a file without one needs it).
Trajectories ParsePeTrack(std::string_view text, const std::string& source, double fps_override = 0.0);
Trajectories ReadPeTrack(const std::filesystem::path& file, double fps_override = 0.0);

}  // namespace crowdrecon::observe
