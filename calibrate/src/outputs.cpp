#include "outputs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "crowdrecon/viz/chart.hpp"

namespace crowdrecon::calibrate {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

namespace {

// Where a statistic stands on the time axis of the fit figure: a count at
// its checkpoint, a recorded event's time at that time, a window at its
// middle.
double WhereOnTheClock(const Statistic& st) {
  return st.is_count ? st.to_s : st.is_time ? st.observed : 0.5 * (st.from_s + st.to_s);
}

// Every how many posterior samples one goes into posterior.csv.
constexpr std::size_t kPosteriorFileEvery = 5;

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json Values(const CalibrationSpec& spec, const std::vector<double>& v) {
  json o = json::object();
  for (std::size_t i = 0; i < v.size(); ++i) o[spec.parameters[i].path] = Num(v[i]);
  return o;
}

// A value per parameter, by path.
json ByParameter(const CalibrationSpec& spec, const std::vector<double>& v) {
  json o = json::object();
  for (std::size_t i = 0; i < spec.parameters.size() && i < v.size(); ++i) o[spec.parameters[i].path] = Num(v[i]);
  return o;
}

json FootageJson(const CalibrationSpec& spec, const FootageDesign& f) {
  if (!f.note.empty()) return {{"note", f.note}};
  json rows = json::array();
  for (const FootageRow& row : f.rows) rows.push_back({{"recordings", row.recordings}, {"length_s", row.length_s}, {"sd", ByParameter(spec, row.sd)}});
  json needed = json::array();
  for (std::size_t t = 0; t < f.one_recording_s.size(); ++t)
    needed.push_back({{"half_width_95_fraction", f.targets[t]},
                      {"one_recording_s", ByParameter(spec, f.one_recording_s[t])},
                      {"recordings_of_this_length", ByParameter(spec, f.recordings_needed[t])}});
  json kinds = json::array();
  for (std::size_t g = 0; g < f.kinds.size(); ++g)
    kinds.push_back({{"kind", f.kinds[g]}, {"precision_lost_without", ByParameter(spec, f.share_lost[g])},
                     {"information_share_alone", ByParameter(spec, f.information_share[g])}});
  return {{"window_s", f.window_s}, {"recording_s", f.recording_s}, {"windows", f.windows},
          {"seeds", "enough (the footage alone limits)"}, {"kinds", kinds}, {"left_out", f.left_out},
          {"designs", rows}, {"needed", needed},
          {"this_calibration", {{"recordings", f.recordings_now}, {"sd", ByParameter(spec, f.sd_now)}}}};
}

json ToJson(const Evaluator& ev, const CalibrationResult& r) {
  const CalibrationSpec& spec = *r.spec;
  const Summary& s = r.summary;
  json j;
  j["format"] = "crowdrecon-calibration-result";
  j["version"] = 1;
  j["name"] = spec.name;
  j["calibration_file"] = spec.file.string();
  j["approach"] = s.approach;
  j["seeds"] = spec.base.seeds;
  json params = json::array();
  for (std::size_t i = 0; i < s.parameters.size(); ++i) {
    const ParameterResult& p = s.parameters[i];
    params.push_back({{"path", p.path}, {"value", Num(p.value)}, {"min", p.min}, {"max", p.max},
                      {"start", spec.parameters[i].start}, {"sigma", Num(p.sigma)},
                      {"ci95", {Num(p.lo95), Num(p.hi95)}}, {"bootstrap_sigma", Num(p.bootstrap_sigma)},
                      {"bootstrap_ci95", {Num(p.bootstrap_lo95), Num(p.bootstrap_hi95)}},
                      {"relative_half_width_95", Num(p.RelativeHalfWidth95())},
                      {"posterior", {{"median", Num(p.posterior_median)}, {"sd", Num(p.posterior_sd)},
                                     {"ci68", {Num(p.posterior_lo68), Num(p.posterior_hi68)}},
                                     {"ci95", {Num(p.posterior_lo95), Num(p.posterior_hi95)}}}},
                      {"determination", p.determination}, {"reason", p.reason}});
  }
  j["parameters"] = params;
  json corr = json::array();
  for (const auto& row : s.correlation) {
    json jr = json::array();
    for (double v : row) jr.push_back(Num(v));
    corr.push_back(jr);
  }
  j["correlation"] = corr;
  j["covariance"] = r.covariance_ok ? json(r.covariance) : json(nullptr);
  j["covariance_note"] = r.covariance_ok ? "" : r.covariance_reason;
  j["chi2"] = Num(s.chi2);
  j["degrees_of_freedom"] = s.degrees_of_freedom;
  j["surrogate"] = {{"form", r.surrogate_form}};
  {
    const auto& post = r.posterior;
    json rh = json::array();
    for (double v : post.r_hat) rh.push_back(Num(v));
    j["posterior"] = {{"prior", "flat over each parameter's bounds"},
                      {"surrogate", post.samples.empty() ? json(nullptr) : json(post.surrogate_form + " over every set evaluated")},
                      {"sets", post.sets}, {"overdispersion_scale", post.scale},
                      {"bandwidth", std::isfinite(post.bandwidth) ? json(post.bandwidth) : json("whole box")},
                      {"seed_functions", post.seed_functions},
                      {"likelihood", post.likelihood_power > 0
                                         ? json{{"form", "(1 + chi2 / freedom)^(-power/2): the seeds' covariance estimated (Percival et al. 2022)"},
                                                {"freedom", Num(r.seed_correlation.freedom)}, {"power", Num(post.likelihood_power)}}
                                         : json{{"form", "exp(-chi2/2): the seeds' covariance taken as known"}}},
                      {"bandwidth_leave_one_out_scores", [&] {
                         json a = json::array();
                         for (double v : post.bandwidth_scores) a.push_back(Num(v));
                         return a;
                       }()},
                      {"chains", post.chains},
                      {"steps_per_chain", spec.options.posterior_steps},
                      {"samples", post.samples.size()}, {"acceptance", Num(post.acceptance)}, {"r_hat", rh},
                      {"samples_file", post.samples.empty() ? json(nullptr) : json("posterior.csv")},
                      {"samples_file_every", kPosteriorFileEvery},
                      {"note", post.note}};
  }
  json starts = json::array();
  for (const StartResult& st : r.starts)
    starts.push_back({{"start", Values(spec, st.start)}, {"found", Values(spec, st.found)},
                      {"surrogate_chi2", Num(st.surrogate_chi2)}, {"simulated_chi2", Num(st.simulated_chi2)},
                      {"ceres", st.termination}});
  j["starts"] = starts;
  j["starts_agree"] = s.starts_agree;
  json noise = json::array();
  for (const NoiseResult& n : r.noise)
    noise.push_back({{"parameter", n.parameter}, {"step", n.step}, {"chi2_scatter", Num(n.chi2_noise_sd)},
                     {"residual_scatter", Num(n.residual_noise_sd)}, {"gradient_step_signal_to_noise", Num(n.slope_signal)}});
  j["noise"] = noise;
  j["seed_correlation"] = {{"values", r.seed_correlation.values}, {"pooled_over_sets", r.seed_correlation.sets},
                           {"shrinkage", Num(r.seed_correlation.shrinkage)},
                           {"effective_independent_values", Num(r.seed_correlation.effective_values)},
                           {"degrees_of_freedom", Num(r.seed_correlation.freedom)}};
  json stats = json::array();
  for (std::size_t k = 0; k < r.objective.statistics.size(); ++k) {
    const Statistic& st = r.objective.statistics[k];
    stats.push_back({{"name", st.name}, {"unit", st.unit}, {"observed", Num(st.observed)},
                     {"observed_sigma", Num(st.observed_sigma)}, {"seed_sd", Num(r.objective.seed_sd[k])},
                     {"sigma", Num(r.objective.sigma[k])}, {"simulated_at_best", Num(r.best_set.mean[k])},
                     {"simulated_sd_at_best", Num(r.best_set.sd[k])},
                     {"residual_at_best", Num((r.best_set.mean[k] - st.observed) / r.objective.sigma[k])},
                     {"surrogate_rms", k < r.surrogate_rms.size() ? Num(r.surrogate_rms[k]) : json(nullptr)},
                     {"posterior_lack_of_fit_sd", k < r.posterior.lack_of_fit_sd.size()
                                                      ? Num(r.posterior.lack_of_fit_sd[r.objective.lead[k]])
                                                      : json(nullptr)}});
  }
  j["statistics"] = stats;
  json profiles = json::object();
  for (std::size_t i = 0; i < r.profiles.size(); ++i) {
    json pts = json::array();
    for (const ProfilePoint& q : r.profiles[i])
      pts.push_back({{"value", Num(q.value)}, {"values", Values(spec, q.values)}, {"chi2", Num(q.chi2)},
                     {"surrogate_chi2", Num(q.surrogate_chi2)}, {"delta_chi2", Num(q.delta_chi2)},
                     {"delta_chi2_seeds_95", {Num(q.delta_lo95), Num(q.delta_hi95)}}});
    profiles[spec.parameters[i].path] = pts;
  }
  j["profiles"] = profiles;
  j["footage"] = FootageJson(spec, r.footage);
  j["profiles_refitted"] = r.profiles_refitted;
  json evals = json::array();
  for (const SetResult* e : ev.All())
    evals.push_back({{"key", e->key}, {"stage", e->stage}, {"values", Values(spec, e->values)},
                     {"chi2", Num(r.objective.Chi2(e->mean))}, {"failed_seeds", e->failures}});
  j["evaluations"] = evals;
  j["sets_evaluated"] = s.sets_evaluated;
  j["runs_simulated_now"] = s.runs;
  j["wall_s"] = s.wall_s;
  return j;
}

// A percentage for a reader: whole percents from 10 on (not "2.7e+02").
std::string Percent(double percent) {
  return percent >= 10.0 ? std::to_string(std::lround(percent)) : Fixed(percent, 2);
}

// A duration for a reader: seconds, minutes or hours.
std::string Duration(double seconds) {
  if (!std::isfinite(seconds)) return "more than any footage";
  const auto number = [](double v) { return v >= 10.0 ? std::to_string(std::lround(v)) : Fixed(v, 2); };
  if (seconds < 120.0) return number(seconds) + " s";
  if (seconds < 7200.0) return number(seconds / 60.0) + " min";
  return number(seconds / 3600.0) + " h";
}

// "How much footage": what the calibrated kind of recording determines, and
// how much of it each parameter needs.
std::string FootageReport(const CalibrationSpec& spec, const CalibrationResult& r) {
  const FootageDesign& f = r.footage;
  std::ostringstream o;
  if (!f.note.empty()) {
    o << "\nHow much footage: no design (" << f.note << ")\n";
    return o.str();
  }
  const std::vector<double>& targets = f.targets;
  o << "\nHow much footage (expected 95 % half-widths, linearised at the best fit, for recordings of the first one's kind: "
    << FormatNumber(f.recording_s) << " s in " << f.windows << " windows of " << FormatNumber(f.window_s)
    << " s; with enough seeds that the footage alone limits; docs/calibration.md, \"How much footage\"):\n";
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    const std::string& path = spec.parameters[i].path;
    const double value = r.best[i];
    const double now = f.rows.empty() ? std::nan("") : [&] {
      for (const FootageRow& row : f.rows)
        if (row.recordings == 1 && std::abs(row.length_s - f.recording_s) < 1e-9) return row.sd[i];
      return std::nan("");
    }();
    o << "  " << path << ": one recording like this one gives +-"
      << (std::isfinite(now) && value != 0.0 ? Percent(100.0 * 1.96 * now / std::abs(value)) + " %" : std::string("- (undetermined)"));
    if (std::isfinite(now) && 1.96 * now > 0.5 * spec.parameters[i].Range())
      o << " (wider than its range: the bounds, not the footage, hold it)";
    for (std::size_t t = 0; t < targets.size() && t < f.one_recording_s.size(); ++t) {
      const double one = f.one_recording_s[t][i], many = f.recordings_needed[t][i];
      o << "; to know it within +-" << std::lround(100.0 * targets[t]) << " %: " << Duration(one)
        << " of one recording";
      if (std::isfinite(many))
        o << ", or " << FormatNumber(many) << (many == 1.0 ? " recording" : " recordings") << " like this one ("
          << Duration(many * f.recording_s) << ")";
    }
    o << "\n";
  }
  o << "  What carries the information (the share of each parameter's precision lost without that kind of statistic):\n";
  for (std::size_t g = 0; g < f.kinds.size(); ++g) {
    o << "    " << f.kinds[g] << ":";
    for (std::size_t i = 0; i < spec.parameters.size(); ++i)
      o << " " << spec.parameters[i].name << " " << Percent(100.0 * f.share_lost[g][i]) << " %";
    o << "\n";
  }
  for (const std::string& why : f.left_out) o << "  Left out of the design: " << why << "\n";
  return o.str();
}

std::string Report(const CalibrationResult& r) {
  const CalibrationSpec& spec = *r.spec;
  const Summary& s = r.summary;
  std::ostringstream o;
  o << "Calibration: " << spec.name << "\n";
  o << "Approach: " << s.approach << "; " << spec.base.seeds.size() << " seeds per parameter set (the same at every set); "
    << r.objective.statistics.size() << " statistics from " << spec.observations.size() << " observation file(s)\n\n";
  o << "Best fit (95 % intervals: Ceres' covariance at the optimum | the seed-and-observation bootstrap):\n";
  for (const ParameterResult& p : s.parameters) {
    o << "  " << p.path << " = " << Fixed(p.value, 4) << "   [" << Fixed(p.lo95) << ", " << Fixed(p.hi95) << "] | ["
      << Fixed(p.bootstrap_lo95) << ", " << Fixed(p.bootstrap_hi95) << "]   range [" << FormatNumber(p.min) << ", "
      << FormatNumber(p.max) << "]: " << p.determination;
    if (p.determination != "undetermined" && std::isfinite(p.RelativeHalfWidth95())) {
      o << " to +-" << Percent(100.0 * p.RelativeHalfWidth95()) << " % (95 %)";
    }
    if (!p.reason.empty()) o << " (" << p.reason << ")";
    o << "\n";
  }
  if (!r.posterior.samples.empty()) {
    o << "\nPosterior (a flat prior over the bounds; " << r.posterior.surrogate_form << " over all "
      << r.posterior.sets << " sets, its lack of fit counted; chi2 divided by "
      << Fixed(r.posterior.scale, 3) << " for overdispersion; "
      << (r.posterior.likelihood_power > 0
              ? "the seeds' covariance estimated on " + Fixed(r.seed_correlation.freedom) +
                    " degrees of freedom: likelihood (1 + chi2/" + Fixed(r.seed_correlation.freedom) + ")^(-" +
                    Fixed(r.posterior.likelihood_power) + "/2); "
              : std::string())
      << r.posterior.chains << " chains, "
      << r.posterior.samples.size() << " samples, acceptance " << Fixed(r.posterior.acceptance, 2)
      << "): median, 68 % and 95 % intervals\n";
    for (std::size_t i = 0; i < s.parameters.size(); ++i) {
      const ParameterResult& p = s.parameters[i];
      o << "  " << p.path << " = " << Fixed(p.posterior_median, 4) << "   68 % [" << Fixed(p.posterior_lo68) << ", "
        << Fixed(p.posterior_hi68) << "]   95 % [" << Fixed(p.posterior_lo95) << ", " << Fixed(p.posterior_hi95)
        << "]   R-hat " << Fixed(i < r.posterior.r_hat.size() ? r.posterior.r_hat[i] : std::nan(""), 4) << "\n";
    }
  } else if (!r.posterior.note.empty()) {
    o << "\nNo posterior: " << r.posterior.note << "\n";
  }
  o << FootageReport(spec, r);
  if (s.parameters.size() > 1 && r.covariance_ok) {
    o << "\nCorrelations:\n";
    for (std::size_t i = 0; i < s.parameters.size(); ++i) {
      o << "  ";
      for (double c : s.correlation[i]) o << Fixed(c, 2) << "\t";
      o << spec.parameters[i].name << "\n";
    }
  }
  o << "\nchi2 at the best fit (simulated): " << Fixed(s.chi2, 4) << " for " << s.degrees_of_freedom
    << " degrees of freedom\n";
  o << "\nStarts (" << (s.starts_agree ? "they agree within the 95 % intervals (2 % of the range at least)" : "they do NOT agree within the 95 % intervals") << "; an undetermined parameter may lie anywhere):\n";
  for (const StartResult& st : r.starts) {
    o << "  from";
    for (double v : st.start) o << " " << FormatNumber(v);
    o << " -> ";
    for (double v : st.found) o << " " << Fixed(v, 4);
    o << "   chi2 " << Fixed(st.simulated_chi2, 4) << "\n";
  }
  if (!r.noise.empty()) {
    o << "\nNoise of the objective (sets " << FormatNumber(spec.options.noise_step) << " of the range apart):\n";
    for (const NoiseResult& n : r.noise)
      o << "  " << n.parameter << ": chi2 scatters by " << Fixed(n.chi2_noise_sd) << ", residuals by "
        << Fixed(n.residual_noise_sd) << "; a central difference over the gradient step sees "
        << Fixed(n.slope_signal) << " times the residuals' scatter (median over statistics)\n";
  }
  if (r.seed_correlation.values > 0)
    o << "\nThe seeds' covariance (pooled over " << r.seed_correlation.sets << " sets): "
      << r.seed_correlation.values << " simulated values, their correlations shrunk by "
      << Fixed(r.seed_correlation.shrinkage, 2) << ", as informative as "
      << Fixed(r.seed_correlation.effective_values, 2) << " independent ones, estimated on "
      << Fixed(r.seed_correlation.freedom) << " degrees of freedom; chi2 is the generalised one\n";
  o << "\nStatistics at the best fit (observed +- its sigma | simulated mean +- seed sd | residual alone):\n";
  for (std::size_t k = 0; k < r.objective.statistics.size(); ++k) {
    const Statistic& st = r.objective.statistics[k];
    o << "  " << st.name << ": " << Fixed(st.observed) << " +- " << Fixed(st.observed_sigma) << " | "
      << Fixed(r.best_set.mean[k]) << " +- " << Fixed(r.best_set.sd[k]) << " | "
      << Fixed((r.best_set.mean[k] - st.observed) / r.objective.sigma[k], 2) << "\n";
  }
  o << "\n" << s.sets_evaluated << " parameter sets evaluated (" << s.runs << " runs simulated by this invocation); wall time "
    << Fixed(s.wall_s, 4) << " s\n";
  return o.str();
}

// chi2 along each parameter: the simulated profile with the seeds' noise in
// its differences, the quadratic's prediction, the best and its intervals.
void DrawProfiles(const fs::path& file, const CalibrationResult& r) {
  const CalibrationSpec& spec = *r.spec;
  viz::ChartSheet sheet(file, 1000, "Calibration: " + spec.name,
                        std::string("chi2 along each parameter, ") +
                            (r.profiles_refitted ? "the others re-fitted at each point"
                                                 : "the others held at the best fit") +
                            "; grey: the seeds' redraws; 95 % intervals: shaded the covariance's, "
                            "green dashes the bootstrap's, orange the posterior's");
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    const Parameter& p = spec.parameters[i];
    const ParameterResult& pr = r.summary.parameters[i];
    std::vector<ProfilePoint> points = r.profiles[i];
    double lowest = r.best_simulated_chi2;
    for (const ProfilePoint& q : points) lowest = std::min(lowest, q.chi2);
    ProfilePoint at_best;  // the best fit lies on every profile (no noise band, no prediction drawn there)
    at_best.value = pr.value;
    at_best.chi2 = r.best_simulated_chi2;
    points.push_back(at_best);
    std::sort(points.begin(), points.end(), [](const ProfilePoint& a, const ProfilePoint& b) { return a.value < b.value; });
    std::vector<double> x, y, bx, blo, bhi, sx, sy;
    double lo = r.best_simulated_chi2, hi = r.best_simulated_chi2;
    for (const ProfilePoint& q : points) {
      if (!std::isfinite(q.chi2)) continue;
      x.push_back(q.value);
      y.push_back(q.chi2);
      lo = std::min(lo, q.chi2);
      hi = std::max(hi, q.chi2);
      if (std::isfinite(q.delta_lo95) && std::isfinite(q.delta_hi95) && std::isfinite(lowest)) {
        bx.push_back(q.value);
        blo.push_back(lowest + q.delta_lo95);
        bhi.push_back(lowest + q.delta_hi95);
        lo = std::min(lo, blo.back());
        hi = std::max(hi, bhi.back());
      }
      if (std::isfinite(q.surrogate_chi2)) {
        sx.push_back(q.value);
        sy.push_back(q.surrogate_chi2);
      }
    }
    hi = std::max(hi, lo + 1.25 * 3.841);  // the 95 % line always shows
    const double y0 = std::max(0.0, lo - 0.1 * (hi - lo)), y1 = hi + 0.1 * (hi - lo);
    viz::ChartPanel& panel = sheet.AddPanel(p.path + " (" + pr.determination + ")", "chi2", p.min, p.max, y0, y1, 260);
    if (std::isfinite(pr.lo95))
      panel.Band({std::max(p.min, pr.lo95), std::min(p.max, pr.hi95)}, {y0, y0}, {y1, y1}, viz::ChartColor(1));
    if (bx.size() >= 2) panel.Band(bx, blo, bhi, viz::Color::Hex(0x969696));
    if (std::isfinite(pr.bootstrap_lo95)) {
      panel.Mark(pr.bootstrap_lo95, viz::ChartColor(2), "", true);
      panel.Mark(pr.bootstrap_hi95, viz::ChartColor(2), "", true);
    }
    if (std::isfinite(pr.posterior_lo95)) {
      panel.Mark(pr.posterior_lo95, viz::ChartColor(4), "", false);
      panel.Mark(pr.posterior_hi95, viz::ChartColor(4), "", false);
    }
    if (!x.empty()) panel.Line(x, y, viz::ChartColor(0), 2.0, "simulated (profile)");
    panel.Points(x, y, viz::ChartColor(0), 3.0);
    if (sx.size() >= 2) panel.Line(sx, sy, viz::ChartColor(3), 1.5, "the quadratic of every set", true);
    panel.Line({p.min, p.max}, {lowest + 3.841, lowest + 3.841}, viz::Color::Black(), 1.0, "chi2 min + 3.84", true);
    panel.Points({pr.value}, {r.best_simulated_chi2}, viz::ChartColor(1), 5.0, "best fit");
  }
  sheet.Finish();
}

