// What the recordings determine, and what more would (issue 41, point 4;
// docs/calibration.md, "How much footage"): each parameter's expected
// interval for N recordings of T seconds of the kind the calibration used,
// from the seeds' covariance of the statistics and the surrogate's Jacobian
// at the best fit, and which statistics carry the information (internal to
// calibrate/).
#pragma once

#include <string>
#include <vector>

#include "fit.hpp"

namespace crowdrecon::calibrate {

struct FootageOptions {
  std::vector<int> recordings{1, 2, 4, 8, 16, 32};
  std::vector<double> lengths_s;  // empty: multiples 1/2, 1, 2, 4, 8, 16, 32 of the calibrated recording (whole windows)
  double seeds = 0.0;             // K of the simulated means; 0: as many as make their error negligible (footage alone)
  std::vector<double> targets{0.2, 0.1};  // the 95 % half-widths, as fractions of the value, to say the footage for
};

// One design: N recordings of T seconds each.
struct FootageRow {
  int recordings = 1;
  double length_s = 0.0;
  std::vector<double> sd;  // per parameter, its units (NaN: not determined by these statistics)
};

struct FootageDesign {
  std::string note;             // why there is none (empty when there is)
  double window_s = 0.0;        // the series' window
  double recording_s = 0.0;     // the calibrated recording's length (its windows)
  std::size_t windows = 0;      // ... in windows
  std::vector<std::string> kinds;      // the statistics' kinds used: "speed hallway forward", "stops hallway backward (count)"
  std::vector<std::string> left_out;   // statistics not used, with the reason
  std::vector<FootageRow> rows;        // recordings x lengths
  // The calibration itself as a design: its recordings of the first one's
  // kind (every statistic reads one of the first's simulated values), with
  // its K seeds: the spread its fitted values should have over replicates.
  int recordings_now = 1;
  std::vector<double> sd_now;
  std::vector<double> targets;  // the 95 % half-widths (fractions of the value) said for, as asked
  // Per target, per parameter: the seconds of one recording, and the number
  // of recordings of the calibrated length, that give that 95 % half-width
  // (inf: never, with these statistics; NaN: no value to be relative to).
  std::vector<std::vector<double>> one_recording_s;
  std::vector<std::vector<double>> recordings_needed;
  // Which statistics carry the information: per kind, per parameter, the
  // share of the parameter's precision (1 / variance) lost without that kind
  // (one recording of the calibrated length; 0: none of it, 1: all of it).
  std::vector<std::vector<double>> share_lost;
  // Per kind, per parameter: the Fisher information's diagonal share.
  std::vector<std::vector<double>> information_share;
};

// The design from the calibration's objective (its statistics, the seeds'
// covariance S, the observed values' own uncertainties), the Jacobian of the
// simulated means at the best fit (statistics x parameters, row-major, the
// parameters' units; NaN rows: not fitted) and the best fit's values.
// Assumptions (docs/calibration.md): the first recording's kind is the kind
// of footage; its series are stationary over the recording (every window has
// the windows' mean Jacobian and the covariance depends only on the lag);
// beyond the calibrated length the information grows with the windows'
// long-run covariance (Newey-West: the lags' covariances summed with Bartlett
// weights); event counts grow in mean and variance with the length and are
// independent of the series.
FootageDesign DesignFootage(const Objective& objective, const std::vector<double>& jacobian,
                            const std::vector<double>& best, const FootageOptions& options);

// The parameters' covariance (p x p, row-major) of N recordings of the first
// recording's kind, `windows` windows long (its own length or longer), with
// simulated means of K seeds (0: exact); NaN where not determined. Exposed
// for the tests.
std::vector<double> FootageCovariance(const Objective& objective, const std::vector<double>& jacobian,
                                      std::size_t parameters, int recordings, double windows, double seeds);

}  // namespace crowdrecon::calibrate
