// Options of a render (render_run.hpp): the frame selection, the window,
// the options' check, the frames folder's kind. The drawing is render_run.cpp.
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"
#include "crowdrecon/viz/render_run.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <regex>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/canvas.hpp"
#include "crowdrecon/media/media.hpp"

namespace crowdrecon::viz {

namespace {

// --- frame selection -----------------------------------------------------------

[[noreturn]] void FailSelection(const std::string& text, const std::string& why) {
  throw InputError("--frames \"" + text + "\": " + why +
                   "; expected all, a list such as first,last or 0,50,last, every:N, or a time range T1:T2 in "
                   "seconds");
}

std::string Trimmed(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t") - begin + 1);
}

std::optional<std::int64_t> ParseInteger(const std::string& s) {
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return value;
}

// The comma-separated items of an option's value, each trimmed (an empty
// item stays, for its message).
std::vector<std::string> CommaItems(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    items.push_back(Trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

// A finite number (seconds, metres).
std::optional<double> ParseNumber(const std::string& s) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(value)) return std::nullopt;
  return value;
}

// Times in messages: six significant digits hide the time-step residue of
// frame times (2.000149 s for a frame written at the step after 2 s).
std::string Seconds(double t_s) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.6g", t_s);
  return buffer;
}

}  // namespace

FrameSelection ParseFrameSelection(const std::string& raw) {
  FrameSelection s;
  s.text = raw;
  const std::string text = Trimmed(raw);
  if (text.empty()) FailSelection(raw, "empty selection");
  if (text == "all") return s;
  if (text.rfind("every:", 0) == 0) {
    const auto n = ParseInteger(Trimmed(text.substr(6)));
    if (!n || *n < 1) FailSelection(raw, "every:N needs a whole number N >= 1");
    s.kind = FrameSelection::Kind::kEvery;
    s.stride = *n;
    return s;
  }
  const auto colon = text.find(':');
  if (colon != std::string::npos) {
    const std::string a = Trimmed(text.substr(0, colon)), b = Trimmed(text.substr(colon + 1));
    if (a.empty() && b.empty()) FailSelection(raw, "a time range needs at least one of T1, T2");
    s.kind = FrameSelection::Kind::kTimeRange;
    if (!a.empty()) {
      const auto t = ParseNumber(a);
      if (!t) FailSelection(raw, "T1 \"" + a + "\" is not a number of seconds");
      s.from_s = *t;
    }
    if (!b.empty()) {
      const auto t = ParseNumber(b);
      if (!t) FailSelection(raw, "T2 \"" + b + "\" is not a number of seconds");
      s.to_s = *t;
    }
    if (s.from_s > s.to_s)
      FailSelection(raw, "the time range ends (" + FormatNumber(s.to_s) + " s) before it starts (" +
                             FormatNumber(s.from_s) + " s)");
    return s;
  }
  s.kind = FrameSelection::Kind::kList;
  for (const std::string& item : CommaItems(text)) {
    if (item == "first") {
      s.list.push_back(FrameSelection::kFirst);
    } else if (item == "last") {
      s.list.push_back(FrameSelection::kLast);
    } else {
      const auto n = ParseInteger(item);
      if (!n || *n < 0)
        FailSelection(raw, item.empty() ? std::string("empty item in the list")
                                        : "\"" + item + "\" is not a frame number, first or last");
      s.list.push_back(*n);
    }
  }
  return s;
}

