// Internal: the binned accumulation shared by every source of observations
// (trajectories and footage), so that both define their series the same way.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "crowdrecon/observe/observation.hpp"

namespace crowdrecon::observe::detail {

class SeriesBuilder {
 public:
  // `sample_area_m2`: the floor one sample stands for (trajectories: the
  // spec's person area; footage: a grid cell). The samples within one
  // person's area count as one independent sample in standard errors.
  // `bins` = 0: as many as the samples need (a video whose length is not
  // known in advance); else a fixed number.
  SeriesBuilder(const ObservationSpec& spec, double t0_s, std::size_t bins, double sample_area_m2);

  // The bin of a time; kNoBin before t0 (and, with a fixed number, after the last).
  static constexpr std::size_t kNoBin = static_cast<std::size_t>(-1);
  std::size_t Bin(double t_s) const;
  std::size_t bins() const { return bins_; }
  // A velocity sample (along the axis, m/s) in region r, bin b.
  void AddSample(std::size_t r, std::size_t b, double v_axis_m_per_s);
  // One frame seen in bin b (every region), with `count` people in region r
  // (trajectories only; footage passes counts = nullptr).
  void AddFrame(std::size_t b, const std::vector<double>* counts);
  // A crossing of line l in bin b: +1 forward, -1 backward.
  void AddCrossing(std::size_t l, std::size_t b, int direction);
  // Fills observation.series and events. `with_density`, `with_flow`: the
  // source can tell them. `onset_uncertainty_s` goes to every event.
  void Finish(Observation* observation, bool with_density, bool with_flow, double onset_uncertainty_s) const;

 private:
  struct Cell {
    double n = 0;                      // samples
    double n_fwd = 0, n_bwd = 0;       // movers
    double s_fwd = 0, ss_fwd = 0;      // sums of speed and its square
    double s_bwd = 0, ss_bwd = 0;
    double s_all = 0, ss_all = 0;      // v.axis over every sample
    double count = 0, count_sq = 0;    // people in the region, summed over frames
    double top = 0;                    // the largest |v.axis| of the bin's samples
  };
  void Grow(std::size_t b);
  const ObservationSpec& spec_;
  double t0_s_;
  std::size_t bins_;
  bool growable_;
  double sample_area_m2_;
  double correlated_;
  std::vector<std::vector<Cell>> cells_;     // [region][bin]
  std::vector<double> frames_;               // frames per bin
  std::vector<std::vector<double>> fwd_, bwd_;  // [line][bin] crossings
};

}  // namespace crowdrecon::observe::detail
