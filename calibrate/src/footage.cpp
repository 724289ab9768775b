#include "footage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Dense>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::calibrate {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
using Matrix = Eigen::MatrixXd;

// The first recording's statistics arranged for the design: each series'
// windows by their place in time, each count's whole-recording checkpoint.
struct Kind {
  std::string name;
  bool count = false;
  std::vector<std::size_t> statistic;  // series: by window index (SIZE_MAX: none); count: one
  double period_s = 0.0;               // count: the span its count covers
};

struct Layout {
  std::vector<Kind> kinds;
  std::size_t windows = 0;
  double window_s = 0.0;
  std::vector<std::string> left_out;
  std::string note;
};

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

Layout LayoutOf(const Objective& o, const std::vector<double>& jac, std::size_t p) {
  Layout l;
  const std::size_t n = o.statistics.size();
  const auto usable = [&](std::size_t j) {
    const double s = o.seed_covariance.empty() ? kNaN : o.seed_covariance[j * n + j];
    if (!(s > 0.0) || !std::isfinite(s)) return std::string("no spread of the seeds measured");
    for (std::size_t i = 0; i < p; ++i)
      if (!std::isfinite(jac[j * p + i])) return std::string("not fitted by the surrogate");
    return std::string();
  };
  std::size_t others = 0;
  double t0 = kInf;
  for (std::size_t j = 0; j < n; ++j) {
    const Statistic& st = o.statistics[j];
    if (st.observation != 0 || st.is_count || st.is_time) continue;
    if (l.window_s == 0.0) l.window_s = st.sim_to_s - st.sim_from_s;
    t0 = std::min(t0, st.sim_from_s);
  }
  std::map<std::string, std::size_t> index;
  for (std::size_t j = 0; j < n; ++j) {
    const Statistic& st = o.statistics[j];
    if (st.observation != 0) {
      ++others;
      continue;
    }
    if (st.is_time) {  // one time of one event: more footage of this kind does not repeat it
      l.left_out.push_back(st.name + ": the time of a single event, which longer or more footage does not add to");
      continue;
    }
    const std::string why = usable(j);
    if (!why.empty()) {
      l.left_out.push_back(st.name + ": " + why);
      continue;
    }
    const std::string name = st.quantity + " " + st.where + " " + st.direction +
                             (st.is_count ? " (count)" : st.is_max ? " (largest bin)" : "");
    auto [it, fresh] = index.emplace(name, l.kinds.size());
    if (fresh) l.kinds.push_back({name, st.is_count, {}, 0.0});
    Kind& k = l.kinds[it->second];
    if (st.is_count) {  // the checkpoint that covers the most: the recording's whole count
      if (k.statistic.empty() || st.sim_to_s > o.statistics[k.statistic[0]].sim_to_s) {
        k.statistic = {j};
        k.period_s = st.sim_to_s - st.sim_from_s;
      }
      continue;
    }
    const double w = st.sim_to_s - st.sim_from_s;
    const double place = (st.sim_from_s - t0) / l.window_s;
    if (std::abs(w - l.window_s) > 1e-6 * l.window_s || std::abs(place - std::round(place)) > 1e-6) {
      l.left_out.push_back(st.name + ": a window of " + FormatNumber(w) + " s from " + FormatNumber(st.sim_from_s) +
                           " s, not on the design's grid of " + FormatNumber(l.window_s) + "-s windows");
      continue;
    }
    const auto at = static_cast<std::size_t>(std::lround(place));
    if (k.statistic.size() <= at) k.statistic.resize(at + 1, kNone);
    k.statistic[at] = j;
    l.windows = std::max(l.windows, at + 1);
  }
  for (Kind& k : l.kinds)
    if (!k.count) k.statistic.resize(l.windows, kNone);
  if (others > 0)
    l.left_out.push_back(std::to_string(others) + " statistics of the other recordings (the design is for "
                         "recordings of the first one's kind)");
  if (l.kinds.empty()) l.note = "no statistic of the first recording has both a spread of the seeds and a Jacobian";
  return l;
}

