// The validation report (validation_report.hpp): a summary table at the top,
// the split between fitted and held-out tests, then a section per test with
// its setup drawn, its criteria judged per profile and its figure (the
// model's spread over seeds beside the data), and the record of what made it.
#include "validation_report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/observe/fundamental_diagram.hpp"
#include "crowdrecon/reports/html_page.hpp"
#include "crowdrecon/reports/svg.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "pooled.hpp"

namespace crowdrecon::validate {

namespace fs = std::filesystem;
using json = nlohmann::json;
namespace svg = reports::svg;

namespace {

const char* const kProfileColor[] = {"#1f4e79", "#c0392b"};
const char* const kDataColor = "#7f7f7f";

std::string Esc(const std::string& s) { return svg::Escape(s); }

std::string VerdictCell(Verdict v) {
  const char* color = v == Verdict::kPass ? "#2e8b57" : v == Verdict::kFail ? "#c0392b" : v == Verdict::kError ? "#8e44ad" : "#666";
  return "<b style=\"color:" + std::string(color) + "\">" + ToString(v) + "</b>";
}

std::string CaseCell(const CaseVerdict& v) {
  const std::string mark = !v.judged ? "&#8211;" : v.pass ? "<b style=\"color:#2e8b57\">pass</b>" : "<b style=\"color:#c0392b\">fail</b>";
  return mark + " " + Esc(v.text) + "<br><span class=\"range\">expected " + Esc(v.expected) + "</span>";
}

// The setup: the first profile's first run's walls and start positions.
std::string SetupFigure(const ValidationTest& t, const TestResult& r) {
  if (r.walls.empty()) return "";
  svg::Plan plan;
  plan.title = "Setup: walls and the people at the start (first run)";
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (const auto& w : r.walls)
    for (const Vec2& p : w) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
  plan.min_m = lo - Vec2{0.5, 0.5};
  plan.max_m = hi + Vec2{0.5, 0.5};
  // At most about 460 px tall: a tall venue is drawn narrower, centred in a
  // figure at least 600 px wide, so that its title and legend are not cut
  // (they were for RiMEA 12a, 12b and 15).
  const Vec2 span = plan.max_m - plan.min_m;
  plan.width = std::clamp(460.0 * span.x / std::max(span.y, 1e-6), 600.0, 760.0);
  const double drawn_x = span.y * (plan.width - 32.0) / 460.0;  // the x span that keeps the plan ~460 px tall
  if (drawn_x > span.x) {
    plan.min_m.x -= (drawn_x - span.x) / 2.0;
    plan.max_m.x += (drawn_x - span.x) / 2.0;
  }
  plan.walls = r.walls;
  for (const Vec2& p : r.start_positions) plan.dots.push_back({p, kProfileColor[0], 0.2, ""});
  const MeasureSpec& m = t.measure;
  auto line = [&](const observe::Line& l) { plan.walls.push_back({l.a_m, l.b_m}); };
  if (m.kind == MeasureKind::kTravel) {
    line(m.from_line);
    line(m.to_line);
  }
  if (m.kind == MeasureKind::kPassages) line(m.line);
  if (m.has_area) {
    std::vector<Vec2> ring = m.area.polygon_m;
    ring.push_back(ring.front());
    plan.area.push_back(ring);
  }
  plan.legend = {{kProfileColor[0], std::to_string(r.start_positions.size()) + " people at the start"},
                 {"#f2f2ee", "measurement area (shaded), measurement lines drawn as walls"}};
  return "<figure>" + plan.ToSvg() + "</figure>\n";
}

// The fundamental diagram: the data's frame samples, each run's mean, Weidmann.
std::string FdFigure(const ValidationTest& t, const std::vector<const TestResult*>& per_profile,
                     const std::vector<Profile>& profiles) {
  svg::Chart c;
  c.title = t.title + ": speed against density";
  c.x_label = "density in the measurement area, persons/m2";
  c.y_label = "mean speed, m/s";
  c.x_min = 0;
  c.y_min = 0;
  c.y_max = 2.0;
  double max_rho = 1.0;
  if (per_profile.front()->data) {
    const Statistics& d = *per_profile.front()->data;
    svg::Series s;
    s.label = "experiment (" + (t.data ? t.data->label : std::string("data")) + "), every 5th frame";
    s.color = kDataColor;
    s.line = false;
    s.marker_radius = 1.6;
    const auto& rho = d.at("fd_density_per_m2");
    const auto& v = d.at("fd_speed_m_per_s");
    for (std::size_t i = 0; i < rho.size() && i < v.size(); i += 1) {
      s.x.push_back(rho[i]);
      s.y.push_back(v[i]);
      max_rho = std::max(max_rho, rho[i]);
    }
    c.series.push_back(s);
  }
  for (std::size_t p = 0; p < per_profile.size(); ++p) {
    svg::Series s;
    s.label = "model, profile " + profiles[p].name + " (each run's mean)";
    s.color = kProfileColor[p % 2];
    s.line = false;
    s.marker_radius = 4.5;
    for (const auto& runs : per_profile[p]->runs)
      for (const Statistics& st : runs) {
        const auto a = st.find("density_per_m2"), b = st.find("speed_m_per_s");
        if (a == st.end() || b == st.end() || a->second.empty() || b->second.empty()) continue;
        s.x.push_back(a->second[0]);
        s.y.push_back(b->second[0]);
        if (std::isfinite(a->second[0])) max_rho = std::max(max_rho, a->second[0]);
      }
    c.series.push_back(s);
  }
  svg::Series w;
  w.label = "Weidmann (1993)";
  w.color = "#000";
  w.dashed = true;
  const observe::WeidmannRelation weidmann;
  for (double rho = 0.3; rho <= std::min(5.4, max_rho * 1.1); rho += 0.05) {
    w.x.push_back(rho);
    w.y.push_back(weidmann.SpeedAt(rho));
  }
  c.series.push_back(w);
  c.x_max = std::ceil(max_rho * 1.1);
  return "<figure>" + c.ToSvg() + "<figcaption>Grey: the experiment's frames (density and mean speed in the area); " +
         "coloured: each run of the model measured by the same code.</figcaption></figure>\n";
}

// A statistic against the cases' x: each run's value (dots), the median over
// seeds (line), the published values (dashed).
std::string CasesFigure(const ValidationTest& t, const Criterion& crit, const std::vector<const TestResult*>& per_profile,
                        const std::vector<Profile>& profiles) {
  svg::Chart c;
  c.title = t.title + ": " + crit.statistic;
  c.x_label = t.x_label.empty() ? "case" : t.x_label;
  c.y_label = crit.statistic;
  c.legend_left = true;
  for (std::size_t p = 0; p < per_profile.size(); ++p) {
    svg::Series dots, median;
    dots.color = median.color = kProfileColor[p % 2];
    dots.line = false;
    dots.marker_radius = 3;
    median.label = "model, profile " + profiles[p].name + " (median over seeds; dots: runs)";
    for (std::size_t k = 0; k < t.cases.size(); ++k) {
      std::vector<double> per_run;
      for (const Statistics& st : per_profile[p]->runs[k]) {
        const auto it = st.find(crit.statistic);
        if (it == st.end() || it->second.empty()) continue;
        const double v = AggregateOf(Finite(it->second), Aggregate::kMedian);
        per_run.push_back(v);
        dots.x.push_back(t.cases[k].x);
        dots.y.push_back(v);
      }
      median.x.push_back(t.cases[k].x);
      median.y.push_back(AggregateOf(Finite(per_run), Aggregate::kMedian));
    }
    c.series.push_back(dots);
    c.series.push_back(median);
  }
  svg::Series lo, hi;
  lo.color = hi.color = "#000";
  lo.dashed = hi.dashed = true;
  lo.label = "published (lowest and highest value)";
  for (const Case& k : t.cases) {
    if (k.reference.empty()) continue;
    lo.x.push_back(k.x);
    hi.x.push_back(k.x);
    lo.y.push_back(*std::min_element(k.reference.begin(), k.reference.end()));
    hi.y.push_back(*std::max_element(k.reference.begin(), k.reference.end()));
  }
  if (!lo.x.empty()) {
    c.series.push_back(lo);
    c.series.push_back(hi);
  }
  c.y_min = 0;
  return "<figure>" + c.ToSvg() + "</figure>\n";
}

// The distribution of a statistic's values (every seed pooled) per profile
// and the data's, with the criterion's band.
std::string DistributionFigure(const ValidationTest& t, const Criterion& crit, const std::string& statistic, bool log,
                               const std::vector<const TestResult*>& per_profile, const std::vector<Profile>& profiles) {
  svg::Chart c;
  c.title = statistic + ": the share of values above each value (every seed)";
  c.x_label = statistic;
  c.y_label = "share of values above";
  c.log_x = c.log_y = log;
  if (!log) {
    c.y_min = 0;
    c.y_max = 1.02;
  }
  c.legend_left = false;
  auto add = [&](std::vector<double> v, const std::string& label, const std::string& color, bool dashed) {
    if (v.empty()) return;
    svg::Series s;
    s.label = label + ", " + std::to_string(v.size()) + " values";
    s.color = color;
    s.dashed = dashed;
    s.step = true;
    for (std::size_t i = 0; i < v.size(); ++i) {
      s.x.push_back(v[i]);
      s.y.push_back(double(v.size() - i) / double(v.size()));
    }
    if (v.size() == 1) {  // a single value: a visible step
      s.x.push_back(v[0]);
      s.y.push_back(0.0);
    }
    c.series.push_back(s);
  };
  for (std::size_t p = 0; p < per_profile.size(); ++p) {
    std::vector<Statistics> all;
    for (const auto& runs : per_profile[p]->runs) all.insert(all.end(), runs.begin(), runs.end());
    add(Pooled(all, statistic), "model, " + profiles[p].name, kProfileColor[p % 2], false);
  }
  if (per_profile.front()->data)
    add(Pooled({*per_profile.front()->data}, statistic), "experiment", kDataColor, true);
  if (per_profile.front()->data && t.data) c.title += "; experiment: " + t.data->label;
  if (crit.kind == CriterionKind::kWithin && crit.statistic == statistic) {
    if (std::isfinite(crit.low)) c.x_marks.push_back({crit.low, "criterion " + svg::Short(crit.low)});
    if (std::isfinite(crit.high)) c.x_marks.push_back({crit.high, "criterion " + svg::Short(crit.high)});
  }
  if (c.series.empty()) return "<p class=\"note\">No values to draw (every run failed or none measured it).</p>\n";
  return "<figure>" + c.ToSvg() + "</figure>\n";
}

// For each "follows" criterion: the survival function of the values of its
// cases (every seed pooled) per profile beside the distribution's.
std::string FollowsFigures(const ValidationTest& t, const std::vector<const TestResult*>& per_profile,
                           const std::vector<Profile>& profiles) {
  std::string out = "<div style=\"display:flex;flex-wrap:wrap;gap:8px\">";
  for (const Criterion& crit : t.criteria) {
    if (crit.kind != CriterionKind::kFollows) continue;
    svg::Chart c;
    std::string cases;
    for (const Case& k : t.cases)
      if (crit.AppliesTo(k.name))
        cases += (cases.empty() ? "" : ", ") + k.label;
    c.title = cases;  // (a case's label names its distribution; the criterion table gives it in full)
    c.x_label = crit.statistic;
    c.y_label = "share of values above";
    c.width = 340;
    c.height = 260;
    c.x_min = 0;
    c.y_min = 0;
    c.y_max = 1.02;
    c.legend_left = true;  // the curves fall from the top left: the bottom left is free
    c.legend_bottom = true;
    double x_max = 0;
    for (std::size_t p = 0; p < per_profile.size(); ++p) {
      std::vector<Statistics> all;
      for (std::size_t i = 0; i < t.cases.size(); ++i)
        if (crit.AppliesTo(t.cases[i].name))
          all.insert(all.end(), per_profile[p]->runs[i].begin(), per_profile[p]->runs[i].end());
      const std::vector<double> v = Pooled(all, crit.statistic);
      if (v.empty()) continue;
      svg::Series s;
      s.label = "model, " + profiles[p].name + " (" + std::to_string(v.size()) + ")";
      s.color = kProfileColor[p % 2];
      s.step = true;
      s.x.push_back(0);
      s.y.push_back(1);
      for (std::size_t i = 0; i < v.size(); ++i) {
        s.x.push_back(v[i]);
        s.y.push_back(double(v.size() - i - 1) / double(v.size()));
      }
      x_max = std::max(x_max, v.back());
      c.series.push_back(s);
    }
    if (c.series.empty()) continue;
    svg::Series d;
    d.label = "the distribution";
    d.color = kDataColor;
    d.dashed = true;
    for (int i = 0; i <= 200; ++i) {
      const double x = 1.05 * x_max * i / 200.0;
      d.x.push_back(x);
      d.y.push_back(1.0 - crit.distribution.Cdf(x));
    }
    c.series.push_back(d);
    out += "<figure style=\"margin:0\">" + c.ToSvg() + "</figure>";
  }
  return out + "</div>\n";
}

// Passages counted over time, each run a line (from its lapses), and the
// experiment's: a clog is a plateau, the flow the slope.
std::string CumulativeFigure(const ValidationTest& t, const std::vector<const TestResult*>& per_profile,
                             const std::vector<Profile>& profiles) {
  svg::Chart c;
  c.title = "People through the line against time since the first passage";
  c.x_label = "time since the first passage, s";
  c.y_label = "people through";
  c.legend_left = true;
  c.x_min = 0;
  c.y_min = 0;
  auto add = [&](const Statistics& s, const std::string& color, const std::string& label, bool dashed, double width) {
    const auto it = s.find("lapse_s");
    if (it == s.end()) return false;
    svg::Series line;
    line.color = color;
    line.label = label;
    line.dashed = dashed;
    line.width = width;
    line.step = true;
    double time = 0;
    line.x.push_back(0);
    line.y.push_back(1);
    for (std::size_t k = 0; k < it->second.size(); ++k) {
      time += it->second[k];
      line.x.push_back(time);
      line.y.push_back(double(k + 2));
    }
    const auto open = s.find("open_lapse_s");
    if (open != s.end() && !open->second.empty() && open->second[0] > 0) {  // a clog to the end
      line.x.push_back(time + open->second[0]);
      line.y.push_back(line.y.back());
    }
    c.series.push_back(line);
    return true;
  };
  for (std::size_t p = 0; p < per_profile.size(); ++p) {
    bool labelled = false;
    for (std::size_t k = 0; k < per_profile[p]->runs.size(); ++k)
      for (const Statistics& s : per_profile[p]->runs[k])
        labelled = add(s, kProfileColor[p % 2], labelled ? "" : "model, profile " + profiles[p].name + " (each run)", false,
                       1.0) || labelled;
  }
  if (per_profile.front()->data)
    add(*per_profile.front()->data, "#000", "experiment (" + (t.data ? t.data->label : std::string("data")) + ")", true, 2.4);
  if (c.series.empty()) return "<p class=\"note\">No passages to draw.</p>\n";
  return "<figure>" + c.ToSvg() + "<figcaption>Each step one person through the line; a flat stretch is a clog, and a " +
         "line that ends flat is a clog that lasted to the end of the run.</figcaption></figure>\n";
}

std::string Figures(const ValidationTest& t, const std::vector<const TestResult*>& per_profile,
                    const std::vector<Profile>& profiles) {
  if (t.measure.kind == MeasureKind::kFundamentalDiagram) return FdFigure(t, per_profile, profiles);
  if (t.criteria.empty()) return "";
  const Criterion& first = t.criteria.front();
  if (std::any_of(t.criteria.begin(), t.criteria.end(), [](const Criterion& c) { return c.kind == CriterionKind::kFollows; }))
    return FollowsFigures(t, per_profile, profiles);
  if (t.figure.kind == FigureSpec::Kind::kCumulative) return CumulativeFigure(t, per_profile, profiles);
  if (t.figure.kind == FigureSpec::Kind::kDistribution)
    return DistributionFigure(t, first, t.figure.statistic.empty() ? first.statistic : t.figure.statistic, t.figure.log,
                              per_profile, profiles);
  const bool has_x = t.cases.size() > 1 &&
                     std::all_of(t.cases.begin(), t.cases.end(), [](const Case& k) { return std::isfinite(k.x); });
  if (has_x) return CasesFigure(t, first, per_profile, profiles);
  return DistributionFigure(t, first, first.statistic, false, per_profile, profiles);
}

std::string FileDigest(const fs::path& f) { return Sha256Hex(ReadInputFile(f, "file")).substr(0, 16); }

std::string Today() {
  const std::time_t now = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return b;
}

std::string Html(const ValidateOptions& options, const ValidateSummary& s) {
  const std::size_t np = s.profiles.size();
  std::string profiles_text;
  for (const Profile& p : s.profiles) profiles_text += (profiles_text.empty() ? "" : " beside ") + p.name;
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"generator\" content=\"crowdrecon validate\">\n<title>Validation: " +
                  Esc(profiles_text) + "</title>\n<style>" + reports::html::Css() +
                  "\nsection.test { page-break-before: always; }\ntd, th { text-align: left; }\n</style></head><body>\n";
  h += "<h1>crowdrecon validation: profile " + Esc(profiles_text) + "</h1>\n";
  // The runs' own wall time (their single-core seconds summed, whichever
  // call ran them: runs reused from earlier calls count), and this call's.
  double runs_s = 0.0;
  for (const auto& per_profile : s.results)
    for (const TestResult& r : per_profile) runs_s += r.wall_s;
  char line[480];
  std::snprintf(line, sizeof line,
                "%zu tests, %d pass, %d fail, %d document behaviour only, %d could not run; the runs: %.1f h of "
                "single-core wall time in all (this call: %.0f s); build %s (sources %s); %s.",
                s.tests.size() * np, s.Count(Verdict::kPass), s.Count(Verdict::kFail), s.Count(Verdict::kDocuments),
                s.Count(Verdict::kError), runs_s / 3600.0, s.wall_s, sweep::BuildVersion().c_str(),
                sweep::SourceFingerprint().c_str(), Today().c_str());
  h += "<p class=\"sub\">" + Esc(line) + "</p>\n";
  h += "<p class=\"note\">Every test is a file of the suite (" + Esc(options.suite.string()) +
       "): its source, setup, criterion and tolerance. Runs and experiments are measured by the same code; a criterion "
       "pools its statistic over every seed of a case. <b>documents</b>: the standard gives no pass band (it documents "
       "behaviour); such results are shown, not judged. How to read and how to validate a profile of your own: "
       "docs/validation.md.</p>\n";

  // Summary table.
  std::vector<std::string> head = {"test", "source", "role", "criterion"};
  for (const Profile& p : s.profiles) head.push_back("result, " + Esc(p.name));
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < s.tests.size(); ++i) {
    const ValidationTest& t = s.tests[i];
    std::string crit;
    for (const Criterion& c : t.criteria) crit += (crit.empty() ? "" : "<br>") + Esc(c.Describe());
    if (crit.empty()) crit = "documents only";
    std::vector<std::string> row = {"<a href=\"#" + t.id + "\">" + Esc(t.id) + "</a><br>" + Esc(t.title),
                                    Esc(t.standard), ToString(t.role), crit};
    for (std::size_t p = 0; p < np; ++p) {
      const TestResult& r = s.results[p][i];
      std::string cell = VerdictCell(r.verdict);
      for (const CriterionVerdict& cv : r.criteria)
        for (const CaseVerdict& v : cv.cases)
          if (v.judged && !v.pass)
            cell += "<br><span class=\"range\">" + Esc(cv.criterion.statistic) +
                    (v.case_name == "base" || v.case_name == "all" ? "" : " @ " + Esc(v.case_name)) + ": " +
                    Esc(v.text.substr(0, v.text.find(','))) + "</span>";
      if (!r.failures.empty()) cell += "<br><span class=\"range\">" + std::to_string(r.failures.size()) + " runs failed</span>";
      row.push_back(cell);
    }
    rows.push_back(row);
  }
  h += "<h2>Summary</h2>\n" + reports::html::Table(head, rows);

