#include "crowdrecon/observe/trajectories.hpp"

#include <algorithm>
#include <map>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/observe/petrack.hpp"

namespace crowdrecon::observe {

Trajectories ReadTrajectories(const std::filesystem::path& file, double fps_override, const std::string& unit) {
  // SQLite files begin with "SQLite format 3" and a NUL. (A missing or
  // unreadable file goes to the PeTrack reader, whose error names it.)
  if (FileStartsWith(file, std::string("SQLite format 3", 16))) {
    if (!unit.empty() && unit != "m")
      throw InputError(file.string() + ": a SQLite trajectory file is in metres; --unit " + unit + " is for PeTrack text files");
    return ReadJuPedSim(file, fps_override);
  }
  Trajectories t = ReadPeTrack(file, fps_override, unit);
  t.format = "petrack";
  return t;
}

std::vector<Track> TracksOf(const Trajectories& t) {
  std::map<std::uint32_t, std::uint32_t> group_of(t.groups.begin(), t.groups.end());
  std::vector<std::size_t> order(t.points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const TrajectoryPoint &p = t.points[a], &q = t.points[b];
    return p.id != q.id ? p.id < q.id : p.frame < q.frame;
  });
  std::vector<Track> tracks;
  for (std::size_t i : order) {
    const TrajectoryPoint& p = t.points[i];
    if (tracks.empty() || tracks.back().id != p.id) {
      Track track;
      track.id = p.id;
      if (auto g = group_of.find(p.id); g != group_of.end()) track.group = g->second;
      tracks.push_back(std::move(track));
    }
    Track& track = tracks.back();
    if (!track.frame.empty() && track.frame.back() == p.frame)
      throw InputError(t.source + ": person " + std::to_string(p.id) + " has two positions in frame " +
                       std::to_string(p.frame) + "; expected one position per person and frame");
    track.frame.push_back(p.frame);
    track.position_m.push_back(p.position_m);
  }
  return tracks;
}

bool VelocityAt(const Track& track, std::size_t k, int half_span, double fps, const PeriodicBox& box,
                Vec2* velocity_m_per_s) {
  const std::size_t n = track.frame.size();
  if (n < 2 || k >= n || half_span < 1 || !(fps > 0.0)) return false;
  const std::int64_t f = track.frame[k];
  // The farthest points within half_span frames either side (a gap leaves
  // fewer points on that side).
  std::size_t lo = k, hi = k;
  while (lo > 0 && f - track.frame[lo - 1] <= half_span) --lo;
  while (hi + 1 < n && track.frame[hi + 1] - f <= half_span) ++hi;
  if (lo == hi) {  // isolated by gaps on both sides: the nearest neighbour
    if (k + 1 < n) hi = k + 1;
    else lo = k - 1;
  }
  const double dt = static_cast<double>(track.frame[hi] - track.frame[lo]) / fps;
  Vec2 d = track.position_m[hi] - track.position_m[lo];
  if (box.any()) {
    // Sum of the minimum-image steps (a span may cross a seam).
    d = {0.0, 0.0};
    for (std::size_t i = lo; i < hi; ++i) d = d + box.MinimumImage(track.position_m[i + 1] - track.position_m[i]);
  }
  *velocity_m_per_s = d * (1.0 / dt);
  return true;
}

}  // namespace crowdrecon::observe
