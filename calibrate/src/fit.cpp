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
  for (;; lambda = std::min(1.0, lambda + 0.02)) {
    shrunk = (1.0 - lambda) * r;
    shrunk.diagonal().setOnes();
    const Eigen::SelfAdjointEigenSolver<Matrix> eig(shrunk);
    if (h == 0 || eig.eigenvalues().minCoeff() > 1e-6 || lambda >= 1.0) {
      const Eigen::VectorXd e = h ? Eigen::VectorXd(eig.eigenvalues()) : Eigen::VectorXd();
      out.effective_values = h ? e.sum() * e.sum() / e.squaredNorm() : 0.0;
      break;
    }
  }
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

// --- Quadratic --------------------------------------------------------------

std::vector<double> Quadratic::Basis(const std::vector<double>& u) const {
  std::vector<double> z(dims_);
  for (std::size_t i = 0; i < dims_; ++i) z[i] = (u[i] - centre[i]) / half_width;
  std::vector<double> b{1.0};
  for (double zi : z) b.push_back(zi);
  if (terms_ >= 1)
    for (std::size_t i = 0; i < dims_; ++i)
      for (std::size_t k = i; k < dims_; ++k)
        if (k == i || terms_ == 2) b.push_back(z[i] * z[k]);
  return b;
}

std::vector<std::vector<double>> Quadratic::BasisGradient(const std::vector<double>& u) const {
  std::vector<double> z(dims_);
  for (std::size_t i = 0; i < dims_; ++i) z[i] = (u[i] - centre[i]) / half_width;
  std::vector<std::vector<double>> g;  // [basis][coordinate]
  g.push_back(std::vector<double>(dims_, 0.0));
  for (std::size_t i = 0; i < dims_; ++i) {
    std::vector<double> row(dims_, 0.0);
    row[i] = 1.0 / half_width;
    g.push_back(row);
  }
  if (terms_ >= 1)
    for (std::size_t i = 0; i < dims_; ++i)
      for (std::size_t k = i; k < dims_; ++k)
        if (k == i || terms_ == 2) {
          std::vector<double> row(dims_, 0.0);
          row[i] += z[k] / half_width;
          row[k] += z[i] / half_width;
          g.push_back(row);
        }
  return g;
}

