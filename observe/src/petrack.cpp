#include "crowdrecon/observe/petrack.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <unordered_map>
#include <unordered_set>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"

namespace crowdrecon::observe {

namespace {

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string Shown(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 60)) out += (static_cast<unsigned char>(c) < 32 || c == 127) ? '?' : c;
  return s.size() > 60 ? out + "..." : out;
}

// The fields of a line, split at spaces and tabs (and a trailing \r).
std::vector<std::string_view> Fields(std::string_view line) {
  std::vector<std::string_view> f;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) f.push_back(line.substr(start, i - start));
  }
  return f;
}

bool Number(std::string_view s, double* v) {
  // strtod needs a terminated string; fields are short.
  if (s.empty() || s.size() > 64) return false;
  const std::string text(s);
  char* end = nullptr;
  *v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(*v);
}

bool Integer(std::string_view s, std::int64_t* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace

Trajectories ParsePeTrack(std::string_view text, const std::string& source, double fps_override,
                          const std::string& unit) {
  Trajectories t;
  t.source = source;
  double file_fps = 0.0;
  bool unit_stated = false;
  double scale = 1.0;  // file unit to metres
  const double given_scale = unit == "m" ? 1.0 : unit == "cm" ? 1e-2 : unit == "mm" ? 1e-3 : 0.0;
  if (!unit.empty() && given_scale == 0.0)
    throw InputError(source + ": unit \"" + unit + "\"; expected m, cm or mm");
  std::unordered_set<std::uint32_t> ids;
  std::size_t line_no = 0;
  std::size_t at = 0;
  bool first_point = true;
  const auto fail = [&](const std::string& what) {
    throw InputError(source + ":" + std::to_string(line_no) + ": " + what);
  };
  while (at <= text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    if (line.find('\0') != std::string_view::npos) fail("a NUL byte; expected a text file of trajectories");
    const std::vector<std::string_view> f = Fields(line);
    if (f.empty()) {
      if (end == text.size()) break;
      continue;
    }
    if (f.front().front() == '#') {
      const std::string lower = Lower(line);
      if (const std::size_t k = lower.find("framerate"); k != std::string::npos) {
        const std::size_t colon = lower.find(':', k);
        const std::vector<std::string_view> rate = Fields(std::string_view(line).substr(colon == std::string::npos ? k + 9 : colon + 1));
        double v = 0.0;
        if (rate.empty() || !Number(rate.front(), &v) || !(v > 0.0 && v <= 10000.0))
          fail("frame rate \"" + Shown(line) + "\"; expected \"# framerate: N fps\" with N in (0, 10000]");
        file_fps = v;
      }
      // The column header: "x/m", "x/cm", "x/mm" give the unit.
      for (const auto& [name, factor] : {std::pair<const char*, double>{"x/mm", 1e-3}, {"x/cm", 1e-2}, {"x/m", 1.0}})
        if (given_scale == 0.0 && lower.find(name) != std::string::npos) {
          scale = factor;
          t.unit = std::string(name).substr(2);
          unit_stated = true;
          break;
        }
      if (end == text.size()) break;
      continue;
    }
    if (given_scale != 0.0 && !unit_stated) {  // the unit given replaces any header
      scale = given_scale;
      t.unit = unit;
      unit_stated = true;
    }
    if (f.size() < 4 || f.size() > 5)
      fail("\"" + Shown(line) + "\": " + std::to_string(f.size()) +
           " fields; expected id frame x y [z] separated by spaces or tabs");
    std::int64_t id = 0, frame = 0;
    if (!Integer(f[0], &id) || id < 0 || id > kMaxPersonId)
      fail("id \"" + Shown(f[0]) + "\"; expected a whole number in [0, " + std::to_string(kMaxPersonId) + "]");
    if (!Integer(f[1], &frame) || frame < 0 || frame > kMaxFrame)
      fail("frame \"" + Shown(f[1]) + "\"; expected a whole number in [0, " + std::to_string(kMaxFrame) + "]");
    double v[3] = {0.0, 0.0, 0.0};
    for (std::size_t c = 2; c < f.size(); ++c) {
      if (!Number(f[c], &v[c - 2]) || std::abs(v[c - 2] * scale) > kMaxCoordinate_m)
        fail(std::string(c == 2 ? "x" : c == 3 ? "y" : "z") + " \"" + Shown(f[c]) + "\"; expected a number within +-" +
             FormatNumber(kMaxCoordinate_m) + " m");
    }
    TrajectoryPoint p;
    p.id = static_cast<std::uint32_t>(id);
    p.frame = frame;
    p.position_m = {v[0] * scale, v[1] * scale};
    p.z_m = v[2] * scale;
    t.points.push_back(p);
    ids.insert(p.id);
    t.first_frame = first_point ? frame : std::min(t.first_frame, frame);
    t.last_frame = first_point ? frame : std::max(t.last_frame, frame);
    first_point = false;
    if (end == text.size()) break;
  }
  if (t.points.empty())
    throw InputError(source + ": no trajectory lines; expected lines of id frame x y [z] after the # comments");
  t.people = ids.size();
  t.fps = fps_override > 0.0 ? fps_override : file_fps;
  if (!(t.fps > 0.0))
    throw InputError(source + ": no frame rate (a comment \"# framerate: 25 fps\"); give it with --fps");
  if (fps_override > 0.0 && file_fps > 0.0 && fps_override != file_fps)
    t.notes.push_back("frame rate " + FormatNumber(fps_override) + " fps as given, not the file's " + FormatNumber(file_fps));
  if (!unit_stated) t.notes.push_back("the file states no unit (x/m, x/cm, x/mm): metres assumed");
  // Beyond human: the fastest step between consecutive frames of a track.
  std::unordered_map<std::uint32_t, const TrajectoryPoint*> last;
  double fastest = 0.0;
  for (const TrajectoryPoint& p : t.points) {
    const auto it = last.find(p.id);
    if (it != last.end() && p.frame > it->second->frame)
      fastest = std::max(fastest, Length(p.position_m - it->second->position_m) * t.fps /
                                      static_cast<double>(p.frame - it->second->frame));
    last[p.id] = &p;
  }
  if (fastest > kMaxHumanSpeed_m_per_s)
    throw InputError(source + ": people move at up to " + FormatFixed(fastest, 1) + " m/s between frames, faster than " +
                     "any human (" + FormatNumber(kMaxHumanSpeed_m_per_s) + " m/s) with coordinates in " +
                     (t.unit == "m" && !unit_stated ? "metres (assumed: the file states no unit)" : t.unit) +
                     " at " + FormatNumber(t.fps) + " fps; the coordinates are likely in " +
                     (fastest > 100.0 * kMaxHumanSpeed_m_per_s ? "mm" : "cm") +
                     " (give --unit cm or --unit mm, or a header # id frame x/cm y/cm), or the frame rate is wrong");
  return t;
}

Trajectories ReadPeTrack(const std::filesystem::path& file, double fps_override, const std::string& unit) {
  return ParsePeTrack(ReadInputFile(file, "PeTrack trajectory file"), file.string(), fps_override, unit);
}

}  // namespace crowdrecon::observe
