// The objective of a calibration (fit.hpp): residuals, covariances, whitening, noise.
#include "fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <ceres/manifold.h>
#include <glog/logging.h>

namespace crowdrecon::calibrate {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

// --- Objective --------------------------------------------------------------

namespace {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The lower Cholesky factor of c; a diagonal jitter (from 1e-12 of the
// mean variance, growing) where c is only semi-definite, as it is when one
// recording holds two statistics of one simulated value measured exactly.
Matrix LowerCholesky(Matrix c) {
  const Eigen::Index n = c.rows();
  const double scale = n > 0 ? std::max(c.diagonal().mean(), 1e-300) : 1.0;
  for (double jitter = 0.0;; jitter = jitter == 0.0 ? 1e-12 * scale : jitter * 100.0) {
    Matrix t = c;
    t.diagonal().array() += jitter;
    const Eigen::LLT<Matrix> llt(t);
    if (llt.info() == Eigen::Success) return llt.matrixL();
    if (jitter > scale) throw std::logic_error("the statistics' covariance is not positive semi-definite");
  }
}

}  // namespace

void Objective::Group() {
  const std::size_t n = statistics.size();
  lead.resize(n);
  using Key = std::tuple<std::string, std::string, std::string, std::string, double, double, bool, bool, bool>;
  std::map<Key, std::size_t> first;
  for (std::size_t j = 0; j < n; ++j) {
    const Statistic& st = statistics[j];
    lead[j] = j;
    if (st.simulated_from.empty()) continue;
    lead[j] = first.try_emplace({st.simulated_from, st.quantity, st.where, st.direction, st.sim_from_s, st.sim_to_s,
                                 st.is_count, st.is_max, st.is_time},
                                j)
                  .first->second;
  }
}

void Objective::Weigh(const std::vector<double>& spread, double k) {
  Group();
  const std::size_t n = statistics.size();
  const auto sd = [&](std::size_t j) { return j < spread.size() && std::isfinite(spread[j]) ? spread[j] : 0.0; };
  std::vector<double> c(n * n, 0.0);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i)
      if (lead[i] == lead[j]) c[j * n + i] = sd(j) * sd(i);
  WeighCovariance(c, k);
  for (std::size_t j = 0; j < n; ++j) seed_sd[j] = j < spread.size() ? spread[j] : kNaN;
}

void Objective::WeighCovariance(const std::vector<double>& covariance, double k) {
  if (lead.size() != statistics.size()) Group();
  const std::size_t n = statistics.size();
  seed_covariance = covariance;
  seeds = k;
  seed_sd.assign(n, kNaN);
  sigma.assign(n, kNaN);
  used_.rows.clear();
  for (std::size_t j = 0; j < n; ++j) {
    const double var = covariance[j * n + j];
    if (var > 0) seed_sd[j] = std::sqrt(var);
    const double obs = statistics[j].observed_sigma;
    const double s = std::sqrt(obs * obs + std::max(var, 0.0) * (1.0 + 1.0 / k));
    // A statistic that neither the runs nor the observation vary is left
    // out: its residual would have no scale.
    sigma[j] = s > 0 ? s : kNaN;
    if (std::isfinite(sigma[j])) used_.rows.push_back(j);
  }
  used_ = Whiten(used_.rows);
  const std::size_t m = used_.rows.size();
  const std::vector<double> own = Covariance(used_.rows, false);
  const Matrix l = LowerCholesky(Eigen::Map<const Matrix>(own.data(), static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m)));
  realisation_.assign(l.data(), l.data() + l.size());
}

std::vector<double> Objective::Covariance(const std::vector<std::size_t>& rows, bool shared) const {
  const std::size_t n = statistics.size(), m = rows.size();
  std::vector<double> c(m * m, 0.0);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < m; ++b) {
      const std::size_t j = rows[a], i = rows[b];
      const double s = seed_covariance[j * n + i];
      double v = statistics[j].observation == statistics[i].observation ? s : 0.0;
      if (shared) v += s / seeds;
      if (shared && !surrogate_variance.empty() && lead[j] == lead[i]) v += surrogate_variance[lead[j]];
      if (a == b) v += statistics[j].observed_sigma * statistics[j].observed_sigma;
      c[a * m + b] = v;
    }
  return c;
}