  // The split.
  h += "<h2>Fitted and held out</h2>\n<p>Decided before any profile was fitted (docs/validation.md, \"Fitted and held "
       "out\"): <b>fit</b> experiments may be used to choose a profile's values; <b>held-out</b> experiments only test "
       "it; <b>verification</b> tests are the standards' and must pass whatever was fitted.</p>\n<ul>\n";
  for (Role role : {Role::kFit, Role::kHeldOut, Role::kVerification}) {
    std::string ids;
    for (const ValidationTest& t : s.tests)
      if (t.role == role) ids += (ids.empty() ? "" : ", ") + t.id;
    h += "<li><b>" + ToString(role) + "</b>: " + (ids.empty() ? "none in this run" : Esc(ids)) + "</li>\n";
  }
  h += "</ul>\n";

  // A section per test.
  std::size_t figures = 0;
  for (std::size_t i = 0; i < s.tests.size(); ++i) {
    const ValidationTest& t = s.tests[i];
    std::vector<const TestResult*> per_profile;
    for (std::size_t p = 0; p < np; ++p) per_profile.push_back(&s.results[p][i]);
    h += "<section class=\"test\" id=\"" + t.id + "\"><h2>" + Esc(t.id) + ": " + Esc(t.title) + "</h2>\n";
    h += "<p><b>Source.</b> " + Esc(t.source) + "</p>\n<p><b>Setup.</b> " + Esc(t.setup) + "</p>\n";
    if (!t.notes.empty()) {
      h += "<ul class=\"note\">";
      for (const std::string& n : t.notes) h += "<li>" + Esc(n) + "</li>";
      h += "</ul>\n";
    }
    std::string seeds = std::to_string(s.results[0][i].runs.empty() ? 0 : s.results[0][i].runs[0].size());
    h += "<p class=\"note\">Role: " + ToString(t.role) + ". Cases: " + std::to_string(t.cases.size()) + ", seeds per case: " +
         seeds + ". Measure: " + ToString(t.measure.kind) + ". Test file " + Esc(t.file.filename().string()) +
         " (SHA-256 " + FileDigest(t.file) + "...).</p>\n";
    const std::string setup = SetupFigure(t, *per_profile.front());
    if (!setup.empty()) ++figures;
    h += setup;
    std::vector<std::string> chead = {"criterion", "why this tolerance"};
    for (const Profile& p : s.profiles) chead.push_back(Esc(p.name));
    std::vector<std::vector<std::string>> crows;
    for (std::size_t c = 0; c < t.criteria.size(); ++c) {
      std::vector<std::string> row = {Esc(t.criteria[c].Describe()), Esc(t.criteria[c].why)};
      for (std::size_t p = 0; p < np; ++p) {
        std::string cell;
        for (const CaseVerdict& v : s.results[p][i].criteria[c].cases)
          cell += (cell.empty() ? "" : "<br>") +
                  (v.case_name == "base" || v.case_name == "all" ? "" : "<i>" + Esc(v.case_name) + "</i>: ") + CaseCell(v);
        row.push_back(cell);
      }
      crows.push_back(row);
    }
    if (!crows.empty()) h += reports::html::Table(chead, crows);
    for (std::size_t p = 0; p < np; ++p) {
      const TestResult& r = s.results[p][i];
      if (!r.failures.empty()) {
        h += "<p class=\"note\">" + Esc(s.profiles[p].name) + ": ";
        for (const std::string& f : r.failures) h += Esc(f) + "; ";
        h += "</p>\n";
      }
    }
    const std::string fig = Figures(t, per_profile, s.profiles);
    if (fig.find("<svg") != std::string::npos) ++figures;
    h += fig + "</section>\n";
  }

