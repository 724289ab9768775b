// Density maps of a run: persons per square metre over the venue at chosen
// times (issue 20: the evacuation's density maps), each person spread as a
// normalised Gaussian of width sigma (the classic kernel estimate; the
// integral of a map is the number of people present).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::analysis {

struct DensityMap {
  double time_s = 0.0;
  std::size_t people = 0;
  Vec2 origin_m;         // lower-left corner of cell (0, 0)
  double cell_m = 0.5;
  std::size_t nx = 0, ny = 0;
  std::vector<double> density_per_m2;  // row-major, index iy * nx + ix
  double max_per_m2 = 0.0;
  double At(std::size_t ix, std::size_t iy) const { return density_per_m2[iy * nx + ix]; }
};

struct DensityMapOptions {
  std::vector<double> times_s;  // empty: the start and the quarters of the run
  double cell_m = 0.5;
  double sigma_m = 0.5;         // kernel width: about the spacing of people at 4 /m2
  bool IsValid(std::string* error) const;
};

// The maps at the frames nearest each time, over the bounding box of the
// run's venue (its walkable area). Throws InputError for a file that is not
// a run, or a run without frames.
std::vector<DensityMap> ComputeDensityMaps(const std::filesystem::path& run_file, const DensityMapOptions& options);

// The same from positions (for tests and callers with their own frames).
DensityMap DensityOf(const std::vector<Vec2>& positions, Vec2 min_m, Vec2 max_m, double cell_m, double sigma_m);

}  // namespace crowdrecon::analysis