Objective::Whitening Objective::WhiteningOf(const std::vector<std::size_t>& rows) const {
  return rows == used_.rows ? used_ : Whiten(rows);
}

void Objective::Whitening::Apply(const double* x, std::size_t stride, bool minus_b, double* out) const {
  const std::size_t m = rows.size();
  for (std::size_t a = 0; a < m; ++a) {
    double v = minus_b ? -b[a] : 0.0;
    for (std::size_t c = 0; c <= a; ++c) v += w[a * m + c] * x[c * stride];
    out[a] = v;
  }
}

Objective::Whitening Objective::Whiten(const std::vector<std::size_t>& rows) const {
  const std::size_t m = rows.size();
  const std::vector<double> c = Covariance(rows, true);
  const auto mi = static_cast<Eigen::Index>(m);
  const Matrix l = LowerCholesky(Eigen::Map<const Matrix>(c.data(), mi, mi));
  const Matrix w = l.triangularView<Eigen::Lower>().solve(Matrix::Identity(mi, mi));
  Eigen::VectorXd o(mi);
  for (std::size_t a = 0; a < m; ++a) o(static_cast<Eigen::Index>(a)) = statistics[rows[a]].observed;
  const Eigen::VectorXd b = w * o;
  Whitening out;
  out.rows = rows;
  out.w.assign(w.data(), w.data() + w.size());
  out.b.assign(b.data(), b.data() + b.size());
  return out;
}

void Objective::Reobserve() { used_ = Whiten(used_.rows); }

std::vector<double> Objective::ObservationNoise(const std::vector<double>& normal) const {
  std::vector<double> e(statistics.size(), 0.0);
  const std::size_t m = used_.rows.size();
  for (std::size_t a = 0; a < m; ++a) {
    double v = 0.0;
    for (std::size_t b = 0; b <= a; ++b) v += realisation_[a * m + b] * normal[used_.rows[b]];
    e[used_.rows[a]] = v;
  }
  return e;
}

std::vector<double> Objective::Residuals(const std::vector<double>& mean) const {
  const std::size_t n = statistics.size();
  std::vector<double> r(n, kNaN);
  std::vector<std::size_t> rows;
  for (std::size_t j : used_.rows)
    if (std::isfinite(mean[lead[j]])) rows.push_back(j);
  Whitening subset;  // (only where some statistic has no simulated mean)
  const Whitening* wh = &used_;
  if (rows != used_.rows) wh = &(subset = Whiten(rows));
  const std::size_t m = rows.size();
  std::vector<double> value(m), white(m);
  for (std::size_t a = 0; a < m; ++a) value[a] = mean[lead[rows[a]]];
  wh->Apply(value.data(), 1, true, white.data());
  for (std::size_t a = 0; a < m; ++a) r[rows[a]] = white[a];
  return r;
}

double Objective::Chi2(const std::vector<double>& mean) const {
  for (std::size_t j : used_.rows)
    if (!std::isfinite(mean[lead[j]])) return std::numeric_limits<double>::infinity();
  double chi2 = 0.0;
  for (double x : Residuals(mean))
    if (std::isfinite(x)) chi2 += x * x;
  return chi2;
}

int Objective::DegreesOfFreedom(std::size_t parameters) const {
  int used = 0;
  for (double s : sigma) used += std::isfinite(s) ? 1 : 0;
  return used - static_cast<int>(parameters);
}