  // What made it.
  h += "<section class=\"test\"><h2>Profiles, build and checksums</h2>\n";
  for (const Profile& p : s.profiles)
    h += "<h3>" + Esc(p.name) + "</h3><p>" + Esc(p.description) + "</p><pre>" + Esc(p.canonical_json) + "</pre><p class=\"note\">" +
         Esc(p.file.string()) + ", SHA-256 " + FileDigest(p.file) + "...</p>\n";
  h += "<p class=\"note\">Build " + Esc(sweep::BuildVersion()) + ", source fingerprint " + Esc(sweep::SourceFingerprint()) +
       " (the runs are reused by it: docs/validation.md). Runs and their measures: " +
       Esc((options.output_dir / "runs").string()) + " (run the same command again to reuse them).</p></section>\n";
  h += reports::html::SelfCheckScript(figures);
  h += "</body></html>\n";
  return h;
}

std::string ResultsJson(const ValidateOptions& options, const ValidateSummary& s) {
  json j = {{"format", "crowdrecon-validation-results"}, {"version", 1}, {"build", sweep::BuildVersion()},
            {"sources", sweep::SourceFingerprint()}, {"suite", fs::absolute(options.suite).string()}, {"wall_s", s.wall_s}};
  j["profiles"] = json::array();
  for (const Profile& p : s.profiles) j["profiles"].push_back(json::parse(p.canonical_json));
  j["tests"] = json::array();
  for (std::size_t i = 0; i < s.tests.size(); ++i) {
    const ValidationTest& t = s.tests[i];
    json jt = {{"id", t.id}, {"title", t.title}, {"standard", t.standard}, {"role", ToString(t.role)}, {"results", json::object()}};
    for (std::size_t p = 0; p < s.profiles.size(); ++p) {
      const TestResult& r = s.results[p][i];
      json jr = {{"verdict", ToString(r.verdict)}, {"wall_s", r.wall_s}, {"failures", r.failures}, {"criteria", json::array()}};
      for (const CriterionVerdict& cv : r.criteria) {
        json jc = {{"criterion", cv.criterion.Describe()}, {"why", cv.criterion.why}, {"judged", cv.judged}, {"pass", cv.pass},
                   {"cases", json::array()}};
        for (const CaseVerdict& v : cv.cases)
          jc["cases"].push_back({{"case", v.case_name}, {"value", std::isfinite(v.value) ? json(v.value) : json(nullptr)},
                                 {"text", v.text}, {"expected", v.expected}, {"judged", v.judged}, {"pass", v.pass}});
        jr["criteria"].push_back(jc);
      }
      jt["results"][s.profiles[p].name] = jr;
    }
    j["tests"].push_back(jt);
  }
  return j.dump(1);
}

std::string ResultsCsv(const ValidateSummary& s) {
  std::string csv = "profile,test,role,verdict,criterion,case,value,expected,judged,pass\n";
  auto q = [](const std::string& x) {
    std::string o = "\"";
    for (char ch : x) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return o + "\"";
  };
  for (std::size_t p = 0; p < s.profiles.size(); ++p)
    for (std::size_t i = 0; i < s.tests.size(); ++i) {
      const TestResult& r = s.results[p][i];
      for (const CriterionVerdict& cv : r.criteria)
        for (const CaseVerdict& v : cv.cases) {
          char value[40];
          std::snprintf(value, sizeof value, "%.6g", v.value);
          csv += s.profiles[p].name + "," + s.tests[i].id + "," + ToString(s.tests[i].role) + "," + ToString(r.verdict) + "," +
                 q(cv.criterion.Describe()) + "," + v.case_name + "," + (std::isfinite(v.value) ? value : "") + "," +
                 q(v.expected) + "," + (v.judged ? "1" : "0") + "," + (v.pass ? "1" : "0") + "\n";
        }
      if (r.criteria.empty())
        csv += s.profiles[p].name + "," + s.tests[i].id + "," + ToString(s.tests[i].role) + "," + ToString(r.verdict) + ",,,,,0,0\n";
    }
  return csv;
}

}  // namespace