// Observed statistics against the simulated ones at the best fit: one panel
// per matched series (window means over time) and per matched events
// (cumulative counts), every observation's points (each its colour, with its
// error bars) against the seeds' mean and band.
void DrawFit(const fs::path& file, const CalibrationResult& r) {
  const CalibrationSpec& spec = *r.spec;
  // Many recordings of one kind (a recovery's): one colour and one legend
  // entry for all, which would otherwise cover the panels.
  const std::size_t observations = spec.observations.size();
  const bool many = observations > 6;
  viz::ChartSheet sheet(file, 1000, "Calibration: " + spec.name,
                        std::string("observed (points, +- sigma; ") +
                            (many ? "every observation file in one colour" : "one colour per observation file") +
                            "; a window's largest value: the window dashed) against simulated at the best fit "
                            "(line: mean of the seeds; band: +- their sd)");
  std::map<std::string, std::vector<std::size_t>> groups;
  std::vector<std::string> order;
  for (std::size_t k = 0; k < r.objective.statistics.size(); ++k) {
    const Statistic& st = r.objective.statistics[k];
    const std::string g = (st.is_count ? st.quantity + "s" : st.quantity) + " " + st.where + " " + st.direction +
                          (st.is_max ? ", largest in the window" : "") + " (" + st.unit + ")";
    if (!groups.contains(g)) order.push_back(g);
    groups[g].push_back(k);
  }
  for (std::size_t panel_index = 0; panel_index < order.size() && panel_index < 16; ++panel_index) {
    const std::vector<std::size_t>& members = groups[order[panel_index]];
    double y0 = 1e300, y1 = -1e300, x0 = 1e300, x1 = -1e300;
    for (std::size_t k : members) {
      const Statistic& st = r.objective.statistics[k];
      const double m = r.best_set.mean[k], sd = std::isfinite(r.best_set.sd[k]) ? r.best_set.sd[k] : 0.0;
      for (double v : {st.observed - st.observed_sigma, st.observed + st.observed_sigma, m - sd, m + sd})
        if (std::isfinite(v)) {
          y0 = std::min(y0, v);
          y1 = std::max(y1, v);
        }
      x0 = std::min(x0, st.from_s);
      x1 = std::max(x1, st.to_s);
    }
    if (!(y1 > y0)) {
      y0 -= 0.5;
      y1 += 0.5;
    }
    // Room above the data for the legend.
    const double pad = 0.15 * (y1 - y0);
    viz::ChartPanel& panel = sheet.AddPanel("time, s (observation's clock)", order[panel_index], x0, x1, y0 - pad,
                                            y1 + 4 * pad, 240);
    // The simulated statistics of the first observation that has this series
    // (the others compare the same runs, over their own windows).
    const std::size_t first = r.objective.statistics[members.front()].observation;
    std::vector<double> x, sim, lo, hi;
    for (std::size_t k : members) {
      const Statistic& st = r.objective.statistics[k];
      if (st.observation != first) continue;
      x.push_back(WhereOnTheClock(st));
      const double m = r.best_set.mean[k], sd = std::isfinite(r.best_set.sd[k]) ? r.best_set.sd[k] : 0.0;
      sim.push_back(m);
      lo.push_back(m - sd);
      hi.push_back(m + sd);
    }
    if (x.size() > 1) {
      panel.Band(x, lo, hi, viz::Color::Black());
      panel.Line(x, sim, viz::Color::Black(), 2.0, "simulated");
    } else {
      std::vector<double> sd{hi[0] - sim[0]};
      panel.Points(x, sim, viz::Color::Black(), 6.0, "simulated", &sd);
    }
    for (std::size_t o = 0; o < observations; ++o) {
      std::vector<double> ox, oy, oe;
      const viz::Color colour = viz::ChartColor(many ? 0 : static_cast<int>(o));
      const double shift = (x1 - x0) * 0.006 * (static_cast<double>(o) - 0.5 * static_cast<double>(observations - 1));
      for (std::size_t k : members) {
        const Statistic& st = r.objective.statistics[k];
        if (st.observation != o) continue;
        ox.push_back(WhereOnTheClock(st) + shift);
        oy.push_back(st.observed);
        oe.push_back(st.observed_sigma);
      }
      // A window's largest bin: the window drawn through the point (the
      // peak may lie anywhere in it).
      for (std::size_t k : members) {
        const Statistic& st = r.objective.statistics[k];
        if (st.observation == o && st.is_max)
          panel.Line({st.from_s, st.to_s}, {st.observed, st.observed}, colour, 1.0, "", true);
      }
      std::string legend = !spec.observations[o].recorded_kind.empty() ? "recorded (the scenario's timeline)"
                           : observations > 1 ? spec.observations[o].file.filename().string()
                                              : std::string("observed");
      if (many) legend = o == 0 ? "observed (" + std::to_string(observations) + " files)" : "";
      if (!ox.empty()) panel.Points(ox, oy, colour, 4.0, legend, &oe);
    }
  }
  sheet.Finish();
}

}  // namespace

