// Passages through a line and the time lapses between them: avalanches and
// clogs measured as the field measures them at bottlenecks (I. Zuriguel et al.,
// "Clogging transition of many-particle systems flowing through bottlenecks",
// Sci. Rep. 4:7324, 2014). A clog is a lapse between consecutive passages
// longer than a threshold; an avalanche (burst) is the passages between two
// clogs; the state shows in the tail of the lapse distribution, p(t) ~ t^-alpha:
// for alpha <= 2 the mean lapse diverges, i.e. the flow is clogged, for
// alpha > 2 it has a finite mean, i.e. it flows (intermittently or not).
//
// The analysis applies this per direction of travel: the passage times of
// one group through the measurement line along its own desired direction
// (run_analysis.hpp); definitions and the reasons for every number are in
// docs/analysis.md, "Passages, lapses and bursts".
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace crowdrecon::analysis {

struct PassageOptions {
  // A lapse longer than this is a clog (s): three relaxation times of the
  // model (tau = 2/3 s, paper), the same as the shortest stop of the speed
  // based detector (RegimeOptions::min_stop_duration_s); at the hallway's
  // flows (1-2 persons/(m s) through a 3 m line) it is 6-12 typical lapses.
  double clog_lapse_s = 2.0;
  // Lower end of the tail fitted with a power law (s): 1.5 relaxation times,
  // about three typical lapses at 1 person/(m s) through 3 m, so that the
  // fit sees the lapses of interrupted flow, not of the steady stream.
  double tail_from_s = 1.0;
  // Fewest lapses in the tail for an exponent (below it: NaN); the maximum
  // likelihood estimate has a relative error of about 1/sqrt(n).
  std::size_t min_tail_lapses = 10;

  bool IsValid(std::string* error) const;
};

struct PassageStatistics {
  std::size_t passages = 0;        // in the observation window
  std::vector<double> lapses_s;    // between consecutive passages, in order
  double median_lapse_s = 0.0;     // NaN if fewer than two passages
  double mean_lapse_s = 0.0;       // NaN if fewer than two passages
  double max_lapse_s = 0.0;        // NaN if fewer than two passages
  // From the last passage (the window's start if none) to the window's end:
  // a lapse still open when the observation ended (censored, so not in
  // lapses_s nor in the fit); a frozen run ends with a long one.
  double open_lapse_s = 0.0;
  int clogs = 0;                   // lapses longer than clog_lapse_s (the open one included)
  double clogged_fraction = 0.0;   // time in clogs / observed time
  // Passages of each burst bounded by clogs on both sides (a burst cut by
  // the window's start, or by its end without a clog, is left out).
  std::vector<int> burst_sizes;
  double mean_burst_size = 0.0;    // NaN if no bounded burst
  // p(t) ~ t^-alpha over lapses t >= tail_from_s, maximum likelihood
  // (A. Clauset, C. R. Shalizi, M. E. J. Newman, SIAM Rev. 51:661, 2009):
  //   alpha = 1 + n / sum ln(t_i / t_min),   standard error (alpha - 1)/sqrt(n).
  std::size_t tail_lapses = 0;
  double tail_exponent = 0.0;       // NaN if fewer than min_tail_lapses
  double tail_exponent_error = 0.0;  // NaN with it
};

// `passage_times_s` (any order; sorted here) inside [from_s, to_s] are used,
// others ignored. Throws InputError if the options or the window are invalid.
PassageStatistics AnalyzePassages(std::vector<double> passage_times_s, double from_s, double to_s,
                                  const PassageOptions& options);

}  // namespace crowdrecon::analysis
