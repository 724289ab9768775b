#include "crowdrecon/analysis/density_map.hpp"

#include <algorithm>
#include <cmath>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::analysis {

bool DensityMapOptions::IsValid(std::string* error) const {
  if (!(cell_m >= 0.05 && cell_m <= 10.0)) {
    if (error) *error = "cell = " + FormatNumber(cell_m) + " m, expected in [0.05, 10]";
    return false;
  }
  if (!(sigma_m >= 0.05 && sigma_m <= 10.0)) {
    if (error) *error = "kernel width = " + FormatNumber(sigma_m) + " m, expected in [0.05, 10]";
    return false;
  }
  for (double t : times_s)
    if (!std::isfinite(t) || t < 0.0) {
      if (error)
        *error = "time " + FormatNumber(t) + (std::isfinite(t) ? " s" : "") +
                 ", expected a finite time in seconds at or after the start";
      return false;
    }
  return true;
}

DensityMap DensityOf(const std::vector<Vec2>& positions, Vec2 min_m, Vec2 max_m, double cell_m, double sigma_m) {
  DensityMap m;
  m.origin_m = min_m;
  m.cell_m = cell_m;
  m.nx = static_cast<std::size_t>(std::max(1.0, std::ceil((max_m.x - min_m.x) / cell_m)));
  m.ny = static_cast<std::size_t>(std::max(1.0, std::ceil((max_m.y - min_m.y) / cell_m)));
  m.density_per_m2.assign(m.nx * m.ny, 0.0);
  m.people = positions.size();
  // Each person's Gaussian, cut at 3 sigma and normalised over the cells it
  // covers, so that a map integrates to exactly the people inside it.
  const double reach = 3.0 * sigma_m;
  std::vector<std::pair<std::size_t, double>> cells;
  for (Vec2 p : positions) {
    const auto lo_x = static_cast<long>(std::floor((p.x - reach - min_m.x) / cell_m));
    const auto hi_x = static_cast<long>(std::floor((p.x + reach - min_m.x) / cell_m));
    const auto lo_y = static_cast<long>(std::floor((p.y - reach - min_m.y) / cell_m));
    const auto hi_y = static_cast<long>(std::floor((p.y + reach - min_m.y) / cell_m));
    cells.clear();
    double sum = 0.0;
    for (long iy = lo_y; iy <= hi_y; ++iy)
      for (long ix = lo_x; ix <= hi_x; ++ix) {
        const Vec2 c{min_m.x + (double(ix) + 0.5) * cell_m, min_m.y + (double(iy) + 0.5) * cell_m};
        const double w = std::exp(-0.5 * LengthSquared(c - p) / (sigma_m * sigma_m));
        sum += w;
        if (ix >= 0 && iy >= 0 && ix < static_cast<long>(m.nx) && iy < static_cast<long>(m.ny))
          cells.push_back({static_cast<std::size_t>(iy) * m.nx + static_cast<std::size_t>(ix), w});
      }
    if (!(sum > 0.0)) continue;
    for (const auto& [k, w] : cells) m.density_per_m2[k] += w / (sum * cell_m * cell_m);
  }
  for (double d : m.density_per_m2) m.max_per_m2 = std::max(m.max_per_m2, d);
  return m;
}

std::vector<DensityMap> ComputeDensityMaps(const std::filesystem::path& run_file, const DensityMapOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("density maps: " + why);
  if (!runfile::IsRunFile(run_file)) throw InputError(run_file.string() + ": not a crowdrecon run file");
  const runfile::RunFileReader reader(run_file);
  const std::vector<runfile::FrameTime> frames = reader.FrameTimes();
  if (frames.empty()) throw InputError(run_file.string() + ": the run has no frames");
  const std::string venue = reader.venue_json();
  if (venue.empty()) throw InputError(run_file.string() + ": the run file holds no venue (written before format 2)");
  const geometry::Venue v = geometry::ParseVenue(venue, run_file.string() + ": run value venue");
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (const auto& ring : v.walkable_area)
      for (Vec2 p : ring) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
      }
  std::vector<double> times = options.times_s;
  const double t0 = frames.front().time_s, t1 = frames.back().time_s;
  // A time after the run's end would draw its last frame under another time
  // (issue 65); half a frame's interval of rounding is allowed.
  const double half_frame = frames.size() > 1 ? 0.5 * (t1 - t0) / double(frames.size() - 1) : 0.0;
  for (double t : times)
    if (t > t1 + half_frame + 1e-9)
      throw InputError(run_file.string() + ": density map time " + FormatNumber(t) + " s lies after the run's end (" +
                       FormatNumber(t1) + " s); expected times within the run");
  if (times.empty())
    for (int q = 0; q <= 3; ++q) times.push_back(t0 + (t1 - t0) * q / 4.0);
  std::vector<DensityMap> maps;
  for (double t : times) {
    const auto nearest = std::min_element(frames.begin(), frames.end(), [t](const auto& a, const auto& b) {
      return std::abs(a.time_s - t) < std::abs(b.time_s - t);
    });
    const runfile::RunFrame f = reader.Frame(nearest->frame);
    DensityMap m = DensityOf(f.position_m, lo, hi, options.cell_m, options.sigma_m);
    m.time_s = nearest->time_s;
    maps.push_back(std::move(m));
  }
  return maps;
}

}  // namespace crowdrecon::analysis