SeedCovariance PooledSeedCovariance(const std::vector<const std::vector<std::vector<double>>*>& sets,
                                    const std::vector<std::size_t>& lead) {
  const std::size_t n = lead.size();
  SeedCovariance out;
  out.covariance.assign(n * n, 0.0);
  out.sd.assign(n, kNaN);
  // Each set's deviations from its own means, per simulated value.
  std::vector<std::size_t> values;
  for (std::size_t j = 0; j < n; ++j)
    if (lead[j] == j) values.push_back(j);
  const std::size_t g = values.size();
  std::vector<std::vector<double>> dev;  // [row][value], NaN: none
  std::vector<double> var_sum(g, 0.0), var_sets(g, 0.0), freedom(g, 0.0);
  std::vector<std::vector<double>> row_weight;  // n / (n - 1) of the row's set, per value
  for (const auto* set : sets) {
    const std::size_t k = set->size();
    std::vector<double> mean(g, 0.0), count(g, 0.0);
    for (const auto& seed : *set)
      for (std::size_t a = 0; a < g; ++a)
        if (std::isfinite(seed[values[a]])) {
          mean[a] += seed[values[a]];
          count[a] += 1.0;
        }
    for (std::size_t a = 0; a < g; ++a) mean[a] = count[a] > 0 ? mean[a] / count[a] : kNaN;
    std::vector<double> ss(g, 0.0);
    for (std::size_t s = 0; s < k; ++s) {
      std::vector<double> d(g, kNaN), w(g, kNaN);
      for (std::size_t a = 0; a < g; ++a)
        if (std::isfinite((*set)[s][values[a]]) && count[a] >= 2) {
          d[a] = (*set)[s][values[a]] - mean[a];
          w[a] = count[a] / (count[a] - 1.0);
          ss[a] += d[a] * d[a];
        }
      dev.push_back(d);
      row_weight.push_back(w);
    }
    for (std::size_t a = 0; a < g; ++a)
      if (count[a] >= 2) {
        var_sum[a] += ss[a] / (count[a] - 1.0);
        var_sets[a] += 1.0;
        freedom[a] += count[a] - 1.0;
      }
  }
  std::vector<double> sd(g, 0.0);
  for (std::size_t a = 0; a < g; ++a)
    if (var_sets[a] > 0) sd[a] = std::sqrt(var_sum[a] / var_sets[a]);
  // Sample correlations (pairwise: rows where both have a value) and the
  // variance of each, from the spread of the standardised products.
  std::vector<std::size_t> live;
  for (std::size_t a = 0; a < g; ++a)
    if (sd[a] > 0) live.push_back(a);
  const std::size_t h = live.size();
  out.values = h;
  out.freedom = h ? std::numeric_limits<double>::infinity() : 0.0;
  for (std::size_t a : live) out.freedom = std::min(out.freedom, freedom[a]);
  Matrix r = Matrix::Identity(static_cast<Eigen::Index>(h), static_cast<Eigen::Index>(h));
  double noise = 0.0, signal = 0.0;
  for (std::size_t x = 0; x < h; ++x)
    for (std::size_t y = x + 1; y < h; ++y) {
      const std::size_t a = live[x], b = live[y];
      std::vector<double> w;
      for (std::size_t row = 0; row < dev.size(); ++row)
        if (std::isfinite(dev[row][a]) && std::isfinite(dev[row][b]))
          w.push_back(dev[row][a] * dev[row][b] / (sd[a] * sd[b]) * std::sqrt(row_weight[row][a] * row_weight[row][b]));
      if (w.size() < 3) continue;  // unknown: taken as uncorrelated
      double mean = 0.0;
      for (double v : w) mean += v;
      mean /= static_cast<double>(w.size());
      double spread = 0.0;
      for (double v : w) spread += (v - mean) * (v - mean);
      const double nw = static_cast<double>(w.size());
      const double rho = std::clamp(mean, -1.0, 1.0);
      r(static_cast<Eigen::Index>(x), static_cast<Eigen::Index>(y)) = rho;
      r(static_cast<Eigen::Index>(y), static_cast<Eigen::Index>(x)) = rho;
      noise += spread / (nw * (nw - 1.0));
      signal += rho * rho;
    }
  double lambda = signal > 0 ? std::clamp(noise / signal, 0.0, 1.0) : 1.0;
  Matrix shrunk;
  // No value varies over the seeds (h = 0): nothing to shrink (Eigen's
  // solver is not asked about an empty matrix: it crashed, issue 65).
  for (; h > 0; lambda = std::min(1.0, lambda + 0.02)) {
    shrunk = (1.0 - lambda) * r;
    shrunk.diagonal().setOnes();
    const Eigen::SelfAdjointEigenSolver<Matrix> eig(shrunk);
    if (eig.eigenvalues().minCoeff() > 1e-6 || lambda >= 1.0) {
      const Eigen::VectorXd e = eig.eigenvalues();
      out.effective_values = e.sum() * e.sum() / e.squaredNorm();
      break;
    }
  }
  if (h == 0) out.effective_values = 0.0;
  out.shrinkage = lambda;
  std::vector<long> row(g, -1);  // value -> row of `shrunk`
  for (std::size_t x = 0; x < h; ++x) row[live[x]] = static_cast<long>(x);
  std::vector<std::size_t> value_of(n, 0);  // statistic -> its value
  for (std::size_t a = 0; a < g; ++a) value_of[values[a]] = a;
  for (std::size_t j = 0; j < n; ++j) value_of[j] = value_of[lead[j]];
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t a = value_of[j];
    out.sd[j] = var_sets[a] > 0 ? sd[a] : kNaN;
    if (row[a] < 0) continue;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t b = value_of[i];
      if (row[b] >= 0) out.covariance[j * n + i] = shrunk(row[a], row[b]) * sd[a] * sd[b];
    }
  }
  return out;
}

