// A calibration's summary: its parameters' values, intervals and
// determination from the result (outputs.hpp), and the summary's brief report.
#include "crowdrecon/calibrate/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "crowdrecon/common/error.hpp"
#include "fit.hpp"
#include "outputs.hpp"

namespace crowdrecon::calibrate {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kChi2At95 = 3.841458820694124;  // chi-square, one degree of freedom, 95 %
}  // namespace

void Summarise(const CalibrationSpec& spec, CalibrationResult& r) {
  const std::size_t p = spec.parameters.size();
  Summary& s = r.summary;
  s.chi2 = r.best_simulated_chi2;
  s.degrees_of_freedom = r.objective.DegreesOfFreedom(p);
  s.parameters.clear();
  for (std::size_t i = 0; i < p; ++i) {
    const Parameter& par = spec.parameters[i];
    ParameterResult pr;
    pr.path = par.path;
    pr.value = r.best[i];
    pr.min = par.min;
    pr.max = par.max;
    pr.sigma = r.covariance_ok ? std::sqrt(std::max(0.0, r.covariance[i * p + i])) : kNaN;
    pr.lo95 = pr.value - 1.96 * pr.sigma;
    pr.hi95 = pr.value + 1.96 * pr.sigma;
    std::vector<double> v;
    for (const auto& rep : r.bootstrap) v.push_back(rep[i]);
    if (v.size() >= 2) {
      std::sort(v.begin(), v.end());
      pr.bootstrap_sigma = SampleSd(v);
      std::tie(pr.bootstrap_lo95, pr.bootstrap_hi95) = Percentiles95(v);
    } else {
      pr.bootstrap_sigma = pr.bootstrap_lo95 = pr.bootstrap_hi95 = kNaN;
    }
    if (!r.posterior.samples.empty()) {
      std::vector<double> w;
      for (const auto& x : r.posterior.samples) w.push_back(x[i]);
      std::sort(w.begin(), w.end());
      pr.posterior_sd = SampleSd(w);
      pr.posterior_median = Quantile(w, 0.5);
      pr.posterior_lo68 = Quantile(w, 0.15865);
      pr.posterior_hi68 = Quantile(w, 0.84135);
      pr.posterior_lo95 = Quantile(w, 0.025);
      pr.posterior_hi95 = Quantile(w, 0.975);
    } else {
      pr.posterior_median = pr.posterior_sd = pr.posterior_lo68 = pr.posterior_hi68 = pr.posterior_lo95 =
          pr.posterior_hi95 = kNaN;
    }
    // Determination: the covariance, the bootstrap and the profile each may
    // say that the observations leave the parameter free.
    const double range = par.Range();
    // An end of the range is excluded when its chi2 lies more than 3.84
    // above the profile's lowest in 97.5 % of the seeds' redraws (or, with
    // no redraws, as simulated): a difference within the simulation's
    // noise excludes nothing (docs/calibration.md, "Profiles").
    bool low_excluded = true, high_excluded = true;
    std::string low_end, high_end;  // each end's difference, for the reason
    if (!r.profiles.empty() && r.profiles[i].size() >= 2) {
      const auto excluded = [](const ProfilePoint& q) {
        return (std::isnan(q.delta_lo95) ? q.delta_chi2 : q.delta_lo95) > kChi2At95;
      };
      const auto said = [](const ProfilePoint& q) {
        std::string t = "delta chi2 " + Fixed(q.delta_chi2, 3);
        if (!std::isnan(q.delta_lo95))
          t += ", seeds redrawn " + Fixed(q.delta_lo95, 3) + " to " + Fixed(q.delta_hi95, 3);
        return t;
      };
      low_excluded = excluded(r.profiles[i].front());
      high_excluded = excluded(r.profiles[i].back());
      low_end = said(r.profiles[i].front());
      high_end = said(r.profiles[i].back());
    }
    const bool no_effect = std::find(r.without_effect.begin(), r.without_effect.end(), static_cast<int>(i)) !=
                           r.without_effect.end();
    if (no_effect) {
      // The bootstrap cannot move it either: its spread would look precise.
      pr.sigma = pr.lo95 = pr.hi95 = kNaN;
      pr.bootstrap_sigma = pr.bootstrap_lo95 = pr.bootstrap_hi95 = kNaN;
      pr.determination = "undetermined";
      pr.reason = "no statistic depends on it at the best fit (the surrogate's slope along it is zero): any value in "
                  "the range fits as well";
    } else if (!r.covariance_ok) {
      pr.determination = "undetermined";
      pr.reason = r.covariance_reason;
    } else if (pr.hi95 - pr.lo95 >= range) {
      pr.determination = "undetermined";
      pr.reason = "the 95 % interval from the covariance (" + FormatNumber(pr.lo95) + " to " + FormatNumber(pr.hi95) +
                  ") is wider than the whole range";
    } else if (std::isfinite(pr.bootstrap_sigma) && pr.bootstrap_hi95 - pr.bootstrap_lo95 >= 0.9 * range) {
      pr.determination = "undetermined";
      pr.reason = "the bootstrap's 95 % interval spans most of the range";
    } else if (pr.value <= par.min + 1e-9 * range || pr.value >= par.max - 1e-9 * range) {
      // The best fit on a bound: the observations ask for a value beyond the
      // box, and the covariance's interval, a local quadratic's, says nothing
      // of that side.
      const bool low = pr.value <= par.min + 1e-9 * range;
      pr.determination = "bounded on one side";
      pr.reason = std::string("the best fit lies on the ") + (low ? "lower" : "upper") + " bound of its range (" +
                  FormatNumber(low ? par.min : par.max) + "): the observations ask for a value beyond it";
    } else if (!low_excluded && !high_excluded) {
      pr.determination = "undetermined";
      pr.reason = "the profile is flat: neither end of the range lies beyond chi2_min + 3.84 beyond the seeds' noise "
                  "(low end: " + low_end + "; high end: " + high_end + ")";
    } else if (!low_excluded || !high_excluded) {
      pr.determination = "bounded on one side";
      pr.reason = std::string("the profile excludes only the ") + (low_excluded ? "low" : "high") +
                  " end of the range (" + (low_excluded ? "high end: " + high_end : "low end: " + low_end) +
                  ", within chi2_min + 3.84 or the seeds' noise)";
    } else {
      pr.determination = "determined";
    }
    s.parameters.push_back(pr);
  }
  s.correlation.assign(p, std::vector<double>(p, kNaN));
  if (r.covariance_ok)
    for (std::size_t i = 0; i < p; ++i)
      for (std::size_t k = 0; k < p; ++k)
        if (r.covariance[i * p + i] > 0 && r.covariance[k * p + k] > 0)
          s.correlation[i][k] = r.covariance[i * p + k] / std::sqrt(r.covariance[i * p + i] * r.covariance[k * p + k]);
  s.starts = r.starts.size();
  s.starts_agree = true;
  // Agreement on what the observations determine (an undetermined
  // parameter lies anywhere, and says so).
  for (const StartResult& a : r.starts)
    for (std::size_t i = 0; i < p; ++i) {
      if (s.parameters[i].determination == "undetermined") continue;
      const double tol = std::max(0.02 * spec.parameters[i].Range(),
                                  std::isfinite(s.parameters[i].sigma) ? 1.96 * s.parameters[i].sigma : 0.0);
      if (std::abs(a.found[i] - r.best[i]) > tol) s.starts_agree = false;
    }
}

