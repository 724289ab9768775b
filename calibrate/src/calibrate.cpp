#include "crowdrecon/calibrate/calibrate.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <tuple>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/scoped_signals.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"
#include "evaluator.hpp"
#include "fit.hpp"
#include "outputs.hpp"

namespace crowdrecon::calibrate {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The posterior's surrogate bandwidths (fractions of the box; inf: the
// quadratic over the whole box), chosen among by leave-one-out error.
const std::vector<double> kBandwidths{0.15, 0.25, 0.4, 0.7, std::numeric_limits<double>::infinity()};

// SIGINT or SIGTERM during the calibration, however it was started (a
// background job of a script inherits SIGINT ignored: issue 65, it sampled
// on for ten minutes). The sweeps of its evaluations install their own
// handlers while they run and hand these back; the stages between them
// (bootstrap, profiles, the posterior, the footage) poll the flag.
std::atomic<bool> g_stop_calibration{false};
extern "C" void OnCalibrationSignal(int signal) {
  RecordStopSignal(signal);
  g_stop_calibration.store(true);
}

// An evaluation was interrupted (Ctrl-C, SIGTERM): the calibration stops
// and resumes from its cache when run again.
struct Interrupted {};

// Between evaluations: a signal stops the calibration here.
void StopIfAsked() {
  if (g_stop_calibration.load()) throw Interrupted{};
}

using Point = std::vector<double>;  // unit coordinates

// The k-th point's i-th coordinate (i < 8) of the Halton sequence in [0, 1).
double Halton(std::size_t k, std::size_t i) {
  static const std::size_t primes[] = {2, 3, 5, 7, 11, 13, 17, 19};
  const std::size_t base = primes[i % 8];
  double f = 1.0, r = 0.0;
  for (std::size_t x = k; x > 0; x /= base) {
    f /= static_cast<double>(base);
    r += f * static_cast<double>(x % base);
  }
  return r;
}

// The face-centred central composite design in the box centre +- half (each
// coordinate clamped to [0, 1]): corners, face centres, centre; for more than
// four parameters a Halton design of twice the quadratic's terms instead.
std::vector<Point> Design(const Point& centre, double half) {
  const std::size_t p = centre.size();
  std::vector<Point> d;
  const auto add = [&](Point u) {
    for (double& x : u) x = std::clamp(x, 0.0, 1.0);
    for (const Point& q : d)
      if (q == u) return;
    d.push_back(std::move(u));
  };
  add(centre);
  if (p <= 4) {
    for (std::size_t mask = 0; mask < (std::size_t{1} << p); ++mask) {
      Point u = centre;
      for (std::size_t i = 0; i < p; ++i) u[i] += (mask >> i & 1) ? half : -half;
      add(u);
    }
    for (std::size_t i = 0; i < p; ++i)
      for (double s : {-1.0, 1.0}) {
        Point u = centre;
        u[i] += s * half;
        add(u);
      }
  } else {
    const std::size_t n = 2 * (1 + p + p * (p + 1) / 2);
    for (std::size_t k = 1; k <= n; ++k) {
      Point u(p);
      for (std::size_t i = 0; i < p; ++i) {
        u[i] = centre[i] - half + 2.0 * half * Halton(k, i);
      }
      add(u);
    }
  }
  return d;
}

double Distance(const Point& a, const Point& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

class Calibration {
 public:
  Calibration(const CalibrationSpec& spec, Evaluator& evaluator, CalibrationResult& r, bool progress)
      : spec_(spec), ev_(evaluator), r_(r), progress_(progress) {}

  void Run() {
    r_.spec = &spec_;
    r_.objective.statistics = ObservedStatistics(spec_);
    if (spec_.options.measure_noise) MeasureNoise();
    if (spec_.approach == Approach::kSurrogate) SearchWithSurrogates();
    else SearchWithGradients();
    StopIfAsked();
    Uncertainty();
    StopIfAsked();
    Profiles();
    StopIfAsked();
    Posterior();
    StopIfAsked();
    Footage();
  }

 private:
  // Runs `sets` (values) and returns their results; throws Interrupted.
  std::vector<SetResult> Eval(const std::vector<Point>& units, const std::string& stage) {
    std::vector<std::vector<double>> sets;
    for (const Point& u : units) sets.push_back(ev_.FromUnit(u));
    std::vector<SetResult> out;
    if (!ev_.Evaluate(sets, stage, &out)) throw Interrupted{};
    return out;
  }

  void Say(const std::string& line) const {
    if (progress_ && ev_.coordinator()) std::fprintf(stderr, "calibrate: %s\n", line.c_str());
  }

  // The seeds' covariance of the statistics, pooled over `sets`, fixes the
  // objective's weights (docs/calibration.md, "The objective").
  void FixSigmas(const std::vector<SetResult>& sets) {
    if (!r_.objective.sigma.empty()) return;
    r_.objective.Group();
    std::vector<const std::vector<std::vector<double>>*> per_seed;
    for (const SetResult& s : sets) per_seed.push_back(&s.per_seed);
    const SeedCovariance c = PooledSeedCovariance(per_seed, r_.objective.lead);
    r_.objective.WeighCovariance(c.covariance, static_cast<double>(spec_.base.seeds.size()));
    r_.seed_correlation = {c.shrinkage, c.effective_values, c.values, sets.size(), c.freedom};
    Say("the seeds' covariance of " + std::to_string(c.values) + " simulated values from " +
        std::to_string(sets.size()) + " sets: correlations shrunk by " + FormatNumber(c.shrinkage) +
        ", as many as " + FormatNumber(c.effective_values) + " independent values");
  }

  std::vector<std::vector<double>> Means(const std::vector<SetResult>& sets) const {
    std::vector<std::vector<double>> m;
    for (const SetResult& s : sets) m.push_back(s.mean);
    return m;
  }

  // 2. The objective's noise: sets a small step apart along each parameter.
  void MeasureNoise() {
    const std::size_t p = spec_.parameters.size();
    const Point start = ev_.ToUnit(spec_.starts[0]);
    const double d = spec_.options.noise_step;
    for (std::size_t i = 0; i < p; ++i) {
      std::vector<Point> line;
      for (int k = -3; k <= 3; ++k) {
        Point u = start;
        u[i] = std::clamp(u[i] + d * k, 0.0, 1.0);
        line.push_back(u);
      }
      const std::vector<SetResult> sets = Eval(line, "noise of the objective along " + spec_.parameters[i].name);
      FixSigmas(sets);
      NoiseResult nr;
      nr.parameter = spec_.parameters[i].path;
      nr.step = d * spec_.parameters[i].Range();
      // chi2 against a quadratic in k, residuals against lines in k.
      std::vector<double> x, chi2;
      std::vector<std::vector<double>> res;
      for (std::size_t s = 0; s < sets.size(); ++s) {
        x.push_back((line[s][i] - start[i]) / d);
        chi2.push_back(r_.objective.Chi2(sets[s].mean));
        res.push_back(r_.objective.Residuals(sets[s].mean));
      }
      const auto scatter = [&](const std::vector<double>& y, double* slope) {
        std::vector<Point> pts;
        std::vector<std::vector<double>> vals;
        for (std::size_t s = 0; s < y.size(); ++s)
          if (std::isfinite(y[s])) {
            pts.push_back({x[s]});
            vals.push_back({y[s]});
          }
        Quadratic q;
        if (pts.size() < 4 || !q.Fit(pts, vals, {0.0}, 1.0)) return kNaN;
        if (slope) *slope = q.Gradient(0, {0.0})[0];
        return q.rms[0] * std::sqrt(static_cast<double>(pts.size()) / static_cast<double>(pts.size() - 3));
      };
      nr.chi2_noise_sd = scatter(chi2, nullptr);
      double pooled = 0.0, count = 0.0;
      std::vector<double> signal;
      for (std::size_t j = 0; j < r_.objective.statistics.size(); ++j) {
        std::vector<double> y;
        for (const auto& rr : res) y.push_back(rr[j]);
        double slope = kNaN;
        const double sd = scatter(y, &slope);
        if (!std::isfinite(sd)) continue;
        pooled += sd * sd;
        count += 1.0;
        if (std::isfinite(slope) && sd > 0) signal.push_back(std::abs(slope) * 2.0 * spec_.options.gradient_step / d / sd);
      }
      nr.residual_noise_sd = count > 0 ? std::sqrt(pooled / count) : kNaN;
      if (!signal.empty()) {
        std::nth_element(signal.begin(), signal.begin() + static_cast<long>(signal.size() / 2), signal.end());
        nr.slope_signal = signal[signal.size() / 2];
      }
      r_.noise.push_back(nr);
      Say("noise along " + spec_.parameters[i].name + ": chi2 scatter " + FormatNumber(nr.chi2_noise_sd) +
          ", residual scatter " + FormatNumber(nr.residual_noise_sd));
    }
  }

  // 3a. Surrogates: a design over the whole box, then boxes shrinking
  //     around each start's optimum.
  void SearchWithSurrogates() {
    const std::size_t p = spec_.parameters.size();
    const Point centre(p, 0.5);
    const std::vector<Point> design = Design(centre, 0.5);
    const std::vector<SetResult> sets = Eval(design, "design over the whole box");
    FixSigmas(sets);
    Quadratic global;
    if (!global.Fit(design, Means(sets), centre, 0.5)) throw InputError(spec_.origin + ": too few design points");
    std::vector<Point> optima;
    for (std::size_t s = 0; s < spec_.starts.size(); ++s) {
      const Point start = ev_.ToUnit(spec_.starts[s]);
      Minimum m = MinimiseSurrogate(global, r_.objective, start);
      for (int round = 1; round <= spec_.options.refinements; ++round) {
        const double half = 0.5 * std::pow(spec_.options.shrink, round);
        Point c = m.u;
        for (double& x : c) x = std::clamp(x, half, 1.0 - half);
        Quadratic local = FitLocal(c, half, "refinement " + std::to_string(round) + " from start " + std::to_string(s + 1));
        m = MinimiseSurrogate(local, r_.objective, m.u);
      }
      StartResult sr;
      sr.start = spec_.starts[s];
      sr.found = ev_.FromUnit(m.u);
      sr.surrogate_chi2 = m.chi2;
      sr.termination = m.termination;
      sr.simulated_chi2 = r_.objective.Chi2(Eval({m.u}, "optimum of start " + std::to_string(s + 1))[0].mean);
      r_.starts.push_back(sr);
      optima.push_back(m.u);
      Say("start " + std::to_string(s + 1) + ": chi2 " + FormatNumber(sr.simulated_chi2));
    }
  }

  // A quadratic over the whole box fitted to every set evaluated so far
  // (the profiles' and the posterior's); false with too few sets.
  bool FitWhole(Quadratic* q) const {
    std::vector<Point> units;
    std::vector<std::vector<double>> means;
    EvaluatedSets(&units, &means);
    return q->Fit(units, means, Point(spec_.parameters.size(), 0.5), 0.5);
  }

  // Every set evaluated so far: its unit coordinates and its seeds' means.
  void EvaluatedSets(std::vector<Point>* units, std::vector<std::vector<double>>* means) const {
    for (const SetResult* s : ev_.All()) {
      units->push_back(ev_.ToUnit(s->values));
      means->push_back(s->mean);
    }
  }

  // Evaluates a design in the box and fits a quadratic to every set
  // evaluated inside it.
  Quadratic FitLocal(const Point& c, double half, const std::string& stage) {
    Eval(Design(c, half), stage);
    std::vector<Point> pts;
    std::vector<std::vector<double>> vals;
    for (const SetResult* s : ev_.All()) {
      const Point u = ev_.ToUnit(s->values);
      if (Distance(u, c) <= half * (1.0 + 1e-9)) {
        pts.push_back(u);
        vals.push_back(s->mean);
      }
    }
    Quadratic q;
    if (!q.Fit(pts, vals, c, half)) throw InputError(spec_.origin + ": too few design points in " + stage);
    return q;
  }

  // 3b. Ceres with central differences of the simulated statistics.
  void SearchWithGradients() {
    const std::size_t p = spec_.parameters.size();
    const std::size_t n = r_.objective.statistics.size();
    const double h = spec_.options.gradient_step;
    for (std::size_t s = 0; s < spec_.starts.size(); ++s) {
      const Point start = ev_.ToUnit(spec_.starts[s]);
      const std::string stage = "gradient search from start " + std::to_string(s + 1);
      const ResidualFunction f = [&](const Point& u, std::vector<double>* res, std::vector<double>* jac) {
        std::vector<Point> pts{u};
        if (jac)
          for (std::size_t i = 0; i < p; ++i)
            for (double sign : {1.0, -1.0}) {
              Point v = u;
              v[i] = std::clamp(u[i] + sign * h, 0.0, 1.0);
              pts.push_back(v);
            }
        const std::vector<SetResult> sets = Eval(pts, stage);
        FixSigmas(sets);
        *res = r_.objective.Residuals(sets[0].mean);
        for (double& x : *res)
          if (!std::isfinite(x)) x = 0.0;  // statistics left out (no scale) or undefined here count nothing
        if (jac) {
          jac->assign(n * p, 0.0);
          for (std::size_t i = 0; i < p; ++i) {
            const std::vector<double> up = r_.objective.Residuals(sets[1 + 2 * i].mean);
            const std::vector<double> down = r_.objective.Residuals(sets[2 + 2 * i].mean);
            const double span = pts[1 + 2 * i][i] - pts[2 + 2 * i][i];
            for (std::size_t j = 0; j < n; ++j) {
              const double d = (up[j] - down[j]) / span;
              (*jac)[j * p + i] = std::isfinite(d) ? d : 0.0;
            }
          }
        }
        return true;
      };
      Minimum m = MinimiseFunction(f, n, start, spec_.options.max_iterations);
      StartResult sr;
      sr.start = spec_.starts[s];
      sr.found = ev_.FromUnit(m.u);
      sr.surrogate_chi2 = kNaN;
      sr.termination = m.termination;
      sr.simulated_chi2 = r_.objective.Chi2(Eval({m.u}, stage)[0].mean);
      r_.starts.push_back(sr);
      Say("start " + std::to_string(s + 1) + ": chi2 " + FormatNumber(sr.simulated_chi2));
    }
  }

  // 4. At the best start's optimum: a local design and quadratic, Ceres'
  //    covariance, the bootstrap.
  void Uncertainty() {
    const std::size_t p = spec_.parameters.size();
    std::size_t b = 0;
    for (std::size_t s = 1; s < r_.starts.size(); ++s)
      if (r_.starts[s].simulated_chi2 < r_.starts[b].simulated_chi2) b = s;
    Point best = ev_.ToUnit(r_.starts[b].found);
    // The same box for both approaches: a box of the gradient's own step
    // (+-0.1 of each range) was dominated by the crowd's noise on the recovery
    // problem (its minimum simulated worse than the start it surrounded, its
    // interval excluded the truth: docs/calibration.md, "The recovery problem").
    const double half = 0.5 * std::pow(spec_.options.shrink, std::max(1, spec_.options.refinements));
    Point c = best;
    for (double& x : c) x = std::clamp(x, half, 1.0 - half);
    const std::vector<Point> design = Design(c, half);
    const std::vector<SetResult> sets = Eval(design, "uncertainty: the design around the best fit");
    FixSigmas(sets);
    Quadratic local;
    {
      std::vector<std::vector<double>> means = Means(sets);
      if (!local.Fit(design, means, c, half)) throw InputError(spec_.origin + ": too few points around the best fit");
    }
    const Minimum m = MinimiseSurrogate(local, r_.objective, best);
    best = m.u;
    r_.best = ev_.FromUnit(best);
    r_.surrogate_form = local.form;
    r_.surrogate_rms = local.rms;
    r_.best_set = Eval({best}, "the best fit")[0];
    r_.best_simulated_chi2 = r_.objective.Chi2(r_.best_set.mean);

    const std::size_t n = r_.objective.statistics.size();
    r_.jacobian.assign(n * p, kNaN);
    for (std::size_t j = 0; j < n; ++j) {
      const std::vector<double> g = local.Gradient(j, best);
      for (std::size_t i = 0; i < p; ++i) r_.jacobian[j * p + i] = g[i] / spec_.parameters[i].Range();
    }
    std::vector<double> cov_u;
    r_.covariance_ok = SurrogateCovariance(local, r_.objective, best, &cov_u, &r_.covariance_reason, &r_.without_effect);
    if (r_.covariance_ok) {
      r_.covariance.assign(p * p, 0.0);
      for (std::size_t i = 0; i < p; ++i)
        for (std::size_t k = 0; k < p; ++k)
          r_.covariance[i * p + k] = cov_u[i * p + k] * spec_.parameters[i].Range() * spec_.parameters[k].Range();
    }

    // The bootstrap: the seeds drawn again with replacement (the same draw at
    // every set: common random numbers), and the observation drawn again
    // from its own uncertainty and the crowd's seed-to-seed spread (it is
    // one realisation); refit, re-minimise.
    std::mt19937_64 rng(20121101);
    const std::size_t k = spec_.base.seeds.size();
    std::uniform_int_distribution<std::size_t> pick(0, k - 1);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int rep = 0; rep < spec_.options.bootstrap; ++rep) {
      StopIfAsked();
      std::vector<std::size_t> draw(k);
      for (std::size_t& d : draw) d = pick(rng);
      Objective o = r_.objective;
      std::vector<double> z(o.statistics.size());
      for (double& x : z) x = normal(rng);
      const std::vector<double> e = o.ObservationNoise(z);  // one recording's statistics scatter together
      for (std::size_t j = 0; j < o.statistics.size(); ++j) o.statistics[j].observed += e[j];
      o.Reobserve();
      std::vector<std::vector<double>> means;
      for (const SetResult& s : sets) means.push_back(RedrawnMean(s.per_seed, draw));
      Quadratic q;
      if (!q.Fit(design, means, c, half)) continue;
      r_.bootstrap.push_back(ev_.FromUnit(MinimiseSurrogate(q, o, best).u));
    }
  }

  // 5. Profiles: along each parameter's whole range, the others re-fitted
  //    (on a quadratic of every set evaluated so far, over the whole box),
  //    simulated there; each chi2 difference with the seeds' noise in it.
  void Profiles() {
    const std::size_t p = spec_.parameters.size();
    const int n = spec_.options.profile_points;
    r_.profiles.assign(p, {});
    if (n < 2) return;
    const Point best = ev_.ToUnit(r_.best);
    Quadratic whole;
    const bool refit = FitWhole(&whole);
    std::vector<Point> pts;
    std::vector<double> surrogate_chi2;
    for (std::size_t i = 0; i < p; ++i)
      for (int k = 0; k < n; ++k) {
        StopIfAsked();
        Point u = best;
        u[i] = static_cast<double>(k) / (n - 1);
        double predicted = kNaN;
        if (refit && p > 1) {
          const Minimum m = MinimiseSurrogate(whole, r_.objective, u, static_cast<int>(i));
          u = m.u;
          u[i] = static_cast<double>(k) / (n - 1);
          predicted = m.chi2;
        } else if (refit) {
          predicted = r_.objective.Chi2(whole.Values(u));
        }
        pts.push_back(u);
        surrogate_chi2.push_back(predicted);
      }
    r_.profiles_refitted = refit && p > 1;
    const std::vector<SetResult> sets = Eval(pts, "profiles");
    for (std::size_t i = 0; i < p; ++i) {
      StopIfAsked();
      std::vector<const std::vector<std::vector<double>>*> along;
      for (int k = 0; k < n; ++k)
        along.push_back(&sets[i * static_cast<std::size_t>(n) + static_cast<std::size_t>(k)].per_seed);
      const ProfileNoise noise =
          ProfileDifferences(r_.objective, along, r_.best_set.per_seed, spec_.options.bootstrap, 20121103 + i);
      for (int k = 0; k < n; ++k) {
        const std::size_t at = i * static_cast<std::size_t>(n) + static_cast<std::size_t>(k);
        const auto kk = static_cast<std::size_t>(k);
        ProfilePoint q;
        q.value = sets[at].values[i];
        q.values = sets[at].values;
        q.chi2 = r_.objective.Chi2(sets[at].mean);
        q.surrogate_chi2 = surrogate_chi2[at];
        q.delta_chi2 = noise.delta[kk];
        q.delta_lo95 = noise.lo95[kk];
        q.delta_hi95 = noise.hi95[kk];
        r_.profiles[i].push_back(q);
      }
    }
  }

  // 6. The posterior: a flat prior over the box and the likelihood of a
  //    quadratic over every set evaluated (the search's, the uncertainty's
  //    and the profiles'), its lack of fit beyond the seeds' S / K added to
  //    the simulated means' error; four Metropolis chains, from the best fit
  //    and three Halton points of the box. No runs: the surrogate alone.
  void Posterior() {
    if (spec_.options.posterior_steps <= 0) return;
    const std::size_t p = spec_.parameters.size();
    auto& post = r_.posterior;
    Quadratic whole;
    if (!FitWhole(&whole)) {
      post.note = "too few parameter sets for a quadratic over the whole box";
      return;
    }
    Objective o = r_.objective;
    const std::size_t n = o.statistics.size();
    // The surrogate: a quadratic over the whole box, or one fitted around
    // each point (the bandwidth whose leave-one-out predictions of the sets'
    // means, each over its seeds' error S_jj / K, err least).
    std::vector<Point> units;
    std::vector<std::vector<double>> means;
    EvaluatedSets(&units, &means);
    std::vector<double> noise(n);
    for (std::size_t j = 0; j < n; ++j) noise[j] = o.seed_covariance[j * n + j] / o.seeds;
    post.bandwidth = ChooseBandwidth(units, means, noise, kBandwidths, &post.bandwidth_scores);
    std::optional<LocalQuadratic> local;
    std::vector<double> misfit = whole.residual_variance;  // beyond the seeds' noise: the surrogate's own error
    if (std::isfinite(post.bandwidth)) {
      local.emplace(units, means, post.bandwidth);
      misfit = local->LeaveOneOutVariance(noise, nullptr);
    }
    o.surrogate_variance.assign(n, 0.0);
    post.lack_of_fit_sd.assign(n, kNaN);
    for (std::size_t j = 0; j < n; ++j) {
      const double var = misfit[j];
      if (!std::isfinite(var)) continue;
      o.surrogate_variance[j] = std::max(0.0, var - noise[j]);
      post.lack_of_fit_sd[j] = std::sqrt(o.surrogate_variance[j]);
    }
    o.Reobserve();
    std::vector<Point> starts{ev_.ToUnit(r_.best)};
    for (std::size_t c = 1; c <= 3; ++c) {
      Point u(p);
      for (std::size_t i = 0; i < p; ++i) u[i] = 0.1 + 0.8 * Halton(c, i);
      starts.push_back(u);
    }
    // Overdispersion: where the best fit's chi2 per degree of freedom
    // exceeds 1, the statistics scatter more than the seeds' covariance
    // allows (a recording with a jam the runs rarely make), and the
    // likelihood is widened by that ratio (never narrowed).
    const int freedom = o.DegreesOfFreedom(p);
    post.scale = freedom > 0 ? std::max(1.0, r_.best_simulated_chi2 / freedom) : 1.0;
    // S is estimated from the design's runs: the likelihood that accounts
    // for that (fit.hpp, EstimatedCovariance), not the Gaussian that takes
    // it as known.
    EstimatedCovariance estimate;
    if (r_.seed_correlation.freedom > 0)
      estimate = {r_.seed_correlation.freedom, static_cast<double>(r_.seed_correlation.values), static_cast<double>(p)};
    post.likelihood_power = estimate.known() ? 0.0 : estimate.Power();
    const SurrogateLikelihood likelihood(whole, o, post.scale, local ? &*local : nullptr, estimate);
    if (likelihood.empty()) {
      post.note = "no statistic could be fitted by the quadratic over the whole box";
      return;
    }
    // The seeds' mean is uncertain as a function, not only in its level:
    // their K surfaces' spread, as K standard normal weights sampled with
    // the parameters (each coordinate z of the box beyond the parameters is
    // a weight w = Phi^-1(z): uniform z, normal w).
    std::vector<std::vector<std::vector<double>>> per_set_seed;
    for (const SetResult* s : ev_.All()) per_set_seed.push_back(s->per_seed);
    SeedSurfaces surfaces;
    const std::size_t k = surfaces.Fit(units, per_set_seed, ev_.ToUnit(r_.best)) ? surfaces.seeds() : 0;
    post.seed_functions = k;
    for (Point& start : starts) start.resize(p + k, 0.5);
    const auto density = [&](const Point& x) {
      if (k == 0) return likelihood(x);
      const Point u(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(p));
      std::vector<double> w(k);
      for (std::size_t s = 0; s < k; ++s) w[s] = NormalQuantile(x[p + s]);
      return likelihood.WithOffset(u, surfaces.Offset(u, w));
    };
    Say("the posterior: " + std::to_string(starts.size()) + " chains of " +
        std::to_string(spec_.options.posterior_steps) + " steps");
    const PosteriorSamples ps = SamplePosterior(density, starts, spec_.options.posterior_steps, 20121104,
                                                [] { return g_stop_calibration.load(); });
    if (ps.interrupted) throw Interrupted{};
    post.samples.clear();
    for (const Point& x : ps.u) post.samples.push_back(ev_.FromUnit(Point(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(p))));
    post.chains = ps.chains;
    post.acceptance = ps.acceptance;
    post.r_hat.assign(ps.r_hat.begin(), ps.r_hat.begin() + static_cast<std::ptrdiff_t>(std::min(p, ps.r_hat.size())));
    post.surrogate_form = local ? "quadratic fitted around each point (Gaussian weights, bandwidth " +
                                      FormatNumber(post.bandwidth) + " of the box)"
                                : whole.form;
    post.sets = ev_.All().size();
    double worst = 0.0;
    for (double r : ps.r_hat) worst = std::max(worst, std::isfinite(r) ? r : 0.0);
    Say("posterior: " + std::to_string(post.samples.size()) + " samples of " + std::to_string(ps.chains) +
        " chains, acceptance " + Fixed(ps.acceptance, 2) + ", largest R-hat " + Fixed(worst, 4));
  }

  // 7. What the recordings determine, and what more would: each
  //    parameter's expected interval for N recordings of T seconds of the
  //    first recording's kind, from the seeds' covariance and the Jacobian
  //    at the best fit (footage.hpp). No runs.
  void Footage() {
    r_.footage = DesignFootage(r_.objective, r_.jacobian, r_.best, FootageOptions{});
    if (r_.footage.note.empty())
      Say("footage: the design over " + std::to_string(r_.footage.kinds.size()) + " kinds of statistics of " +
          FormatNumber(r_.footage.recording_s) + "-s recordings");
  }

  const CalibrationSpec& spec_;
  Evaluator& ev_;
  CalibrationResult& r_;
  bool progress_;
};

}  // namespace

