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

// `fps_override` > 0 replaces the file's frame rate (a file without one
// needs it); `unit` ("m", "cm" or "mm"; "" = the file's column header, else
// metres) gives the coordinates' unit (a file without a header needs it
// when it is not in metres). A file whose people move faster than any human
// (kMaxHumanSpeed_m_per_s between two frames of a track) is refused, naming
// the likely unit mistake: PedPy's own demo file has no header and is in cm.
Trajectories ParsePeTrack(std::string_view text, const std::string& source, double fps_override = 0.0,
                          const std::string& unit = "");
Trajectories ReadPeTrack(const std::filesystem::path& file, double fps_override = 0.0, const std::string& unit = "");

// Faster than the fastest sprinters (about 12 m/s, over a few metres).
inline constexpr double kMaxHumanSpeed_m_per_s = 12.0;

}  // namespace crowdrecon::observe
