// The least-squares problems of a calibration, in the unit box of the
// parameters' bounds (internal to calibrate/): the residuals, the quadratic
// surrogate of every statistic, and Ceres minimising it, with its covariance.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/calibrate/statistics.hpp"

namespace crowdrecon::calibrate {

// The weighted residuals of the statistics (docs/calibration.md, "The
// objective"): the generalised chi2 (m - o)^T C^-1 (m - o), whitened by C's
// Cholesky factor L (residuals L^-1 (m - o)), m the simulated means of K
// seeds, o the observed values. The covariance of the statistics' errors,
// with S the seeds' covariance of the statistics' values (one run's):
//   C_jk = S_jk [j, k of one recording] + S_jk / K + [j = k] observed_sigma_j^2.
// An observation is one realisation of the crowd (its statistics scatter
// together as one run's do: S within a recording), measured with its own
// uncertainty, against a mean of K seeds whose error S / K is shared by
// every statistic and every recording (the same seeds: common random
// numbers). Statistics of several recordings that read one simulated value
// (Statistic::simulated_from, the same series, window and reduction) are one
// value of the runs: lead_j, the first of them, is what j is compared with.
// Alone (S diagonal, one recording) a residual is (m_j - o_j) / sigma_j,
// sigma_j^2 = observed_sigma_j^2 + S_jj (1 + 1/K). Counted as independent,
// correlated statistics (one window and the next, a share moving and a
// share still) would each count as new evidence of the same seeds' offset,
// and N recordings would shrink the simulated mean's error N times.
struct Objective {
  std::vector<Statistic> statistics;
  std::vector<double> sigma;  // per statistic, alone (display, and NaN: left out)
  std::vector<std::size_t> lead;  // per statistic: the first statistic of its simulated value
  // The seeds' covariance of the statistics (n x n, row-major; zero rows
  // where no spread was measured), its diagonal's square roots (NaN: none
  // measured), and K.
  std::vector<double> seed_covariance;
  std::vector<double> seed_sd;
  double seeds = 1.0;
  // The error of a surrogate of the simulated means beyond the seeds' S / K
  // (per statistic, indexed like the statistics, read at each statistic's
  // lead; empty: none): shared by every recording's statistics of one
  // simulated value, as S / K is. Set by the posterior (its quadratic over
  // the whole box has a lack of fit); call Reobserve() after setting it.
  std::vector<double> surrogate_variance;

  // Sets lead from the statistics' simulated values.
  void Group();
  // Sets the weights from independent simulated values' spreads (sd per
  // statistic, NaN or missing: none measured; statistics reading one
  // simulated value share it).
  void Weigh(const std::vector<double>& spread, double k);
  // Sets the weights from the seeds' covariance of the statistics.
  void WeighCovariance(const std::vector<double>& covariance, double k);
  // Again after observed values changed (the same covariance).
  void Reobserve();
  // Residuals, one per statistic: the whitened ones at the positions of the
  // statistics used with a finite simulated mean (whitened among those
  // alone), NaN elsewhere.
  std::vector<double> Residuals(const std::vector<double>& mean) const;
  double Chi2(const std::vector<double>& mean) const;
  // chi2's degrees of freedom: the statistics used less the parameters fitted.
  int DegreesOfFreedom(std::size_t parameters) const;  // +inf where a statistic used has no simulated mean

  // The whitening of `rows` (statistics used, ascending): residuals
  // w * (simulated values of rows) - b.
  struct Whitening {
    std::vector<std::size_t> rows;
    std::vector<double> w;  // rows x rows, row-major, lower triangular
    std::vector<double> b;
    // w * x - b (the residuals of simulated values x), or w * x without b
    // (their derivatives); x: one value per row, `stride` apart.
    void Apply(const double* x, std::size_t stride, bool minus_b, double* out) const;
  };
  Whitening WhiteningOf(const std::vector<std::size_t>& rows) const;
  // The same, computed now (after the covariance changed; WhiteningOf may
  // return the whitening of every statistic used as it was last computed).
  Whitening Whiten(const std::vector<std::size_t>& rows) const;
  // One draw of the observed values' errors (C's part of one recording:
  // S within recordings plus observed_sigma^2), from `normal` draws, one per
  // statistic; zero for statistics left out.
  std::vector<double> ObservationNoise(const std::vector<double>& normal) const;