void WriteValidationReport(const ValidateOptions& options, const std::string& chromium, ValidateSummary* summary) {
  const fs::path dir = options.output_dir;
  WriteFileAtomically(dir / "results.json", ResultsJson(options, *summary));
  summary->json = dir / "results.json";
  WriteFileAtomically(dir / "results.csv", ResultsCsv(*summary));
  summary->csv = dir / "results.csv";
  WriteFileAtomically(dir / "report.html", Html(options, *summary));
  summary->html = dir / "report.html";
  if (!options.pdf) {
    // A previous validation's PDF would pass for this one's.
    std::error_code ec;
    if (fs::remove(dir / "report.pdf", ec)) summary->notes.push_back("removed the previous report.pdf (--no-pdf)");
  } else {
    // Printed beside, then renamed: a browser that fails leaves no PDF that
    // looks complete.
    const fs::path partial = dir / ".report.pdf.partial";
    reports::html::PrintPdf(chromium, summary->html, partial);
    fs::rename(partial, dir / "report.pdf");
    summary->pdf = dir / "report.pdf";
  }
}

const ProfileVerdicts* ValidationSummary::Find(const std::string& profile) const {
  for (const ProfileVerdicts& p : profiles)
    if (p.name == profile) return &p;
  return nullptr;
}