std::vector<double> RedrawnMean(const std::vector<std::vector<double>>& per_seed,
                                const std::vector<std::size_t>& draw) {
  const std::size_t n = per_seed.empty() ? 0 : per_seed.front().size();
  std::vector<double> mean(n, 0.0), count(n, 0.0);
  for (std::size_t d : draw)
    for (std::size_t j = 0; j < n; ++j)
      if (std::isfinite(per_seed[d][j])) {
        mean[j] += per_seed[d][j];
        count[j] += 1.0;
      }
  for (std::size_t j = 0; j < n; ++j) mean[j] = count[j] > 0 ? mean[j] / count[j] : kNaN;
  return mean;
}

std::pair<double, double> Percentiles95(const std::vector<double>& sorted) {
  const double last = static_cast<double>(sorted.size() - 1);
  return {sorted[static_cast<std::size_t>(std::floor(0.025 * last))],
          sorted[static_cast<std::size_t>(std::ceil(0.975 * last))]};
}

ProfileNoise ProfileDifferences(const Objective& objective,
                                const std::vector<const std::vector<std::vector<double>>*>& points,
                                const std::vector<std::vector<double>>& best, int replicates, std::uint64_t seed) {
  const std::size_t n = points.size(), k = best.size();
  // chi2 - lowest of every point for one draw of the seeds (every point and
  // the best fit with the same draw); the lowest is finite unless every set failed.
  const auto differences = [&](const std::vector<std::size_t>& draw) {
    std::vector<double> chi2(n);
    double lowest = objective.Chi2(RedrawnMean(best, draw));
    for (std::size_t i = 0; i < n; ++i) {
      chi2[i] = objective.Chi2(RedrawnMean(*points[i], draw));
      lowest = std::min(lowest, chi2[i]);
    }
    for (double& c : chi2) c = std::isfinite(lowest) ? c - lowest : kNaN;
    return chi2;
  };
  std::vector<std::size_t> all(k);
  for (std::size_t d = 0; d < k; ++d) all[d] = d;
  ProfileNoise noise;
  noise.delta = differences(all);
  noise.lo95.assign(n, kNaN);
  noise.hi95.assign(n, kNaN);
  if (replicates < 2 || k == 0) return noise;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, k - 1);
  std::vector<std::vector<double>> samples(n);
  std::vector<std::size_t> draw(k);
  for (int rep = 0; rep < replicates; ++rep) {
    for (std::size_t& d : draw) d = pick(rng);
    const std::vector<double> delta = differences(draw);
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isnan(delta[i])) samples[i].push_back(delta[i]);  // (+inf: that point's runs failed in this draw)
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double>& v = samples[i];
    if (v.size() < 2) continue;
    std::sort(v.begin(), v.end());
    std::tie(noise.lo95[i], noise.hi95[i]) = Percentiles95(v);
  }
  return noise;
}

}  // namespace crowdrecon::calibrate
