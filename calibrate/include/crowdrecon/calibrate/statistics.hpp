// The statistics a calibration compares: numbers computed alike from an
// observation file and from every simulated run's observation (the same
// observe::ObserveTrajectories with the observation's own spec), one per
// window of a matched series and one per checkpoint of matched events
// (docs/calibration.md, "Statistics").
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/observe/observation.hpp"

namespace crowdrecon::calibrate {

struct Statistic {
  std::string name;        // "obs0 speed hallway forward [5, 30) s", "obs0 stop hallway forward count at 12.4 s"
  std::string unit;
  std::size_t observation = 0;  // index into CalibrationSpec::observations
  bool is_count = false;        // an event count (else a series' window mean, or largest bin)
  bool is_max = false;          // a series' largest bin in the window (SeriesMatch::take_max)
  bool is_time = false;         // the first onset's time in the window, its end if none (EventMatch::first_time)
  std::string quantity;         // the series' quantity, or the events' kind
  std::string where, direction;
  double from_s = 0.0, to_s = 0.0;  // window (series) or [from, checkpoint] (counts), observed clock
  double sim_from_s = 0.0, sim_to_s = 0.0;  // the same on the run's clock
  // What the simulated value is computed from: the observation spec the runs
  // are observed with ("" for statistics built by hand). Statistics of
  // several recordings with the same spec, quantity, place, direction,
  // reduction and simulated window read one simulated value (fit.hpp).
  std::string simulated_from;
  double observed = 0.0;
  // The observed value's own uncertainty: the standard error of the window's
  // mean from its bins' (independent bins assumed), plus the match's
  // relative error, in quadrature; for counts, half an event.
  double observed_sigma = 0.0;
};

// Every statistic of the calibration, observed values included. Throws
// InputError naming the calibration file, the match and the series when a
// matched series is missing from the observation or a window holds no value.
std::vector<Statistic> ObservedStatistics(const CalibrationSpec& spec);

// The values of `statistics` (of observation `index` only; others NaN) in a
// simulated run's observation, over their simulated windows (the observed
// ones shifted by the observation's time offset, or the match's own). NaN
// where a window holds no value.
void SimulatedStatistics(std::size_t index, const observe::Observation& simulated,
                         const std::vector<Statistic>& statistics, std::vector<double>* values);

// A run's observation as a calibration keeps it (DIR/cache/KEY/seedN-TAG.json,
// read instead of running that set again): its bins, series and events.
// Throws InputError naming the file, and saying to delete it, if it is damaged.
observe::Observation ReadCachedObservation(const std::filesystem::path& file);

}  // namespace crowdrecon::calibrate
