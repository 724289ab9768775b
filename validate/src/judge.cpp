// Judging a test's criteria over its seeds (validate.hpp: Judge).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "crowdrecon/validate/validate.hpp"
#include "pooled.hpp"

namespace crowdrecon::validate {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Num(double v) {
  if (!std::isfinite(v)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

std::size_t FailedRuns(const std::vector<Statistics>& runs) {
  std::size_t n = 0;
  for (const Statistics& s : runs) {
    const auto it = s.find("completed");
    if (it == s.end() || it->second.empty() || it->second[0] != 1.0) ++n;
  }
  return n;
}

std::string Range(double lo, double hi) {
  if (std::isinf(lo) && lo < 0) return "<= " + Num(hi);
  if (std::isinf(hi)) return ">= " + Num(lo);
  return "[" + Num(lo) + ", " + Num(hi) + "]";
}

CaseVerdict JudgeCase(const Criterion& c, const Case& k, const std::vector<Statistics>& runs,
                      const std::optional<Statistics>& data) {
  CaseVerdict v;
  v.case_name = k.name;
  const std::vector<double> values = Pooled(runs, c.statistic);
  const std::size_t failed = FailedRuns(runs);
  v.value = AggregateOf(values, c.aggregate);
  const std::string over = std::to_string(runs.size()) + (runs.size() == 1 ? " run" : " runs") +
                           (failed ? ", " + std::to_string(failed) + " failed" : "");
  v.text = (c.aggregate == Aggregate::kEvery && !values.empty() ? Num(values.front()) + " - " + Num(values.back()) + " (every value)"
                                                                 : Num(v.value) + " (" + ToString(c.aggregate) + ")") +
           ", " + std::to_string(values.size()) + " values over " + over;
  auto judge_range = [&](double lo, double hi) {
    v.expected = Range(lo, hi);
    v.judged = true;
    if (values.empty()) {
      v.pass = false;
      v.text = "no value (" + over + ")";
      return;
    }
    if (c.aggregate == Aggregate::kEvery)
      v.pass = values.front() >= lo && values.back() <= hi;
    else
      v.pass = v.value >= lo && v.value <= hi;
    // A run that failed fails the criterion: its values are missing.
    if (failed) v.pass = false;
  };
  switch (c.kind) {
    case CriterionKind::kWithin: judge_range(c.low, c.high); break;
    case CriterionKind::kNearReference: {
      const auto [lo, hi] = std::minmax_element(k.reference.begin(), k.reference.end());
      judge_range(*lo * (1.0 - c.relative), *hi * (1.0 + c.relative));
      v.expected += " (published " + Num(*lo) + (*hi > *lo ? "-" + Num(*hi) : "") + " +- " + Num(100 * c.relative) + " %)";
      break;
    }
    case CriterionKind::kWithinData:
    case CriterionKind::kNearData: {
      const std::vector<double> d = data ? Pooled({*data}, c.statistic) : std::vector<double>{};
      if (d.empty()) {
        v.expected = "the data has no " + c.statistic;
        break;
      }
      if (c.kind == CriterionKind::kWithinData) {
        judge_range(Quantile(d, c.quantile_low), Quantile(d, c.quantile_high));
        v.expected += " (data's " + Num(100 * c.quantile_low) + "-" + Num(100 * c.quantile_high) + " % quantiles)";
      } else {
        const double ref = AggregateOf(d, c.aggregate == Aggregate::kEvery ? Aggregate::kMedian : c.aggregate);
        judge_range(ref * (1.0 - c.relative), ref * (1.0 + c.relative));
        v.expected += " (data " + Num(ref) + " +- " + Num(100 * c.relative) + " %)";
      }
      break;
    }
    case CriterionKind::kDataBand: {
      // The run's mean density and speed (median over seeds) against the
      // data's frame samples at that density.
      const double rho = AggregateOf(Pooled(runs, "density_per_m2"), Aggregate::kMedian);
      v.value = AggregateOf(Pooled(runs, "speed_m_per_s"), Aggregate::kMedian);
      v.text = Num(v.value) + " m/s at " + Num(rho) + " /m2 (median over " + over + ")";
      if (!data || !std::isfinite(rho) || !std::isfinite(v.value)) {
        v.expected = "no data or no value";
        v.judged = !std::isfinite(v.value);
        v.pass = false;
        break;
      }
      const auto dr = data->find("fd_density_per_m2"), dv = data->find("fd_speed_m_per_s");
      std::vector<double> near;
      if (dr != data->end() && dv != data->end())
        for (std::size_t i = 0; i < dr->second.size() && i < dv->second.size(); ++i)
          if (std::abs(dr->second[i] - rho) <= 0.5 * c.band_width_per_m2 && std::isfinite(dv->second[i]))
            near.push_back(dv->second[i]);
      if (near.size() < 10) {
        v.expected = "the data has " + std::to_string(near.size()) + " samples at " + Num(rho) +
                     " /m2 (fewer than 10): not judged";
        break;
      }
      double mean = 0, var = 0;
      for (double x : near) mean += x;
      mean /= double(near.size());
      for (double x : near) var += (x - mean) * (x - mean);
      const double sd = std::sqrt(var / double(near.size() - 1));
      v.expected = Range(mean - c.band_sd * sd, mean + c.band_sd * sd) + " m/s (data: " + Num(mean) + " +- " +
                   Num(c.band_sd) + " x " + Num(sd) + ", " + std::to_string(near.size()) + " samples)";
      v.judged = true;
      v.pass = failed == 0 && std::abs(v.value - mean) <= c.band_sd * sd;
      break;
    }
    case CriterionKind::kDocuments: {
      v.expected = "documented only";
      const std::vector<double> d = data ? Pooled({*data}, c.statistic) : std::vector<double>{};
      if (!d.empty()) v.expected += "; the experiment: " + Num(AggregateOf(d, c.aggregate == Aggregate::kEvery ? Aggregate::kMedian : c.aggregate));
      break;
    }
    case CriterionKind::kFollows: {
      // Kolmogorov-Smirnov: the largest distance between the values' empirical
      // CDF and the distribution's, against the critical value at alpha
      // (the asymptotic one with Stephens' correction for small n).
      v.expected = "D <= critical value at alpha " + Num(c.alpha) + " (" + c.distribution.Describe() + ")";
      v.judged = true;
      if (values.empty()) {
        v.pass = false;
        v.text = "no value (" + over + ")";
        break;
      }
      const double n = double(values.size());
      double d = 0.0;
      for (std::size_t i = 0; i < values.size(); ++i) {
        const double f = c.distribution.Cdf(values[i]);
        d = std::max({d, double(i + 1) / n - f, f - double(i) / n});
      }
      const double critical = std::sqrt(-0.5 * std::log(c.alpha / 2.0)) / (std::sqrt(n) + 0.12 + 0.11 / std::sqrt(n));
      v.value = d;
      v.text = "D " + Num(d) + " (critical " + Num(critical) + "), " + std::to_string(values.size()) + " values over " + over;
      v.pass = failed == 0 && d <= critical;
      break;
    }
    case CriterionKind::kIncreasing:
    case CriterionKind::kRatio: break;  // (over cases: in Judge)
  }
  return v;
}

}  // namespace

std::string ToString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPass: return "pass";
    case Verdict::kFail: return "fail";
    case Verdict::kDocuments: return "documents";
    case Verdict::kError: return "error";
  }
  return "?";
}