// Each parameter's expected 95 % half-width against the footage, for one
// recording made longer and for more recordings of the calibrated length.
void DrawFootage(const fs::path& file, const CalibrationResult& r) {
  const CalibrationSpec& spec = *r.spec;
  const FootageDesign& f = r.footage;
  viz::ChartSheet sheet(file, 1000, "How much footage: " + spec.name,
                        "expected 95 % half-width (linearised at the best fit), recordings of " +
                            FormatNumber(f.recording_s) + " s like the first; enough seeds");
  double x1 = 0.0;  // the longest footage drawn: one recording made longest, or the most recordings
  for (const FootageRow& row : f.rows)
    if (row.recordings == 1 || std::abs(row.length_s - f.recording_s) < 1e-9)
      x1 = std::max(x1, row.recordings * row.length_s / 60.0);
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    const double value = std::abs(r.best[i]);
    std::vector<double> lx, ly, nx, ny;
    double y1 = 25.0;
    for (const FootageRow& row : f.rows) {
      const double percent = 100.0 * 1.96 * row.sd[i] / value;
      if (!std::isfinite(percent)) continue;
      if (row.recordings == 1) {
        lx.push_back(row.length_s / 60.0);
        ly.push_back(percent);
        y1 = std::max(y1, percent);
      }
      if (std::abs(row.length_s - f.recording_s) < 1e-9) {
        nx.push_back(row.recordings * row.length_s / 60.0);
        ny.push_back(percent);
        y1 = std::max(y1, percent);
      }
    }
    y1 = std::min(y1 * 1.05, 300.0);
    viz::ChartPanel& panel = sheet.AddPanel("footage, minutes (all recordings together)",
                                            spec.parameters[i].name + " +-% of " + Fixed(r.best[i], 3),
                                            0.0, x1, 0.0, y1, 260);
    for (std::size_t t = 0; t < f.targets.size(); ++t) {
      const double target = 100.0 * f.targets[t];
      panel.Line({0.0, x1}, {target, target}, viz::Color::Black(), 1.0, t == 0 ? "+-20 % and +-10 %" : "", true);
    }
    if (!lx.empty()) panel.Line(lx, ly, viz::ChartColor(0), 2.0, "one recording, longer");
    panel.Points(lx, ly, viz::ChartColor(0), 3.0);
    if (!nx.empty()) panel.Line(nx, ny, viz::ChartColor(1), 2.0, "more recordings of this length");
    panel.Points(nx, ny, viz::ChartColor(1), 3.0);
  }
  sheet.Finish();
}

