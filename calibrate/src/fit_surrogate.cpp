// The quadratic surrogate of the statistics and Ceres minimising it (fit.hpp).
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

std::vector<std::size_t> FittedRows(const Quadratic& q, const Objective& o) {
  std::vector<std::size_t> rows;
  const std::vector<double> probe = q.Values(q.centre);
  for (std::size_t j = 0; j < o.statistics.size(); ++j)
    if (std::isfinite(probe[o.lead[j]]) && std::isfinite(o.sigma[j]) && o.sigma[j] > 0) rows.push_back(j);
  return rows;
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

}  // namespace crowdrecon::calibrate