// The parameters' covariance from the information of N recordings `m`
// windows long; `skip`: a kind left out (SIZE_MAX: none).
Matrix Covariance(const Objective& o, const std::vector<double>& jac, std::size_t p, const Layout& l, int recordings,
                  double m, double seeds, std::size_t skip) {
  const std::size_t n = o.statistics.size();
  const double a = 1.0 / recordings + (seeds > 0.0 ? 1.0 / seeds : 0.0), d = 1.0 / recordings;
  const auto s = [&](std::size_t i, std::size_t j) { return o.seed_covariance[i * n + j]; };
  const auto sigma2 = [&](std::size_t j) { return o.statistics[j].observed_sigma * o.statistics[j].observed_sigma; };
  Matrix info = Matrix::Zero(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(p));
  const auto add = [&](const Matrix& c, const Matrix& jr, double times) {
    if (c.rows() == 0) return;
    const Eigen::LDLT<Matrix> ldlt(c);
    info += times * jr.transpose() * ldlt.solve(jr);
  };
  // The series: the first min(m, windows) windows as they are.
  const std::size_t whole = static_cast<std::size_t>(std::floor(m + 1e-9));
  const std::size_t own = std::min(whole, l.windows);
  std::vector<std::size_t> rows;
  for (std::size_t g = 0; g < l.kinds.size(); ++g) {
    if (l.kinds[g].count || g == skip) continue;
    for (std::size_t w = 0; w < own; ++w)
      if (l.kinds[g].statistic[w] != kNone) rows.push_back(l.kinds[g].statistic[w]);
  }
  {
    const auto r = static_cast<Eigen::Index>(rows.size());
    Matrix c(r, r), jr(r, static_cast<Eigen::Index>(p));
    for (Eigen::Index x = 0; x < r; ++x) {
      for (Eigen::Index y = 0; y < r; ++y) c(x, y) = a * s(rows[x], rows[y]);
      c(x, x) += d * sigma2(rows[x]);
      for (std::size_t i = 0; i < p; ++i) jr(x, static_cast<Eigen::Index>(i)) = jac[rows[x] * p + i];
    }
    add(c, jr, 1.0);
  }
  // Beyond the recording's own windows: each further window adds the
  // information of the windows' long-run covariance.
  if (m > static_cast<double>(l.windows) + 1e-9) {
    std::vector<std::size_t> series;
    for (std::size_t g = 0; g < l.kinds.size(); ++g)
      if (!l.kinds[g].count && g != skip) series.push_back(g);
    const auto gs = static_cast<Eigen::Index>(series.size());
    Matrix longrun = Matrix::Zero(gs, gs), jw = Matrix::Zero(gs, static_cast<Eigen::Index>(p));
    Eigen::VectorXd obs = Eigen::VectorXd::Zero(gs);
    const std::size_t lags = l.windows;
    for (Eigen::Index x = 0; x < gs; ++x) {
      const Kind& kx = l.kinds[series[x]];
      std::size_t count = 0;
      for (std::size_t w = 0; w < lags; ++w)
        if (kx.statistic[w] != kNone) {
          for (std::size_t i = 0; i < p; ++i) jw(x, static_cast<Eigen::Index>(i)) += jac[kx.statistic[w] * p + i];
          obs(x) += sigma2(kx.statistic[w]);
          ++count;
        }
      jw.row(x) /= static_cast<double>(std::max<std::size_t>(count, 1));
      obs(x) /= static_cast<double>(std::max<std::size_t>(count, 1));
      for (Eigen::Index y = 0; y < gs; ++y) {
        const Kind& ky = l.kinds[series[y]];
        for (std::size_t lag = 0; lag < lags; ++lag) {  // R_xy(lag): x's window a, y's window a + lag
          double sum = 0.0;
          std::size_t pairs = 0;
          for (std::size_t w = 0; w + lag < lags; ++w)
            if (kx.statistic[w] != kNone && ky.statistic[w + lag] != kNone) {
              sum += s(kx.statistic[w], ky.statistic[w + lag]);
              ++pairs;
            }
          if (pairs == 0) continue;
          const double bartlett = 1.0 - static_cast<double>(lag) / static_cast<double>(lags);
          const double r = sum / static_cast<double>(pairs);
          longrun(x, y) += lag == 0 ? r : bartlett * r;
          if (lag > 0) longrun(y, x) += bartlett * r;
        }
      }
    }
    // Symmetric and positive: eigenvalues below 1e-9 of the largest raised to it.
    longrun = 0.5 * (longrun + longrun.transpose());
    if (gs > 0) {
      Eigen::SelfAdjointEigenSolver<Matrix> eig(longrun);
      Eigen::VectorXd ev = eig.eigenvalues();
      const double floor = 1e-9 * std::max(ev.maxCoeff(), 0.0);
      for (Eigen::Index k = 0; k < ev.size(); ++k) ev(k) = std::max(ev(k), floor);
      longrun = eig.eigenvectors() * ev.asDiagonal() * eig.eigenvectors().transpose();
      Matrix c = a * longrun;
      c.diagonal() += d * obs;
      add(c, jw, m - static_cast<double>(l.windows));
    }
  }
  // The counts: mean and the crowd's variance grow with the length; the
  // observed count's own half an event does not.
  std::vector<std::size_t> counts;
  for (std::size_t g = 0; g < l.kinds.size(); ++g)
    if (l.kinds[g].count && g != skip) counts.push_back(g);
  {
    const auto r = static_cast<Eigen::Index>(counts.size());
    Matrix c(r, r), jr(r, static_cast<Eigen::Index>(p));
    for (Eigen::Index x = 0; x < r; ++x) {
      const Kind& kx = l.kinds[counts[x]];
      const double fx = m * l.window_s / kx.period_s;
      for (Eigen::Index y = 0; y < r; ++y) {
        const Kind& ky = l.kinds[counts[y]];
        const double fy = m * l.window_s / ky.period_s;
        c(x, y) = a * s(kx.statistic[0], ky.statistic[0]) * std::sqrt(fx * fy);
      }
      c(x, x) += d * sigma2(kx.statistic[0]);
      for (std::size_t i = 0; i < p; ++i) jr(x, static_cast<Eigen::Index>(i)) = fx * jac[kx.statistic[0] * p + i];
    }
    add(c, jr, 1.0);
  }
  // A parameter nothing informs is undetermined; the others' covariance is
  // the inverse of their information.
  std::vector<Eigen::Index> known;
  const double largest = info.diagonal().maxCoeff();
  for (Eigen::Index i = 0; i < info.rows(); ++i)
    if (info(i, i) > 1e-12 * largest && info(i, i) > 0.0) known.push_back(i);
  Matrix cov = Matrix::Constant(info.rows(), info.cols(), kNaN);
  const auto k = static_cast<Eigen::Index>(known.size());
  Matrix sub(k, k);
  for (Eigen::Index x = 0; x < k; ++x)
    for (Eigen::Index y = 0; y < k; ++y) sub(x, y) = info(known[x], known[y]);
  const Eigen::LLT<Matrix> llt(sub);
  if (k == 0 || llt.info() != Eigen::Success) return cov;
  const Matrix inv = llt.solve(Matrix::Identity(k, k));
  for (Eigen::Index x = 0; x < k; ++x)
    for (Eigen::Index y = 0; y < k; ++y) cov(known[x], known[y]) = inv(x, y);
  return cov;
}