 private:
  std::vector<double> Covariance(const std::vector<std::size_t>& rows, bool shared) const;
  Whitening used_;                  // over every statistic used
  std::vector<double> realisation_; // Cholesky factor of one recording's part, over used_.rows
};

// The seeds' covariance of the statistics pooled over sets: each set's
// per-seed values ([seed][statistic], NaN: none) about that set's own mean,
// every simulated value (lead) once; the correlations shrunk toward zero by
// the Schafer-Strimmer intensity (the estimated variance of the sample
// correlations over their squares), raised until the matrix is positive
// definite. Variances: the mean of the sets' own, as `spread` gives them.
struct SeedCovariance {
  std::vector<double> covariance;  // n x n over the statistics, row-major
  std::vector<double> sd;          // per statistic (NaN: none measured)
  double shrinkage = 0.0;          // 0: the sample correlations, 1: none kept
  double effective_values = 0.0;   // (sum eigenvalues)^2 / sum eigenvalues^2 of the correlation used
  std::size_t values = 0;          // distinct simulated values with a spread
  double freedom = 0.0;            // degrees of freedom of the estimate: the fewest over the values of sum over sets (K - 1)
};
SeedCovariance PooledSeedCovariance(const std::vector<const std::vector<std::vector<double>>*>& sets,
                                    const std::vector<std::size_t>& lead);

// The mean of each statistic over the seeds `draw` (indices into per_seed,
// [seed][statistic], repeats allowed: a bootstrap's redraw of the seeds);
// NaN where none of them has a value.
std::vector<double> RedrawnMean(const std::vector<std::vector<double>>& per_seed,
                                const std::vector<std::size_t>& draw);

// The 2.5 and 97.5 percentiles of `sorted` (ascending, at least two values):
// the bootstrap's 95 % interval, as the calibration reports it everywhere.
std::pair<double, double> Percentiles95(const std::vector<double>& sorted);

// The chi2 differences along one parameter's profile, and the seeds' noise
// in them (docs/calibration.md, "Profiles"). `points`: the profile's sets,
// `best`: the best fit's, each as per-seed values [seed][statistic] of the
// same K seeds. delta[k] = chi2(point k) - the lowest chi2 among the points
// and the best fit. lo95/hi95: the 2.5 and 97.5 percentiles of that
// difference over `replicates` redraws of the K seeds with replacement (the
// same draw for every set: common random numbers), NaN when replicates < 2.
// The simulated chi2 is noisy (each set is a mean of K chaotic runs): a
// difference above 3.84 may be noise, and the redraws say how much.
struct ProfileNoise {
  std::vector<double> delta, lo95, hi95;
};
ProfileNoise ProfileDifferences(const Objective& objective,
                                const std::vector<const std::vector<std::vector<double>>*>& points,
                                const std::vector<std::vector<double>>& best, int replicates, std::uint64_t seed);

// Each statistic's mean as a quadratic in the unit coordinates around
// `centre`, scaled by `half_width` (full quadratic where the points allow,
// else squares without cross terms, else linear), fitted by least squares.
class Quadratic {
 public:
  // points: unit coordinates; values[point][statistic] (NaN: left out).
  bool Fit(const std::vector<std::vector<double>>& points, const std::vector<std::vector<double>>& values,
           const std::vector<double>& centre, double half_width);
  double Value(std::size_t statistic, const std::vector<double>& u) const;
  // d value / d u.
  std::vector<double> Gradient(std::size_t statistic, const std::vector<double>& u) const;
  std::vector<double> Values(const std::vector<double>& u) const;
  // Root mean square of the fit's residuals per statistic, and the terms used.
  std::vector<double> rms;
  // The residuals' variance per statistic with the fit's terms counted
  // (sum of squares / (points - terms); NaN with no point to spare).
  std::vector<double> residual_variance;
  std::string form;  // "full quadratic", "quadratic without cross terms", "linear"
  std::vector<double> centre;
  double half_width = 1.0;

