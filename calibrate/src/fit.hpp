// The least-squares problems of a calibration, in the unit box of the
// parameters' bounds (internal to calibrate/): the residuals, the quadratic
// surrogate of every statistic, and Ceres minimising it, with its covariance.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/calibrate/statistics.hpp"

namespace crowdrecon::calibrate {

// The weighted residuals of the statistics (docs/calibration.md, "The
// objective"). Statistic j alone: (simulated mean_j - observed_j) / sigma_j,
// sigma_j^2 = observed_sigma_j^2 + seed_sd_j^2 (1 + 1/K): the observation
// is one realisation of the crowd (its own seed-to-seed spread) measured
// with its uncertainty, against the mean of K seeds. Statistics of several
// recordings that read the same simulated value (Statistic::simulated_from,
// the same series, window and reduction) share that mean's error, of
// variance seed_sd^2 / K: their residuals are correlated, with covariance
// C = diag(observed_sigma_i^2 + seed_sd^2) + seed_sd^2 / K, and are whitened
// by C's Cholesky factor L (residuals L^-1 (m 1 - o)), so that the sum of
// squares is the generalised chi2 r^T C^-1 r. (Counted as independent,
// N recordings would shrink the simulated mean's error N times: intervals
// too narrow by up to sqrt(1 + N/K) at N >> K.) NaN where the simulated
// mean is.
struct Objective {
  std::vector<Statistic> statistics;
  std::vector<double> sigma;  // per statistic, alone (display, and NaN: left out)
  // Residual j = alpha_j * mean[lead_j] - beta_j; lead_j is the first
  // statistic of j's group (j itself when alone).
  std::vector<std::size_t> lead;
  std::vector<double> alpha, beta;
  // The pooled seed-to-seed spread per statistic (NaN: none measured) and K.
  std::vector<double> seed_sd;
  double seeds = 1.0;
  // Sets seed_sd, seeds, sigma, the groups and their whitening; again (with
  // the same spread) after an observed value changes.
  void Weigh(const std::vector<double>& spread, double k);
  std::vector<double> Residuals(const std::vector<double>& mean) const;
  double Chi2(const std::vector<double>& mean) const;  // +inf where a residual is NaN
};

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
  std::string form;  // "full quadratic", "quadratic without cross terms", "linear"
  std::vector<double> centre;
  double half_width = 1.0;

 private:
  std::vector<double> Basis(const std::vector<double>& u) const;
  std::vector<std::vector<double>> BasisGradient(const std::vector<double>& u) const;
  std::size_t dims_ = 0;
  int terms_ = 2;  // 0 linear, 1 squares, 2 full
  std::vector<std::vector<double>> coefficients_;  // [statistic][basis]
};

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

}  // namespace crowdrecon::calibrate
