// The venue-design envelope of a sweep (issue 21): over its diagram's two
// axes (e.g. density x counter-flow), per variant, the number of people in
// the danger zone (or another risk column) as the median over seeds with its
// range, and the region where the median stays at or below a stated level.
// Internal to reports; read from DIR/results.sqlite (sweep/results.hpp).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace crowdrecon::reports {

struct EnvelopeCell {
  double x = 0.0, y = 0.0;
  std::vector<double> values;  // one per complete seed
  double median = 0.0, low = 0.0, high = 0.0;
};

struct Envelope {
  std::filesystem::path results;  // the results.sqlite read
  std::string sweep_name, sweep_file, crowdrecon_version;
  std::string x_axis, y_axis, metric;
  double level = 0.0;
  std::vector<double> xs, ys;  // the grid, ascending
  std::map<std::string, std::vector<EnvelopeCell>> variants;  // cells in (y, x) order
  std::size_t runs = 0, failed = 0, without_metric = 0;
};

// True if `dir` is a sweep's folder (holds results.sqlite).
bool IsSweepFolder(const std::filesystem::path& dir);
Envelope ReadEnvelope(const std::filesystem::path& dir, const std::string& metric, double level);
// The design chart of one variant as inline SVG.
std::string EnvelopeSvg(const Envelope& e, const std::string& variant);

}  // namespace crowdrecon::reports