 private:
  std::vector<double> Basis(const std::vector<double>& u) const;
  double ValueAt(std::size_t statistic, const std::vector<double>& basis) const;
  std::vector<std::vector<double>> BasisGradient(const std::vector<double>& u) const;
  std::size_t dims_ = 0;
  int terms_ = 2;  // 0 linear, 1 squares, 2 full
  std::vector<std::vector<double>> coefficients_;  // [statistic][basis]
};

// The rows (statistics) the surrogate can fit: finite at its centre, with a
// positive sigma.
std::vector<std::size_t> FittedRows(const Quadratic& q, const Objective& o);

struct Minimum {
  std::vector<double> u;
  double chi2 = 0.0;
  int iterations = 0;
  std::string termination;  // Ceres' summary line
};

// Ceres (trust region, Levenberg-Marquardt, bounds [0, 1]) on the surrogate's
// residuals from `start`; `fixed` >= 0 holds that coordinate at start's value.
Minimum MinimiseSurrogate(const Quadratic& q, const Objective& objective, const std::vector<double>& start, int fixed = -1);

// Residuals and (when jacobian is not null) their Jacobian, row-major
// [residual][coordinate], at u; false when they cannot be had (interrupted,
// a statistic undefined). The gradient approach's function.
using ResidualFunction = std::function<bool(const std::vector<double>& u, std::vector<double>* residuals,
                                            std::vector<double>* jacobian)>;
// Ceres (Levenberg-Marquardt) from `start`, f evaluated at the point clamped
// into [0, 1]^p (rather than under Ceres' bounds, which ask for a Jacobian at
// every trial point); the minimum returned inside the box.
Minimum MinimiseFunction(const ResidualFunction& f, std::size_t residuals, const std::vector<double>& start,
                         int max_iterations);

// Ceres' covariance of the unit coordinates at u for the surrogate problem
// (row-major p x p). A coordinate no statistic depends on (its Jacobian
// column below 1e-6 of the largest) is listed in `without_effect`, held
// constant, and gets zero rows and columns: the others' covariance is then
// given whatever its value. False with the reason when what remains is still
// rank deficient (a combination of parameters leaves every statistic unchanged).
bool SurrogateCovariance(const Quadratic& q, const Objective& objective, const std::vector<double>& u,
                         std::vector<double>* covariance, std::string* reason, std::vector<int>* without_effect);

// Each statistic's mean at u from a quadratic fitted around u to every
// set, each weighted by exp(-d^2 / (2 h^2)), d its distance from u in the
// unit box (locally weighted regression, Cleveland and Devlin 1988, with a
// Gaussian kernel): follows a statistic that a quadratic over the whole box
// cannot (the restitution's effect, steep at one end and flat at the
// other). The bandwidth h is chosen among candidates by leave-one-out
// prediction error, the global quadratic (h = inf) among them.
class LocalQuadratic {
 public:
  // points: unit coordinates; values[point][statistic] (NaN: left out).
  LocalQuadratic(std::vector<std::vector<double>> points, std::vector<std::vector<double>> values, double bandwidth);
  // The means at u (NaN where a statistic has too few values); `skip`: a
  // point left out (leave-one-out), SIZE_MAX none.
  std::vector<double> Values(const std::vector<double>& u, std::size_t skip = static_cast<std::size_t>(-1)) const;
  // Per statistic, the mean square of the leave-one-out errors over the
  // points (NaN: none), and their sum over statistics each divided by
  // `scale` (its seeds' variance; statistics without one left out).
  std::vector<double> LeaveOneOutVariance(const std::vector<double>& scale, double* score) const;
  double bandwidth() const { return h_; }

 private:
  std::vector<std::vector<double>> points_, values_;
  double h_;
};

// The bandwidth (of `candidates`, inf for the global quadratic) whose
// leave-one-out errors, each over its statistic's `scale`, sum least.
double ChooseBandwidth(const std::vector<std::vector<double>>& points, const std::vector<std::vector<double>>& values,
                       const std::vector<double>& scale, const std::vector<double>& candidates,
                       std::vector<double>* scores = nullptr);

// A seeds' covariance S estimated from a finite number of runs, as the
// likelihood must treat it (docs/calibration.md, "The posterior"): a
// Gaussian likelihood with S taken as known gives intervals that cover less
// than they claim (an S of 8 values on 15 degrees of freedom: a "95 %"
// interval covers about 67 %). With S estimated on `freedom` degrees of
// freedom over `dimension` simulated values and `parameters` fitted, the
// likelihood (1 + chi2 / freedom)^(-m/2) with the power m of Percival et al.
// (2022, MNRAS 510, 3207: "Matching Bayesian and frequentist coverage
// probabilities when using an approximate data covariance matrix") gives
// posterior intervals whose coverage matches their level; Sellentin &
// Heavens' (2016) marginal over S is m = freedom + 1.
struct EstimatedCovariance {
  double freedom = std::numeric_limits<double>::infinity();  // inf: S known (the Gaussian likelihood)
  double dimension = 0.0;
  double parameters = 0.0;
  bool known() const { return !std::isfinite(freedom) || freedom <= 0.0; }
  // m; where freedom <= dimension + 3 (too few runs for the formula), its
  // limit for few runs, parameters + 3.
  double Power() const;
};

// The posterior's log-likelihood at u (docs/calibration.md, "The
// posterior"): -chi2 / (2 scale) over the statistics `mean` fits, the
// simulated means read from `mean`, chi2 the objective's generalised one;
// `scale` >= 1 widens it where the best fit's chi2 per degree of freedom
// says the statistics scatter more than their covariance allows. With an
// estimated covariance: -(m / 2) log(1 + (chi2 - chi2_scatter) / (scale
// freedom)), chi2_scatter the part of chi2 that no simulated means remove
// (the scatter between recordings of one simulated value: the least-squares
// residual over free means, one per lead), computed once here; Percival et
// al.'s m is calibrated for a chi2 over the simulated values alone (issue
// 41, point 3: with the scatter counted the intervals at K = 6 covered more
// than their level).
class SurrogateLikelihood {
 public:
  SurrogateLikelihood(const Quadratic& mean, const Objective& objective, double scale = 1.0,
                      const LocalQuadratic* local = nullptr, EstimatedCovariance covariance = {});
  double operator()(const std::vector<double>& u) const;  // -inf where undefined
  // The same with `offset` (per statistic) added to the simulated means.
  double WithOffset(const std::vector<double>& u, const std::vector<double>& offset) const;
  bool empty() const { return rows_.empty(); }