std::string Summary::BriefReport() const {
  std::string s = "calibration: " + name + " (" + approach + ")\n";
  if (interrupted) return s + "interrupted: run the same command again to continue (the runs done are cached)\n";
  for (const ParameterResult& p : parameters) {
    s += "  " + p.path + " = " + FormatNumber(p.value);
    if (std::isfinite(p.sigma)) s += " +- " + FormatNumber(p.sigma) + " (95 %: " + FormatNumber(p.lo95) + " to " + FormatNumber(p.hi95) + ")";
    s += ": " + p.determination + (p.reason.empty() ? "" : " (" + p.reason + ")") + "\n";
  }
  s += "  chi2 " + FormatNumber(chi2) + " for " + std::to_string(degrees_of_freedom) + " degrees of freedom; " +
       std::to_string(starts) + " start(s), " + (starts_agree ? "agreeing within the 95 % intervals" : "NOT agreeing within the 95 % intervals") + "\n";
  s += "  " + std::to_string(sets_evaluated) + " parameter sets, " + std::to_string(runs) + " runs simulated now; wall time " +
       FormatNumber(std::round(wall_s)) + " s\n";
  s += "  outputs: " + json_file.string() + ", " + report_file.string() + "\n";
  for (const std::string& n : notes) s += "note: " + n + "\n";
  return s;
}

}  // namespace crowdrecon::calibrate