OutputKind CalibrationFolderOutput() {
  return {"a calibration folder (.crowdrecon-calibration, cache/, batches/, calibration.json, ...)", true,
          [](const fs::path& dir) {
            std::error_code ec;
            return fs::is_regular_file(dir / ".crowdrecon-calibration", ec);
          }};
}

bool Options::IsValid(std::string* error) const {
  if (calibration_file.empty()) return *error = "no calibration file", false;
  if (output_dir.empty()) return *error = "no output folder", false;
  if (jobs < 0) return *error = "jobs must be 0 (all cores) or more", false;
  return true;
}

namespace {

// Partial runs an interrupted calibration left in its batch folders (issue
// 40): a rerun resumes those of the batches it asks for again, but a rerun
// with other options (other sets, seeds or bounds) never asks for the rest.
// Once the calibration is done, whatever partial run is left is such an
// orphan; it is removed (sweep::RemovePartialRuns), one note per batch.
std::vector<std::string> RemoveOrphanedRuns(const fs::path& batches) {
  std::vector<fs::path> folders;
  std::error_code ec;
  for (fs::directory_iterator it(batches, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_directory()) folders.push_back(it->path());
  std::sort(folders.begin(), folders.end());
  std::vector<std::string> notes;
  for (const fs::path& batch : folders) {
    const std::vector<fs::path> removed = sweep::RemovePartialRuns(batch);
    if (!removed.empty())
      notes.push_back("removed " + std::to_string(removed.size()) + " partial run file(s) from " +
                      (batch / "runs").string() + ", left by an interrupted calibration whose batch was not asked for again");
  }
  return notes;
}

}  // namespace

Summary Calibrate(const Options& options) {
  const auto t0 = Clock::now();
  std::string error;
  if (!options.IsValid(&error)) throw InputError("calibrate: " + error);
  const CalibrationSpec spec = LoadCalibration(options.calibration_file);
  CreateOutputFolder(options.output_dir);
  WriteFileAtomically(options.output_dir / ".crowdrecon-calibration", spec.file.string() + "\n");
  CalibrationResult r;
  r.summary.name = spec.name;
  r.summary.approach = ToString(spec.approach);
  const std::vector<Statistic> statistics = ObservedStatistics(spec);
  Evaluator evaluator(spec, statistics, options.output_dir, options.jobs, options.show_progress);
  g_stop_calibration.store(false);
  const ScopedSignals signals(OnCalibrationSignal);
  try {
    Calibration(spec, evaluator, r, options.show_stages).Run();
  } catch (const Interrupted&) {
    r.summary.interrupted = true;
    r.summary.coordinator = evaluator.coordinator();
    r.summary.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
    return r.summary;
  }
  r.summary.coordinator = evaluator.coordinator();
  r.summary.sets_evaluated = evaluator.All().size();
  r.summary.runs = evaluator.runs_simulated();
  Summarise(spec, r);
  r.summary.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (r.summary.coordinator) {
    WriteOutputs(options.output_dir, evaluator, &r);
    r.summary.notes = RemoveOrphanedRuns(options.output_dir / "batches");
  }
  return r.summary;
}

}  // namespace crowdrecon::calibrate