bool Quadratic::Fit(const std::vector<std::vector<double>>& points, const std::vector<std::vector<double>>& values,
                    const std::vector<double>& centre_u, double half) {
  centre = centre_u;
  half_width = half;
  dims_ = centre.size();
  const std::size_t p = dims_;
  const std::size_t full = 1 + p + p * (p + 1) / 2, squares = 1 + 2 * p, linear = 1 + p;
  const std::size_t n = points.size();
  terms_ = n >= full + 1 ? 2 : n >= squares + 1 ? 1 : 0;
  if (n < linear) return false;
  form = terms_ == 2 ? "full quadratic" : terms_ == 1 ? "quadratic without cross terms" : "linear";
  const std::size_t statistics = values.empty() ? 0 : values[0].size();
  coefficients_.assign(statistics, {});
  rms.assign(statistics, kNaN);
  residual_variance.assign(statistics, kNaN);
  const std::size_t m = Basis(points[0]).size();
  for (std::size_t j = 0; j < statistics; ++j) {
    std::vector<std::size_t> rows;
    for (std::size_t i = 0; i < n; ++i)
      if (std::isfinite(values[i][j])) rows.push_back(i);
    if (rows.size() < m) {
      coefficients_[j].assign(m, kNaN);
      continue;
    }
    Eigen::MatrixXd a(rows.size(), m);
    Eigen::VectorXd y(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const std::vector<double> b = Basis(points[rows[r]]);
      for (std::size_t c = 0; c < m; ++c) a(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = b[c];
      y(static_cast<Eigen::Index>(r)) = values[rows[r]][j];
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(y);
    coefficients_[j].assign(x.data(), x.data() + x.size());
    const Eigen::VectorXd e = a * x - y;
    rms[j] = std::sqrt(e.squaredNorm() / static_cast<double>(rows.size()));
    if (rows.size() > m) residual_variance[j] = e.squaredNorm() / static_cast<double>(rows.size() - m);
  }
  return true;
}

double Quadratic::ValueAt(std::size_t statistic, const std::vector<double>& basis) const {
  double v = 0.0;
  for (std::size_t c = 0; c < basis.size(); ++c) v += coefficients_[statistic][c] * basis[c];
  return v;
}

double Quadratic::Value(std::size_t statistic, const std::vector<double>& u) const { return ValueAt(statistic, Basis(u)); }

std::vector<double> Quadratic::Gradient(std::size_t statistic, const std::vector<double>& u) const {
  const auto g = BasisGradient(u);
  std::vector<double> out(dims_, 0.0);
  for (std::size_t c = 0; c < g.size(); ++c)
    for (std::size_t i = 0; i < dims_; ++i) out[i] += coefficients_[statistic][c] * g[c][i];
  return out;
}

std::vector<double> Quadratic::Values(const std::vector<double>& u) const {
  const std::vector<double> b = Basis(u);  // (once for every statistic)
  std::vector<double> v(coefficients_.size());
  for (std::size_t j = 0; j < v.size(); ++j) v[j] = ValueAt(j, b);
  return v;
}

// --- Ceres ------------------------------------------------------------------

namespace {

// The surrogate's residuals: the statistics it could fit, whitened among
// themselves.
class SurrogateCost final : public ceres::CostFunction {
 public:
  SurrogateCost(const Quadratic& q, const Objective& o, const std::vector<std::size_t>& rows)
      : q_(q), o_(o), white_(o.WhiteningOf(rows)) {
    set_num_residuals(static_cast<int>(rows.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(q.centre.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const std::size_t p = q_.centre.size(), m = white_.rows.size();
    const std::vector<double> u(parameters[0], parameters[0] + p);
    const bool want = jacobians && jacobians[0];
    std::vector<double> value(m), gradient(want ? m * p : 0);
    for (std::size_t r = 0; r < m; ++r) {
      const std::size_t lead = o_.lead[white_.rows[r]];
      value[r] = q_.Value(lead, u);
      if (want) {
        const std::vector<double> g = q_.Gradient(lead, u);
        std::copy(g.begin(), g.end(), gradient.begin() + static_cast<long>(r * p));
      }
    }
    white_.Apply(value.data(), 1, true, residuals);
    if (want) {
      std::vector<double> column(m);
      for (std::size_t i = 0; i < p; ++i) {
        white_.Apply(gradient.data() + i, p, false, column.data());
        for (std::size_t r = 0; r < m; ++r) jacobians[0][r * p + i] = column[r];
      }
    }
    return true;
  }

 private:
  const Quadratic& q_;
  const Objective& o_;
  Objective::Whitening white_;
};

std::vector<std::size_t> FittedRows(const Quadratic& q, const Objective& o) {
  std::vector<std::size_t> rows;
  const std::vector<double> probe = q.Values(q.centre);
  for (std::size_t j = 0; j < o.statistics.size(); ++j)
    if (std::isfinite(probe[o.lead[j]]) && std::isfinite(o.sigma[j]) && o.sigma[j] > 0) rows.push_back(j);
  return rows;
}

// Ceres logs through glog, which writes to stderr unless told otherwise; a
// calibration says what happened in its own outputs.
void QuietGlog() {
  static const bool once = [] {
    FLAGS_minloglevel = google::GLOG_FATAL;
    return true;
  }();
  (void)once;
}

ceres::Solver::Options SolverOptions(int max_iterations) {
  QuietGlog();
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;  // deterministic
  options.logging_type = ceres::SILENT;
  return options;
}

void Bound(ceres::Problem* problem, double* u, std::size_t p) {
  for (std::size_t i = 0; i < p; ++i) {
    problem->SetParameterLowerBound(u, static_cast<int>(i), 0.0);
    problem->SetParameterUpperBound(u, static_cast<int>(i), 1.0);
  }
}

// The gradient approach's residuals: the caller's function of the point
// Ceres asks for clamped into the box [0, 1]^p (its Jacobian by the caller's
// central differences). The clamp replaces Ceres' bounds: on a bounded
// problem Ceres evaluates a Jacobian at every trial point (its projection
// onto the bounds searches along a gradient), 14 Jacobians instead of 2 in
// 5 iterations of a small test, and here each Jacobian is a stencil of
// 2p + 1 parameter sets. Clamped, a trial point costs one set and a
// Jacobian is asked for only where a step was accepted. Outside the box the
// clamped function does not depend on that coordinate: its column is zero.
class FunctionCost final : public ceres::CostFunction {
 public:
  FunctionCost(const ResidualFunction& f, std::size_t residuals, std::size_t p) : f_(f), p_(p) {
    set_num_residuals(static_cast<int>(residuals));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(p));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    std::vector<double> u(parameters[0], parameters[0] + p_);
    for (double& x : u) x = std::clamp(x, 0.0, 1.0);
    std::vector<double> r, j;
    const bool want = jacobians && jacobians[0];
    if (!f_(u, &r, want ? &j : nullptr)) return false;
    std::copy(r.begin(), r.end(), residuals);
    if (want) {
      for (std::size_t i = 0; i < p_; ++i)
        if (parameters[0][i] != u[i])
          for (std::size_t k = 0; k < r.size(); ++k) j[k * p_ + i] = 0.0;
      std::copy(j.begin(), j.end(), jacobians[0]);
    }
    return true;
  }

 private:
  const ResidualFunction& f_;
  std::size_t p_;
};

}  // namespace

Minimum MinimiseSurrogate(const Quadratic& q, const Objective& objective, const std::vector<double>& start, int fixed) {
  const std::size_t p = start.size();
  Minimum m;
  m.u = start;
  const std::vector<std::size_t> rows = FittedRows(q, objective);
  if (rows.empty() || (p == 1 && fixed == 0)) {
    m.chi2 = objective.Chi2(q.Values(m.u));
    m.termination = rows.empty() ? "no statistic could be fitted" : "nothing to vary";
    return m;
  }
  ceres::Problem problem;
  problem.AddResidualBlock(new SurrogateCost(q, objective, rows), nullptr, m.u.data());
  Bound(&problem, m.u.data(), p);
  if (fixed >= 0) problem.SetManifold(m.u.data(), new ceres::SubsetManifold(static_cast<int>(p), {fixed}));
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(100), &problem, &summary);
  m.iterations = static_cast<int>(summary.iterations.size());
  m.termination = summary.BriefReport();
  m.chi2 = 2.0 * summary.final_cost;
  return m;
}

Minimum MinimiseFunction(const ResidualFunction& f, std::size_t residuals, const std::vector<double>& start,
                         int max_iterations) {
  Minimum m;
  m.u = start;
  ceres::Problem problem;
  problem.AddResidualBlock(new FunctionCost(f, residuals, start.size()), nullptr, m.u.data());
  ceres::Solver::Options options = SolverOptions(max_iterations);
  options.max_num_consecutive_invalid_steps = 3;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (double& x : m.u) x = std::clamp(x, 0.0, 1.0);
  m.iterations = static_cast<int>(summary.iterations.size());
  m.termination = summary.BriefReport();
  m.chi2 = 2.0 * summary.final_cost;
  return m;
}

bool SurrogateCovariance(const Quadratic& q, const Objective& objective, const std::vector<double>& u,
                         std::vector<double>* covariance, std::string* reason, std::vector<int>* without_effect) {
  const std::size_t p = u.size();
  std::vector<double> x = u;
  without_effect->clear();
  const std::vector<std::size_t> rows = FittedRows(q, objective);
  if (rows.empty()) {
    *reason = "no statistic could be fitted";
    return false;
  }
  // Which coordinates move any statistic at all (the whitened Jacobian's columns).
  std::vector<double> norm(p, 0.0);
  {
    const SurrogateCost cost(q, objective, rows);
    std::vector<double> res(rows.size()), jac(rows.size() * p);
    const double* params[] = {x.data()};
    double* jacobians[] = {jac.data()};
    cost.Evaluate(params, res.data(), jacobians);
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t i = 0; i < p; ++i) norm[i] += jac[r * p + i] * jac[r * p + i];
  }
  const double largest = *std::max_element(norm.begin(), norm.end());
  for (std::size_t i = 0; i < p; ++i)
    if (!(norm[i] > 1e-12 * largest) || largest == 0.0) without_effect->push_back(static_cast<int>(i));
  if (without_effect->size() == p) {
    *reason = "no statistic depends on any parameter at the optimum";
    return false;
  }
  ceres::Problem problem;
  problem.AddResidualBlock(new SurrogateCost(q, objective, rows), nullptr, x.data());
  if (!without_effect->empty()) problem.SetManifold(x.data(), new ceres::SubsetManifold(static_cast<int>(p), *without_effect));
  QuietGlog();
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.null_space_rank = 0;  // a direction the data do not constrain is an error, not dropped
  options.min_reciprocal_condition_number = 1e-12;
  options.num_threads = 1;
  ceres::Covariance cov(options);
  std::vector<std::pair<const double*, const double*>> blocks{{x.data(), x.data()}};
  if (!cov.Compute(blocks, &problem)) {
    *reason = "the Jacobian at the optimum is rank deficient (some combination of the parameters leaves every "
              "statistic unchanged)";
    return false;
  }
  covariance->assign(p * p, 0.0);
  cov.GetCovarianceBlock(x.data(), x.data(), covariance->data());
  return true;
}

// --- The posterior -----------------------------------------------------------

double SampleSd(const std::vector<double>& v) {
  double mean = 0.0, ss = 0.0;
  for (double x : v) mean += x / static_cast<double>(v.size());
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

double Quantile(const std::vector<double>& sorted, double q) {
  const double at = std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (at - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

LocalQuadratic::LocalQuadratic(std::vector<std::vector<double>> points, std::vector<std::vector<double>> values,
                               double bandwidth)
    : points_(std::move(points)), values_(std::move(values)), h_(bandwidth) {}

std::vector<double> LocalQuadratic::Values(const std::vector<double>& u, std::size_t skip) const {
  const std::size_t n = points_.size(), p = u.size();
  const std::size_t statistics = values_.empty() ? 0 : values_[0].size();
  const std::size_t m = 1 + p + p * (p + 1) / 2;
  std::vector<double> out(statistics, kNaN);
  // The weighted design: rows sqrt(w) [1, d, d_i d_k], d = point - u; the
  // value at u is the intercept.
  Eigen::MatrixXd a(n, m);
  Eigen::VectorXd sw(n);
  for (std::size_t i = 0; i < n; ++i) {
    double d2 = 0.0;
    for (std::size_t k = 0; k < p; ++k) d2 += (points_[i][k] - u[k]) * (points_[i][k] - u[k]);
    const double w = i == skip ? 0.0 : std::isinf(h_) ? 1.0 : std::exp(-0.5 * d2 / (h_ * h_));
    sw(static_cast<Eigen::Index>(i)) = std::sqrt(w);
    Eigen::Index c = 0;
    const auto ii = static_cast<Eigen::Index>(i);
    a(ii, c++) = 1.0;
    for (std::size_t k = 0; k < p; ++k) a(ii, c++) = points_[i][k] - u[k];
    for (std::size_t k = 0; k < p; ++k)
      for (std::size_t l = k; l < p; ++l) a(ii, c++) = (points_[i][k] - u[k]) * (points_[i][l] - u[l]);
    a.row(ii) *= sw(ii);
  }
  // Statistics with a value at every point share one factorisation.
  std::vector<std::size_t> complete, partial;
  for (std::size_t j = 0; j < statistics; ++j) {
    bool all = true;
    for (std::size_t i = 0; i < n; ++i) all = all && (i == skip || std::isfinite(values_[i][j]));
    (all ? complete : partial).push_back(j);
  }
  const std::size_t used = n - (skip < n ? 1 : 0);
  if (!complete.empty() && used >= m) {
    Eigen::MatrixXd y(n, complete.size());
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t c = 0; c < complete.size(); ++c) {
        const double v = values_[i][complete[c]];
        y(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = i == skip ? 0.0 : v * sw(static_cast<Eigen::Index>(i));
      }
    const Eigen::MatrixXd x = a.colPivHouseholderQr().solve(y);
    for (std::size_t c = 0; c < complete.size(); ++c) out[complete[c]] = x(0, static_cast<Eigen::Index>(c));
  }
  for (std::size_t j : partial) {
    std::vector<Eigen::Index> rows;
    for (std::size_t i = 0; i < n; ++i)
      if (i != skip && std::isfinite(values_[i][j])) rows.push_back(static_cast<Eigen::Index>(i));
    if (rows.size() < m) continue;
    Eigen::MatrixXd aj(rows.size(), m);
    Eigen::VectorXd yj(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      aj.row(static_cast<Eigen::Index>(r)) = a.row(rows[r]);
      yj(static_cast<Eigen::Index>(r)) = values_[static_cast<std::size_t>(rows[r])][j] * sw(rows[r]);
    }
    out[j] = aj.colPivHouseholderQr().solve(yj)(0);
  }
  return out;
}

std::vector<double> LocalQuadratic::LeaveOneOutVariance(const std::vector<double>& scale, double* score) const {
  const std::size_t statistics = values_.empty() ? 0 : values_[0].size();
  std::vector<double> sum(statistics, 0.0);
  std::vector<std::size_t> count(statistics, 0);
  double total = 0.0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const std::vector<double> v = Values(points_[i], i);
    for (std::size_t j = 0; j < statistics; ++j) {
      const double e = v[j] - values_[i][j];
      if (!std::isfinite(e)) continue;
      sum[j] += e * e;
      ++count[j];
      if (j < scale.size() && scale[j] > 0.0 && std::isfinite(scale[j])) total += e * e / scale[j];
    }
  }
  for (std::size_t j = 0; j < statistics; ++j) sum[j] = count[j] > 0 ? sum[j] / static_cast<double>(count[j]) : kNaN;
  if (score) *score = total;
  return sum;
}

double ChooseBandwidth(const std::vector<std::vector<double>>& points, const std::vector<std::vector<double>>& values,
                       const std::vector<double>& scale, const std::vector<double>& candidates,
                       std::vector<double>* scores) {
  double best = std::numeric_limits<double>::infinity(), best_score = best;
  if (scores) scores->clear();
  for (double h : candidates) {
    double score = 0.0;
    LocalQuadratic(points, values, h).LeaveOneOutVariance(scale, &score);
    if (scores) scores->push_back(score);
    if (score < best_score) {
      best_score = score;
      best = h;
    }
  }
  return best;
}

double EstimatedCovariance::Power() const {
  const double runs = freedom + 1.0, d = dimension, p = parameters;
  if (freedom <= d + 3.0) return p + 3.0;  // B below grows without bound as runs - d - 4 -> 0
  const double b = (runs - d - 2.0) / ((runs - d - 1.0) * (runs - d - 4.0));
  const double bd = b * std::max(0.0, d - p);
  return p + 2.0 + (runs - 1.0 + bd) / (1.0 + bd);
}

SurrogateLikelihood::SurrogateLikelihood(const Quadratic& mean, const Objective& objective, double scale,
                                         const LocalQuadratic* local, EstimatedCovariance covariance)
    : mean_(mean), local_(local), lead_(objective.lead), rows_(FittedRows(mean, objective)), scale_(scale),
      covariance_(covariance), power_(covariance.known() ? 0.0 : covariance.Power()) {
  if (!rows_.empty()) white_ = objective.Whiten(rows_);
  // The part of chi2 no simulated means can remove (the scatter between
  // recordings of one statistic): the least-squares residual of
  // |W P mu - b|^2 over free means mu, one per simulated value (lead).
  if (!rows_.empty() && !covariance_.known()) {
    std::vector<std::size_t> leads;
    for (std::size_t r : rows_) leads.push_back(lead_[r]);
    std::vector<std::size_t> unique = leads;
    std::sort(unique.begin(), unique.end());
    unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
    const std::size_t n = rows_.size(), k = unique.size();
    Eigen::MatrixXd a(n, k);
    std::vector<double> column(n);
    for (std::size_t j = 0; j < k; ++j) {
      for (std::size_t r = 0; r < n; ++r) column[r] = leads[r] == unique[j] ? 1.0 : 0.0;
      std::vector<double> out(n);
      white_.Apply(column.data(), 1, false, out.data());
      for (std::size_t r = 0; r < n; ++r) a(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) = out[r];
    }
    Eigen::VectorXd b(n);
    for (std::size_t r = 0; r < n; ++r) b(static_cast<Eigen::Index>(r)) = white_.b[r];
    const Eigen::VectorXd mu = a.colPivHouseholderQr().solve(b);
    scatter_chi2_ = (a * mu - b).squaredNorm();
  }
}

double SurrogateLikelihood::operator()(const std::vector<double>& u) const { return WithOffset(u, {}); }

double SurrogateLikelihood::WithOffset(const std::vector<double>& u, const std::vector<double>& offset) const {
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  if (rows_.empty()) return kNone;
  std::vector<double> all = local_ ? local_->Values(u) : mean_.Values(u);
  for (std::size_t j = 0; j < offset.size() && j < all.size(); ++j) all[j] += offset[j];
  std::vector<double> value(rows_.size()), residuals(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) value[r] = all[lead_[rows_[r]]];
  white_.Apply(value.data(), 1, true, residuals.data());
  double chi2 = 0.0;
  for (double r : residuals) chi2 += r * r;
  if (!std::isfinite(chi2)) return kNone;
  if (covariance_.known()) return -0.5 * chi2 / scale_;
  return -0.5 * power_ * std::log1p(std::max(0.0, chi2 - scatter_chi2_) / (scale_ * covariance_.freedom));
}

bool SeedSurfaces::Fit(const std::vector<std::vector<double>>& points,
                       const std::vector<std::vector<std::vector<double>>>& per_set_seed, const std::vector<double>& anchor) {
  surfaces_.clear();
  if (per_set_seed.empty() || per_set_seed[0].size() < 2) return false;
  const std::size_t k = per_set_seed[0].size();
  for (std::size_t s = 0; s < k; ++s) {
    std::vector<std::vector<double>> values;
    for (const auto& set : per_set_seed) values.push_back(s < set.size() ? set[s] : std::vector<double>(set[0].size(), kNaN));
    Quadratic q;
    if (!q.Fit(points, values, std::vector<double>(anchor.size(), 0.5), 0.5)) {
      surfaces_.clear();
      return false;
    }
    surfaces_.push_back(std::move(q));
  }
  anchor_ = anchor;
  at_anchor_.clear();
  for (const Quadratic& q : surfaces_) at_anchor_.push_back(q.Values(anchor));
  return true;
}

std::vector<double> SeedSurfaces::Offset(const std::vector<double>& u, const std::vector<double>& w) const {
  const std::size_t k = surfaces_.size();
  std::vector<std::vector<double>> d;
  for (std::size_t s = 0; s < k; ++s) {
    std::vector<double> v = surfaces_[s].Values(u);
    for (std::size_t j = 0; j < v.size(); ++j) v[j] -= at_anchor_[s][j];  // each seed's change from the anchor
    d.push_back(std::move(v));
  }
  const std::size_t n = d.empty() ? 0 : d[0].size();
  std::vector<double> out(n, 0.0);
  const double norm = 1.0 / std::sqrt(static_cast<double>(k) * static_cast<double>(k - 1));
  for (std::size_t j = 0; j < n; ++j) {
    double mean = 0.0;
    for (std::size_t s = 0; s < k; ++s) mean += d[s][j] / static_cast<double>(k);
    for (std::size_t s = 0; s < k; ++s) out[j] += w[s] * (d[s][j] - mean) * norm;
    if (!std::isfinite(out[j])) out[j] = 0.0;  // a statistic some seed has no surface for: no slope error known
  }
  return out;
}

double NormalQuantile(double p) {
  if (!(p > 0.0)) return -std::numeric_limits<double>::infinity();
  if (!(p < 1.0)) return std::numeric_limits<double>::infinity();
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p > 1.0 - 0.02425) {
    const double q = std::sqrt(-2.0 * std::log1p(-p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  // One Newton step on Phi(x) = p.
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * 3.14159265358979323846) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

PosteriorSamples SamplePosterior(const LogDensity& density, const std::vector<std::vector<double>>& starts, int steps,
                                 std::uint64_t seed) {
  PosteriorSamples out;
  if (starts.empty() || steps < 8) return out;
  const std::size_t p = starts[0].size();
  const auto pi = static_cast<Eigen::Index>(p);
  const auto log_density = [&](const Eigen::VectorXd& u) {
    for (Eigen::Index i = 0; i < pi; ++i)
      if (!(u(i) >= 0.0 && u(i) <= 1.0)) return -std::numeric_limits<double>::infinity();
    return density(std::vector<double>(u.data(), u.data() + pi));
  };
  const int burn = std::max(steps / 4, 1);
  const int keep = steps - burn;
  const double scale = 2.38 * 2.38 / static_cast<double>(p);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::size_t accepted = 0;
  std::vector<std::vector<Eigen::VectorXd>> chains;
  for (const std::vector<double>& start : starts) {
    Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(start.data(), pi);
    for (Eigen::Index i = 0; i < pi; ++i) x(i) = std::clamp(x(i), 0.0, 1.0);
    double lx = log_density(x);
    Eigen::MatrixXd chol = Eigen::MatrixXd::Identity(pi, pi) * 0.1;  // the first proposal: 0.1 of each range
    std::vector<Eigen::VectorXd> kept;
    std::vector<Eigen::VectorXd> burnt;
    for (int step = 0; step < steps; ++step) {
      if (step < burn && step > 0 && step % 200 == 0 && burnt.size() >= 2 * p + 2) {
        // Adapt to the spread of the chain's second half so far (past its
        // walk from the start).
        const std::size_t from = burnt.size() / 2, n = burnt.size() - from;
        Eigen::VectorXd mean = Eigen::VectorXd::Zero(pi);
        for (std::size_t k = from; k < burnt.size(); ++k) mean += burnt[k] / static_cast<double>(n);
        Eigen::MatrixXd c = Eigen::MatrixXd::Zero(pi, pi);
        for (std::size_t k = from; k < burnt.size(); ++k) c += (burnt[k] - mean) * (burnt[k] - mean).transpose();
        c = c / static_cast<double>(n - 1) * scale;
        c.diagonal().array() += 1e-8;
        const Eigen::LLT<Eigen::MatrixXd> llt(c);
        if (llt.info() == Eigen::Success) chol = llt.matrixL();
      }
      Eigen::VectorXd z(pi);
      for (Eigen::Index i = 0; i < pi; ++i) z(i) = normal(rng);
      const Eigen::VectorXd y = x + chol * z;
      const double ly = log_density(y);
      const double a = uniform(rng);
      const bool accept = std::isfinite(ly) && (ly >= lx || a < std::exp(ly - lx));
      if (accept) {
        x = y;
        lx = ly;
      }
      if (step < burn) {
        burnt.push_back(x);
      } else {
        kept.push_back(x);
        accepted += accept ? 1 : 0;
      }
    }
    chains.push_back(std::move(kept));
  }
  out.chains = chains.size();
  out.acceptance = static_cast<double>(accepted) / static_cast<double>(chains.size() * static_cast<std::size_t>(keep));
  for (const auto& chain : chains)
    for (const Eigen::VectorXd& x : chain) out.u.emplace_back(x.data(), x.data() + x.size());
  // Gelman and Rubin: between-chain against within-chain variance.
  out.r_hat.assign(p, kNaN);
  const double m = static_cast<double>(chains.size()), n = static_cast<double>(keep);
  if (chains.size() >= 2 && keep >= 2)
    for (std::size_t i = 0; i < p; ++i) {
      std::vector<double> means, vars;
      for (const auto& chain : chains) {
        double mean = 0.0, ss = 0.0;
        for (const Eigen::VectorXd& x : chain) mean += x(static_cast<Eigen::Index>(i)) / n;
        for (const Eigen::VectorXd& x : chain) ss += (x(static_cast<Eigen::Index>(i)) - mean) * (x(static_cast<Eigen::Index>(i)) - mean);
        means.push_back(mean);
        vars.push_back(ss / (n - 1.0));
      }
      double grand = 0.0, w = 0.0, b = 0.0;
      for (double x : means) grand += x / m;
      for (double x : means) b += n * (x - grand) * (x - grand) / (m - 1.0);
      for (double v : vars) w += v / m;
      const double v = (n - 1.0) / n * w + b / n;
      out.r_hat[i] = w > 0.0 ? std::sqrt(v / w) : kNaN;
    }
  return out;
}

}  // namespace crowdrecon::calibrate