ValidationSummary ParseValidationSummary(const std::string& text, const std::string& origin) {
  const JsonDocument doc = JsonDocument::Parse(text, origin);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a validation's results (an object), found " + root.ValueText());
  if (root.String("format") != "crowdrecon-validation-results")
    root.At("format").Fail("expected \"crowdrecon-validation-results\" (a validation's results.json), found " +
                           root.At("format").ValueText());
  (void)root.Integer("version", 1, 1);
  ValidationSummary summary;
  summary.origin = origin;
  summary.build = root.String("build");
  summary.sources = root.String("sources");
  const JsonReader profiles = root.At("profiles");
  if (!profiles.IsArray() || profiles.Size() == 0) profiles.Fail("expected a list of the profiles judged");
  for (std::size_t k = 0; k < profiles.Size(); ++k) {
    const JsonReader p = profiles.Element(k);
    if (!p.IsObject()) p.Fail("expected a profile (an object), found " + p.ValueText());
    ProfileVerdicts v;
    v.name = p.At("name").AsName();
    if (summary.Find(v.name) != nullptr) p.At("name").Fail("the profile \"" + v.name + "\" is listed twice");
    summary.profiles.push_back(std::move(v));
  }
  const JsonReader tests = root.At("tests");
  if (!tests.IsArray()) tests.Fail("expected a list of tests, found " + tests.ValueText());
  for (std::size_t t = 0; t < tests.Size(); ++t) {
    const JsonReader test = tests.Element(t);
    if (!test.IsObject()) test.Fail("expected a test (an object), found " + test.ValueText());
    const std::string id = test.At("id").AsName();
    const std::string role = test.String("role");
    const JsonReader results = test.At("results");
    if (!results.IsObject()) results.Fail("expected each profile's result (an object), found " + results.ValueText());
    for (ProfileVerdicts& v : summary.profiles) {
      if (!results.Has(v.name)) results.Fail("no result of the profile \"" + v.name + "\"");
      const JsonReader r = results.At(v.name);
      if (!r.IsObject()) r.Fail("expected a result (an object), found " + r.ValueText());
      const std::string verdict = r.Choice("verdict", {"pass", "fail", "documents", "error"});
      ++v.tests;
      if (verdict == "pass") ++v.passed;
      if (verdict == "fail" || verdict == "error") v.failed.push_back(id + " (" + role + (verdict == "error" ? ", an error" : "") + ")");
    }
  }
  return summary;
}

ValidationSummary LoadValidationSummary(const fs::path& results_json) {
  return ParseValidationSummary(ReadInputFile(results_json, "validation results"), results_json.string());
}

}  // namespace crowdrecon::validate