 private:
  const Quadratic& mean_;
  const LocalQuadratic* local_;  // the means from it where given (mean_ then says which statistics are fitted)
  std::vector<std::size_t> lead_;
  std::vector<std::size_t> rows_;
  Objective::Whitening white_;
  double scale_;
  EstimatedCovariance covariance_;
  double power_;
  double scatter_chi2_ = 0.0;  // chi2's part that no simulated means remove (with an estimated covariance)
};

// The error of a mean of K seeds as a function of the parameters (common
// random numbers make it smooth, not constant: the same seeds at every set
// move together, and their mean's slope is as uncertain as its level): the
// K seeds' own quadratics q_s over every set, and their spread about their
// mean as random functions. Offset(u, w) = sum_s w_s (d_s(u) - d_s(anchor)) /
// sqrt(K (K - 1)), d_s = q_s - mean of the q_s, w ~ N(0, I_K): zero at the
// anchor (the best fit, where the objective's S / K already counts the
// level), with the sample covariance of the seeds' surfaces over K as its
// covariance elsewhere. The posterior samples w with the parameters
// (docs/calibration.md, "The posterior").
class SeedSurfaces {
 public:
  // per_set_seed[set][seed][statistic] (NaN: none), points: the sets' unit
  // coordinates; false with fewer than 2 seeds or too few sets.
  bool Fit(const std::vector<std::vector<double>>& points,
           const std::vector<std::vector<std::vector<double>>>& per_set_seed, const std::vector<double>& anchor);
  std::size_t seeds() const { return surfaces_.size(); }
  // The offset per statistic at u for standard normal weights w (K of them).
  std::vector<double> Offset(const std::vector<double>& u, const std::vector<double>& w) const;

 private:
  std::vector<Quadratic> surfaces_;
  std::vector<double> anchor_;
  std::vector<std::vector<double>> at_anchor_;  // [seed][statistic] - the mean there
};

// The standard normal's quantile (Acklam's rational approximation refined
// by a Newton step: relative error below 1e-12 on (0, 1)); +-inf at 0 and 1.
double NormalQuantile(double p);

// Samples of a density over the unit box: random-walk Metropolis, one chain
// from each of `starts`; the first quarter of `steps` burns in (the proposal
// adapted to the chain's own spread every 200 steps, scaled by 2.38^2 / p),
// the rest is kept. Proposals outside the box are refused (the prior is 0
// there). Deterministic for a seed.
struct PosteriorSamples {
  std::vector<std::vector<double>> u;  // kept samples, chain after chain
  std::size_t chains = 0;
  double acceptance = 0.0;             // of the kept steps, over every chain
  std::vector<double> r_hat;           // per coordinate: Gelman and Rubin's potential scale reduction (NaN: one chain)
  bool interrupted = false;            // `stop` said so: the samples are incomplete
};
using LogDensity = std::function<double(const std::vector<double>& u)>;
// `stop` (if given) is asked every 100 steps: when it says so, the sampling
// ends at once with `interrupted` set.
PosteriorSamples SamplePosterior(const LogDensity& log_density, const std::vector<std::vector<double>>& starts,
                                 int steps, std::uint64_t seed, const std::function<bool()>& stop = {});

// The sample standard deviation of v (at least two values).
double SampleSd(const std::vector<double>& v);

// The q-quantile (0 <= q <= 1) of `sorted` (ascending, non-empty), linear
// between order statistics.
double Quantile(const std::vector<double>& sorted, double q);

}  // namespace crowdrecon::calibrate