std::vector<double> Sds(const Matrix& cov) {
  std::vector<double> sd;
  for (Eigen::Index i = 0; i < cov.rows(); ++i) sd.push_back(std::sqrt(cov(i, i)));
  return sd;
}

// The smallest whole number x in [lo, hi] with ok(x), by bisection (ok is
// monotone: more footage never knows less); inf when even hi is not enough.
template <typename Ok>
double Smallest(double lo, double hi, const Ok& ok) {
  if (!ok(hi)) return kInf;
  if (ok(lo)) return lo;
  while (hi - lo > 1.0) {
    const double mid = std::floor(0.5 * (lo + hi));
    (ok(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace

std::vector<double> FootageCovariance(const Objective& objective, const std::vector<double>& jacobian,
                                      std::size_t parameters, int recordings, double windows, double seeds) {
  const Layout l = LayoutOf(objective, jacobian, parameters);
  if (!l.note.empty()) return std::vector<double>(parameters * parameters, kNaN);
  const Matrix c = Covariance(objective, jacobian, parameters, l, recordings, windows, seeds, kNone);
  std::vector<double> out(parameters * parameters);
  for (std::size_t i = 0; i < parameters; ++i)
    for (std::size_t k = 0; k < parameters; ++k)
      out[i * parameters + k] = c(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k));
  return out;
}

FootageDesign DesignFootage(const Objective& objective, const std::vector<double>& jacobian,
                            const std::vector<double>& best, const FootageOptions& options) {
  FootageDesign d;
  const std::size_t p = best.size();
  if (p == 0 || jacobian.size() != objective.statistics.size() * p || objective.seed_covariance.empty()) {
    d.note = "no Jacobian at a best fit, or no seeds' covariance";
    return d;
  }
  const Layout l = LayoutOf(objective, jacobian, p);
  d.left_out = l.left_out;
  d.note = l.note;
  if (!d.note.empty()) return d;
  if (l.windows == 0) {  // counts alone: the design's unit is the counts' span
    d.note = "no series of the first recording (counts alone): no window to measure footage in";
    return d;
  }
  d.targets = options.targets;
  d.window_s = l.window_s;
  d.windows = l.windows;
  d.recording_s = static_cast<double>(l.windows) * l.window_s;
  for (const Kind& k : l.kinds) d.kinds.push_back(k.name);
  const auto cov = [&](int n, double m, std::size_t skip = kNone) {
    return Covariance(objective, jacobian, p, l, n, m, options.seeds, skip);
  };
  std::vector<double> lengths = options.lengths_s;
  if (lengths.empty())
    for (double f : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0})
      lengths.push_back(std::max(1.0, std::round(f * static_cast<double>(l.windows))) * l.window_s);
  std::sort(lengths.begin(), lengths.end());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  for (int n : options.recordings)
    for (double t : lengths) d.rows.push_back({n, t, Sds(cov(n, std::max(1.0, std::round(t / l.window_s))))});

  const double own = static_cast<double>(l.windows);
  {
    std::size_t observations = 0;
    for (const Statistic& st : objective.statistics) observations = std::max(observations, st.observation + 1);
    std::vector<bool> alike(observations, true);
    for (std::size_t j = 0; j < objective.statistics.size(); ++j)
      if (j >= objective.lead.size() || objective.statistics[objective.lead[j]].observation != 0)
        alike[objective.statistics[j].observation] = false;
    d.recordings_now = std::max(1, static_cast<int>(std::count(alike.begin(), alike.end(), true)));
    d.sd_now = Sds(Covariance(objective, jacobian, p, l, d.recordings_now, own, objective.seeds, kNone));
  }
  for (double target : options.targets) {
    std::vector<double> one(p), many(p);
    for (std::size_t i = 0; i < p; ++i) {
      if (best[i] == 0.0) {
        one[i] = many[i] = kNaN;
        continue;
      }
      const double limit = target * std::abs(best[i]) / 1.96;
      const auto enough = [&](double sd) { return std::isfinite(sd) && sd <= limit; };
      one[i] = Smallest(1.0, 1e7, [&](double m) { return enough(Sds(cov(1, m))[i]); }) * l.window_s;
      many[i] = Smallest(1.0, 1e6, [&](double n) { return enough(Sds(cov(static_cast<int>(n), own))[i]); });
    }
    d.one_recording_s.push_back(one);
    d.recordings_needed.push_back(many);
  }
  const std::vector<double> all = Sds(cov(1, own));
  for (std::size_t g = 0; g < l.kinds.size(); ++g) {
    const std::vector<double> without = Sds(cov(1, own, g));
    std::vector<double> lost(p);
    for (std::size_t i = 0; i < p; ++i)
      lost[i] = !std::isfinite(all[i]) ? kNaN : !std::isfinite(without[i]) ? 1.0
                                                                             : 1.0 - (all[i] * all[i]) / (without[i] * without[i]);
    d.share_lost.push_back(lost);
  }
  // The Fisher information's diagonal by kind, each statistic alone.
  const std::size_t n = objective.statistics.size();
  std::vector<std::vector<double>> diag(l.kinds.size(), std::vector<double>(p, 0.0));
  std::vector<double> total(p, 0.0);
  for (std::size_t g = 0; g < l.kinds.size(); ++g)
    for (std::size_t j : l.kinds[g].statistic) {
      if (j == kNone) continue;
      const double var = objective.seed_covariance[j * n + j] +
                         objective.statistics[j].observed_sigma * objective.statistics[j].observed_sigma;
      for (std::size_t i = 0; i < p; ++i) {
        const double f = jacobian[j * p + i] * jacobian[j * p + i] / var;
        diag[g][i] += f;
        total[i] += f;
      }
    }
  for (auto& row : diag)
    for (std::size_t i = 0; i < p; ++i) row[i] = total[i] > 0.0 ? row[i] / total[i] : kNaN;
  d.information_share = diag;
  return d;
}

}  // namespace crowdrecon::calibrate