TestResult Judge(const ValidationTest& test, const std::string& profile, std::vector<std::vector<Statistics>> runs,
                 std::optional<Statistics> data) {
  TestResult r;
  r.test_id = test.id;
  r.profile = profile;
  r.runs = std::move(runs);
  r.data = std::move(data);
  const auto case_index = [&](const std::string& name) {
    for (std::size_t i = 0; i < test.cases.size(); ++i)
      if (test.cases[i].name == name) return i;
    return test.cases.size();
  };
  bool any_judged = false, all_pass = true;
  for (const Criterion& c : test.criteria) {
    CriterionVerdict cv;
    cv.criterion = c;
    std::vector<std::size_t> which;
    for (std::size_t i = 0; i < test.cases.size(); ++i)
      if (c.AppliesTo(test.cases[i].name)) which.push_back(i);
    if (c.kind == CriterionKind::kIncreasing || c.kind == CriterionKind::kRatio) {
      // Over cases: each case's aggregate, then the rise or the ratio.
      std::vector<double> agg;
      std::string values;
      std::size_t failed = 0;
      for (std::size_t i : which) {
        agg.push_back(AggregateOf(Pooled(r.runs[i], c.statistic), c.aggregate));
        failed += FailedRuns(r.runs[i]);
        values += (values.empty() ? "" : ", ") + test.cases[i].name + " " + Num(agg.back());
      }
      CaseVerdict v;
      v.case_name = "all";
      v.judged = true;
      if (c.kind == CriterionKind::kIncreasing) {
        v.pass = agg.size() >= 2;
        for (std::size_t i = 1; i < agg.size(); ++i) v.pass = v.pass && agg[i] > agg[i - 1];
        v.value = agg.empty() ? kNaN : agg.back();
        v.text = values;
        v.expected = "rising from case to case";
      } else {
        const double a = AggregateOf(Pooled(r.runs[case_index(c.case_a)], c.statistic), c.aggregate);
        const double b = AggregateOf(Pooled(r.runs[case_index(c.case_b)], c.statistic), c.aggregate);
        v.value = b / a;
        v.pass = std::isfinite(v.value) && v.value >= c.low && v.value <= c.high;
        v.text = Num(v.value) + " (" + c.case_b + " " + Num(b) + " / " + c.case_a + " " + Num(a) + ")";
        v.expected = Range(c.low, c.high);
      }
      if (failed) {
        v.pass = false;
        v.text += "; " + std::to_string(failed) + " runs failed";
      }
      cv.cases.push_back(v);
    } else {
      for (std::size_t i : which) cv.cases.push_back(JudgeCase(c, test.cases[i], r.runs[i], r.data));
    }
    cv.judged = std::any_of(cv.cases.begin(), cv.cases.end(), [](const CaseVerdict& v) { return v.judged; });
    cv.pass = cv.judged && std::all_of(cv.cases.begin(), cv.cases.end(), [](const CaseVerdict& v) { return !v.judged || v.pass; });
    any_judged = any_judged || cv.judged;
    if (cv.judged && !cv.pass) all_pass = false;
    r.criteria.push_back(std::move(cv));
  }
  r.verdict = !any_judged ? Verdict::kDocuments : (all_pass ? Verdict::kPass : Verdict::kFail);
  for (std::size_t i = 0; i < r.runs.size(); ++i)
    for (std::size_t s = 0; s < r.runs[i].size(); ++s)
      if (FailedRuns({r.runs[i][s]})) r.failures.push_back(test.cases[i].name + ", run " + std::to_string(s + 1) + ": did not complete");
  return r;
}

}  // namespace crowdrecon::validate