std::vector<std::int64_t> SelectFrames(const FrameSelection& selection, const std::vector<std::int64_t>& frames,
                                       const std::function<double(std::int64_t)>& time_of_frame_s,
                                       double tolerance_s) {
  if (frames.empty()) throw InputError("--frames \"" + selection.text + "\": the run has no frames");
  const std::string range = " (the run has " + std::to_string(frames.size()) + " frames, " +
                            std::to_string(frames.front()) + " to " + std::to_string(frames.back()) + ")";
  std::vector<std::int64_t> out;
  switch (selection.kind) {
    case FrameSelection::Kind::kAll:
      out = frames;
      break;
    case FrameSelection::Kind::kEvery:
      for (std::size_t i = 0; i < frames.size(); i += static_cast<std::size_t>(selection.stride))
        out.push_back(frames[i]);
      break;
    case FrameSelection::Kind::kList:
      for (std::int64_t f : selection.list) {
        if (f == FrameSelection::kFirst) f = frames.front();
        if (f == FrameSelection::kLast) f = frames.back();
        if (!std::binary_search(frames.begin(), frames.end(), f))
          throw InputError("--frames \"" + selection.text + "\": frame " + std::to_string(f) +
                           " is not in the run" + range);
        out.push_back(f);
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      break;
    case FrameSelection::Kind::kTimeRange: {
      // Times grow with frame numbers: two binary searches over the frames.
      const auto first_at_or_after = [&](double t, bool inclusive) {
        std::size_t lo = 0, hi = frames.size();
        while (lo < hi) {
          const std::size_t mid = lo + (hi - lo) / 2;
          const double tm = time_of_frame_s(frames[mid]);
          if (inclusive ? tm < t : tm <= t) lo = mid + 1; else hi = mid;
        }
        return lo;
      };
      const std::size_t begin = first_at_or_after(selection.from_s - tolerance_s, true);
      const std::size_t end = first_at_or_after(selection.to_s + tolerance_s, false);
      for (std::size_t i = begin; i < end; ++i) out.push_back(frames[i]);
      if (out.empty())
        throw InputError("--frames \"" + selection.text + "\": no frame lies between " +
                         FormatNumber(selection.from_s) + " s and " + FormatNumber(selection.to_s) +
                         " s (the run covers " + Seconds(time_of_frame_s(frames.front())) + " s to " +
                         Seconds(time_of_frame_s(frames.back())) + " s)");
      break;
    }
  }
  return out;
}

bool RenderOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (output_dir.empty()) return fail("output folder: none given");
  if (width_px < 320 || width_px > 8000)
    return fail("--width: " + std::to_string(width_px) + " px, expected 320 .. 8000");
  if (!(video_fps >= 0.0 && video_fps <= 1000.0))
    return fail("--fps: " + FormatNumber(video_fps) + ", expected 0 (the run's rate) or up to 1000");
  if (!(force_n_per_px >= 0.0 && std::isfinite(force_n_per_px)))
    return fail("--force-scale: " + FormatNumber(force_n_per_px) + " N/px, expected a positive number (0: automatic)");
  if (has_window) {
    const auto finite = [](Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); };
    if (!finite(window_min_m) || !finite(window_max_m) || !(window_min_m.x < window_max_m.x) ||
        !(window_min_m.y < window_max_m.y))
      return fail("--window: (" + FormatNumber(window_min_m.x) + ", " + FormatNumber(window_min_m.y) + ") to (" +
                  FormatNumber(window_max_m.x) + ", " + FormatNumber(window_max_m.y) +
                  ") m, expected finite corners with x0 < x1 and y0 < y1");
  }
  if (!video.empty()) {
    std::string ext = video.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext != ".mp4" && ext != ".avi")
      return fail("--video " + video.string() + ": unknown video format \"" + ext + "\", expected .mp4 or .avi");
  }
  return true;
}

void ParseRenderWindow(const std::string& text, RenderOptions* options) {
  const auto fail = [&](const std::string& why) {
    throw InputError("--window \"" + text + "\": " + why +
                     "; expected x0,y0,x1,y1 in metres, the lower-left and upper-right corners (x0 < x1, y0 < y1)");
  };
  std::vector<double> v;
  for (const std::string& part : CommaItems(text)) {
    const auto x = ParseNumber(part);
    if (!x) fail("\"" + part + "\" is not a number");
    v.push_back(*x);
  }
  if (v.size() != 4) fail(std::to_string(v.size()) + " numbers");
  if (!(v[0] < v[2] && v[1] < v[3])) fail("the corners are not lower-left then upper-right");
  options->has_window = true;
  options->window_min_m = {v[0], v[1]};
  options->window_max_m = {v[2], v[3]};
}

std::filesystem::path FramePicturePath(const std::filesystem::path& dir, std::int64_t frame,
                                       const std::string& extension) {
  char name[64];
  std::snprintf(name, sizeof name, "frame_%06lld%s", static_cast<long long>(frame), extension.c_str());
  return dir / name;
}

OutputKind FramesFolderOutput() {
  return {"a frames folder (frame_NNNNNN.png, .svg and videos only)", true, [](const std::filesystem::path& dir) {
    const std::regex frame_name(R"(frame_[0-9]{6,}\.(png|svg))");
    const OutputKind video = VideoOutputKind();
    return FolderHoldsOnly(dir, [&](const std::filesystem::directory_entry& e) {
      std::error_code ec;
      // With the unfinished pictures of a render that was killed (removed by the next).
      return e.is_regular_file(ec) && (std::regex_match(e.path().filename().string(), frame_name) ||
                                       video.is_previous(e.path()) || IsStalePartial(e.path()));
    });
  }};
}

}  // namespace crowdrecon::viz
