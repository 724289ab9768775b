// Stops and surges in a speed series, by a two-state CUSUM change detector
// (E. S. Page, "Continuous inspection schemes", Biometrika 41:100, 1954):
// the series is "moving" or "stopped"; in either state the detector sums the
// evidence for the other one,
//   moving:  G <- max(0, G + (v_ref - v) dt)      (distance not walked below v_ref)
//   stopped: G <- max(0, G + (v - v_ref) dt)      (distance walked beyond v_ref)
// and declares the change when G exceeds h (m); the change's onset is the
// start of the excursion that crossed h (the last time G was 0), Page's own
// estimate of the change point. A threshold in metres reads plainly: the
// crowd must have walked h more (or less) than at the reference speed.
// A stop shorter than min_stop_s is dropped (merged into the motion around
// it); a surge is the motion that follows a stop: an avalanche's onset.
// Definitions and the reasons for the numbers: docs/observations.md.
#pragma once

#include <string>
#include <vector>

namespace crowdrecon::observe {

struct EventOptions {
  // Speed between stopped and moving (m/s): the analysis' stop threshold
  // 0.1 m/s (a tenth of the desired speed) and a bursting crowd's 0.2-0.3
  // m/s (issue 19's releases) on either side.
  double reference_speed_m_per_s = 0.15;
  // CUSUM threshold (m): a tenth of a metre, a third of a body depth: a
  // crowd at 0.3 m/s crosses it in 0.7 s, noise of 0.05 m/s about the
  // reference needs 2 s of one sign to.
  double threshold_m = 0.1;
  // Shortest stop kept (s): 1.5 relaxation times of the model (tau = 2/3 s);
  // shorter dips are steps in a moving crowd.
  double min_stop_s = 1.0;

  bool IsValid(std::string* error) const;
};

struct Event {
  std::string kind;       // "stop" or "surge"
  std::string where;      // region name
  std::string direction;  // forward, backward or all
  double time_s = 0.0;    // onset
  double uncertainty_s = 0.0;
  // Stop: when motion resumed (the next surge's onset); surge: when it
  // stopped again. NaN if the series ended first.
  double end_s = 0.0;
  // True when the stop began before the series did (its onset is the
  // series' start, not an observed onset).
  bool censored = false;
  // Surges: the highest speed before the next stop, and the time from the
  // onset to first reaching 90 % of it.
  double peak_speed_m_per_s = 0.0;
  double rise_time_s = 0.0;
};

// `time_s` are the bins' start times (equally spaced by bin_s), `speed` the
// series (NaN bins are skipped: they add no evidence). `time_uncertainty_s`
// is given to every onset (the caller knows its bins and velocity span).
std::vector<Event> DetectEvents(const std::vector<double>& time_s, const std::vector<double>& speed, double bin_s,
                                double time_uncertainty_s, const EventOptions& options, const std::string& where,
                                const std::string& direction);

}  // namespace crowdrecon::observe
