// The posterior of a calibration (fit.hpp): local quadratics, the estimated covariance, the likelihood, quantiles.
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
                                 std::uint64_t seed, const std::function<bool()>& stop) {
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
      if (stop && step % 100 == 0 && stop()) {
        out.interrupted = true;
        return out;
      }
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