void WriteOutputs(const fs::path& dir, const Evaluator& ev, CalibrationResult* r) {
  r->summary.json_file = dir / "calibration.json";
  r->summary.report_file = dir / "report.txt";
  WriteFileAtomically(r->summary.json_file, ToJson(ev, *r).dump(1) + "\n");
  // Every evaluation, one row each.
  std::ostringstream csv;
  csv << "order,stage,key";
  for (const Parameter& p : r->spec->parameters) csv << "," << p.path;
  csv << ",chi2,failed_seeds\n";
  for (const SetResult* e : ev.All()) {
    csv << e->order << ",\"" << e->stage << "\"," << e->key;
    for (double v : e->values) csv << "," << sweep::ExactNumber(v);
    csv << "," << sweep::ExactNumber(r->objective.Chi2(e->mean)) << "," << e->failures.size() << "\n";
  }
  WriteFileAtomically(dir / "evaluations.csv", csv.str());
  // The posterior's samples (chain after chain, every kPosteriorFileEvery-th),
  // for corner plots and checks.
  if (!r->posterior.samples.empty()) {
    std::ostringstream post;
    post << "chain";
    for (const Parameter& p : r->spec->parameters) post << "," << p.path;
    post << "\n";
    const std::size_t per_chain = r->posterior.samples.size() / std::max<std::size_t>(r->posterior.chains, 1);
    for (std::size_t k = 0; k < r->posterior.samples.size(); k += kPosteriorFileEvery) {
      post << k / per_chain;
      for (double v : r->posterior.samples[k]) post << "," << sweep::ExactNumber(v);
      post << "\n";
    }
    WriteFileAtomically(dir / "posterior.csv", post.str());
  }
  if (r->footage.note.empty()) {  // the footage design: one row per N recordings of T seconds
    std::ostringstream fc;
    fc << "recordings,length_s,footage_min";
    for (const Parameter& p : r->spec->parameters) fc << "," << p.path << "_sd," << p.path << "_half_width_95_percent";
    fc << "\n";
    for (const FootageRow& row : r->footage.rows) {
      fc << row.recordings << "," << sweep::ExactNumber(row.length_s) << ","
         << sweep::ExactNumber(row.recordings * row.length_s / 60.0);
      for (std::size_t i = 0; i < row.sd.size(); ++i) {
        const double half = 100.0 * 1.96 * row.sd[i] / std::abs(r->best[i]);
        fc << "," << (std::isfinite(row.sd[i]) ? sweep::ExactNumber(row.sd[i]) : "") << ","
           << (std::isfinite(half) ? sweep::ExactNumber(half) : "");
      }
      fc << "\n";
    }
    WriteFileAtomically(dir / "footage.csv", fc.str());
  }
  WriteFileAtomically(r->summary.report_file, Report(*r));
  for (const char* ext : {".png", ".svg"}) {
    if (!r->profiles.empty() && !r->profiles[0].empty()) DrawProfiles(dir / (std::string("profiles") + ext), *r);
    DrawFit(dir / (std::string("fit") + ext), *r);
    if (r->footage.note.empty() && !r->footage.rows.empty()) DrawFootage(dir / (std::string("footage") + ext), *r);
  }
}

}  // namespace crowdrecon::calibrate
