// The injury-risk report of an ensemble of runs (report.hpp): its page, section by section.
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/reports/report.hpp"
#include "crowdrecon/reports/html_page.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <utility>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/common/child_process.hpp"
#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/common/staged_folder.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/render_run.hpp"
#include "crowdrecon/sweep/version.hpp"
#include "envelope.hpp"
#include "report_parts.hpp"
#include "crowdrecon/reports/ensemble.hpp"
#include "crowdrecon/reports/svg.hpp"

namespace crowdrecon::reports {

Spread SpreadOf(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  Spread s;
  s.runs = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.low = v.front();
  s.high = v.back();
  const std::size_t m = v.size() / 2;
  s.median = v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
  return s;
}

DangerRatio DangerRatioOf(const std::vector<std::pair<double, double>>& main,
                          const std::vector<std::pair<double, double>>& other) {
  DangerRatio r;
  std::vector<double> ratios;
  for (const auto& [danger_a, people_a] : main)
    for (const auto& [danger_b, people_b] : other) {
      const double fa = people_a > 0.0 ? danger_a / people_a : 0.0;
      const double fb = people_b > 0.0 ? danger_b / people_b : 0.0;
      if (fa > 0.0)
        ratios.push_back(fb / fa);
      else if (fb > 0.0)
        r.main_none += 1;
      else
        r.neither += 1;
    }
  r.finite = SpreadOf(std::move(ratios));
  return r;
}

std::string DangerRatioText(const DangerRatio& r, const std::string& main_label, const std::string& other_label,
                            bool html) {
  if (r.Pairs() == 0) return "";
  const std::string a = html ? Escape(main_label) : main_label, b = html ? Escape(other_label) : other_label;
  const std::string open = html ? "<b>" : "", close = html ? "</b>" : "";
  const std::string pairs = std::to_string(r.Pairs()) + (r.Pairs() == 1 ? " pair" : " pairs");
  if (r.finite.runs == 0 && r.main_none == 0)
    return open + "No ratio of the fractions in danger" + close + ": nobody reached the danger zone in " + a +
           " or " + b + ".";
  if (r.finite.runs == 0)
    return open + "No finite ratio of the fractions in danger" + close + ": nobody reached the danger zone in " + a +
           ", and someone did in " + b + " (in " + std::to_string(r.main_none) + " of " + pairs + " of runs).";
  std::string s = open + "Fraction of people in danger, " + b + " / " + a + ": " + Short(r.finite.median) + close + " (range " +
      Short(r.finite.low) + "–" + Short(r.finite.high) + " over the " + std::to_string(r.finite.runs) + " of " + pairs +
      " of runs in which " + a + " had someone in danger)";
  if (r.main_none > 0)
    s += "; in " + std::to_string(r.main_none) + " more " + a + " had nobody in danger and " + b +
         " had someone: no finite ratio, so the ratio over all pairs is larger than these figures";
  if (r.neither > 0) s += "; in " + std::to_string(r.neither) + " nobody was in danger in either run";
  return s + ".";
}

namespace {

EnsembleSummary Summarise(const std::string& label, const std::vector<RunRisk>& runs) {
  EnsembleSummary e;
  e.label = label;
  e.runs = runs.size();
  for (std::size_t z = 0; z < kZones; ++z) {
    std::vector<double> v;
    for (const RunRisk& r : runs) v.push_back(r.counts[z]);
    e.zone[z] = SpreadOf(v);
  }
  std::vector<double> people, beyond, fraction;
  for (const RunRisk& r : runs) {
    const double n = double(r.people.size());
    people.push_back(n);
    beyond.push_back(r.beyond_tolerance);
    fraction.push_back(n > 0 ? r.counts[2] / n : 0.0);
    for (const PersonRisk& p : r.people) {
      e.longest_exposure_s = std::max(e.longest_exposure_s, p.longest_above_f0_s);
      e.max_load_n = std::max(e.max_load_n, p.max_load_n);
    }
  }
  e.people = SpreadOf(people);
  e.beyond_tolerance = SpreadOf(beyond);
  e.danger_fraction = SpreadOf(fraction);
  return e;
}

}  // namespace

ReportSummary WriteReport(const ReportOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) throw InputError("report: " + why);
  // A sweep's folder: its runs differ in their parameters, not only in their
  // seeds, so they are no ensemble; its results give the design envelope.
  if (options.inputs.size() == 1 && options.compare.empty() && IsSweepFolder(options.inputs.front()))
    return WriteEnvelopeReport(options);
  for (const fs::path& in : options.inputs)
    if (IsSweepFolder(in))
      throw InputError(in.string() + ": a sweep's folder; expected it alone (its design envelope), or run files of one "
                       "scenario's seeds");
  {
    std::vector<NamedInput> named;
    for (const fs::path& f : options.inputs) named.push_back({"an input", f});
    for (const fs::path& f : options.compare) named.push_back({"an input", f});
    CheckOutputs({{"-o", options.output_dir, ReportFolderOutput()}}, named, options.force);
  }
  std::vector<std::string> input_notes;
  const std::vector<fs::path> main_files = RunFilesOf(options.inputs, &input_notes);
  const std::vector<fs::path> other_files =
      options.compare.empty() ? std::vector<fs::path>{} : RunFilesOf(options.compare, &input_notes);
  // An ensemble is seeds of one scenario, by content: runs of another (or a
  // copy of one run) pooled into it would be averaged as if they were seeds
  // (issues 40, 65). Another scenario's runs go with --compare.
  CheckSeedsOfOneScenario(main_files, "the ensemble", "give another scenario's runs with --compare");
  CheckSeedsOfOneScenario(other_files, "the --compare ensemble");
  // An unfinished run (interrupted, killed, failed) is refused in an ensemble,
  // as the timeline's ensembles refuse it, and said of a run reported alone:
  // in the summary and on the report's page (issue 65, M10, M11, V02).
  std::string unfinished;
  for (const std::vector<fs::path>* files : {&main_files, &other_files})
    for (const fs::path& f : *files) {
      const std::string status = runfile::RunFileReader(f).RunValue("status");
      if (status == "complete") continue;
      if (files->size() > 1)
        throw InputError(f.string() + ": the run's status is \"" + status + "\"; an ensemble pools finished runs (" +
                         (status.rfind("failed", 0) == 0 ? "leave the failed run out" : "resume it with crowdrecon simulate --resume, or leave it out") + ")");
      const std::string note = runfile::RunFileReader(f).UnfinishedNote();
      input_notes.push_back(note);
      unfinished += (unfinished.empty() ? "" : " ") + note;
    }
  const std::string chromium = ChromiumFor(options);
  const auto say = [&](const std::string& text) {
    if (options.progress) options.progress(text);
  };
  // Each run's loads and its validity (section 1's last part) in one pass.
  const analysis::PlausibilityOptions validity_options;
  RiskOptions with_validity = options.risk;
  with_validity.validity = validity_options;
  // A long run's pass takes minutes: a line at each tenth of its frames.
  const auto tenths = [&](std::size_t done, std::size_t total) {
    if (total >= kFramesForProgress && done * 10 / total != (done - 1) * 10 / total)
      say("  " + std::to_string(done * 100 / total) + " % of its " + std::to_string(total) + " frames");
  };
  if (options.progress) with_validity.progress = tenths;
  const auto analyse = [&](const std::vector<fs::path>& files) {
    std::vector<RunRisk> runs;
    for (std::size_t k = 0; k < files.size(); ++k) {
      say("reading " + files[k].string() + " (" + std::to_string(k + 1) + " of " + std::to_string(files.size()) + ")");
      runs.push_back(AnalyseRunRisk(files[k], with_validity));
    }
    return runs;
  };
  const std::vector<RunRisk> main_runs = analyse(main_files);
  const std::vector<RunRisk> other_runs = analyse(other_files);
  // (Each set was checked to be the seeds of one scenario before it was read.)
  ReportSummary summary;
  summary.notes = input_notes;
  summary.main = Summarise(options.label, main_runs);
  summary.other = Summarise(options.compare_label, other_runs);
  if (!other_runs.empty()) {
    const auto danger = [](const std::vector<RunRisk>& runs) {
      std::vector<std::pair<double, double>> out;
      for (const RunRisk& r : runs) out.emplace_back(double(r.counts[2]), double(r.people.size()));
      return out;
    };
    summary.danger_ratio = DangerRatioOf(danger(main_runs), danger(other_runs));
  }
  const RiskOptions& o = options.risk;

  // --- The page ------------------------------------------------------------
  say("writing the report");
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">" + std::string(kGenerator) +
                  "<title>Injury-risk report: " + Escape(main_runs.front().scenario_name) + "</title><style>" + Css() +
                  "</style></head><body>\n";
  const RunRisk& first = main_runs.front();
  h += "<h1>Injury-risk report</h1>\n<p class=\"sub\">" + Escape(first.scenario_name) + " — venue: " +
       Escape(first.venue_name) + " — model profile: <b>" + Escape(first.profile) + "</b>" +
       (other_runs.empty() || other_runs.front().profile == first.profile
            ? std::string()
            : " (compared with profile <b>" + Escape(other_runs.front().profile) + "</b>)") +
       "<br>" + std::to_string(main_runs.size()) +
       (main_runs.size() == 1 ? " run" : " runs (seeds)") +
       (other_runs.empty() ? "" : ", compared with " + Escape(other_runs.front().scenario_name) + " (" +
                                      std::to_string(other_runs.size()) + (other_runs.size() == 1 ? " run)" : " runs)")) +
       ". crowdrecon " + Escape(CROWDRECON_GIT_VERSION) + ".</p>\n";

  // Summary.
  h += "<h2>1. Summary</h2>\n";
  const auto key_boxes = [&](const EnsembleSummary& e) {
    std::string k = "<div class=\"key\">";
    k += "<div>people in the runs<b>" + SpreadText(e.people) + "</b></div>";
    k += "<div>in the <span class=\"zone-uncomfortable\">uncomfortable</span> zone<b>" + SpreadText(e.zone[1]) + "</b></div>";
    k += "<div>in the <span class=\"zone-danger\">danger</span> zone<b>" + SpreadText(e.zone[2]) + "</b></div>";
    k += "<div>beyond the tolerance dose<b>" + SpreadText(e.beyond_tolerance) + "</b></div>";
    return k + "</div>\n";
  };
  // The validity beside the headline numbers it qualifies (issue 65: the
  // demo's 3,951 people in danger stood on page 1 without the caveat the
  // next section gave).
  const auto caveat = [](const std::vector<RunRisk>& runs) -> std::string {
    std::size_t beyond_measured = 0, beyond_static = 0;
    double peak = 0.0, longest = 0.0;
    for (const RunRisk& r : runs) {
      if (!r.validity) continue;
      const analysis::Plausibility& p = *r.validity;
      if (p.verdict == analysis::PlausibilityVerdict::kBeyondMeasured) ++beyond_measured;
      if (p.verdict == analysis::PlausibilityVerdict::kBeyondStatic) ++beyond_static;
      peak = std::max(peak, p.peak_equivalent_density_per_m2);
      longest = std::max(longest, p.time_beyond_measured_s);
    }
    const std::string of = " of " + std::to_string(runs.size()) + (runs.size() == 1 ? " run" : " runs");
    if (beyond_measured > 0)
      return "<p class=\"caveat\"><b>Read these numbers with their validity.</b> In " + std::to_string(beyond_measured) +
             of + " the crowd reached states beyond what any human crowd has been measured to reach (up to " +
             Short(peak) + " persons/m² as real-size people" +
             (longest > 0.0 ? ", beyond 10 /m² for up to " + Short(longest) + " s" : std::string()) +
             "): the counts and loads below are the model's in that state, not injuries to expect (\"Are these states a "
             "human crowd can reach?\", below).</p>\n";
    if (beyond_static > 0)
      return "<p class=\"caveat\"><b>Read these numbers with their validity.</b> In " + std::to_string(beyond_static) + of +
             " the crowd went beyond Fruin's critical density of a static crowd (7.1 /m², up to " + Short(peak) +
             " persons/m² as real-size people), within what crushes have reached (\"Are these states a human crowd can "
             "reach?\", below).</p>\n";
    return "";
  };
  h += "<h3>" + Escape(options.label) + "</h3>" + key_boxes(summary.main) + caveat(main_runs);
  if (!other_runs.empty())
    h += "<h3>" + Escape(options.compare_label) + "</h3>" + key_boxes(summary.other) + caveat(other_runs);
  {
    std::vector<std::vector<std::string>> rows;
    const auto row = [&](const std::string& what, auto get) {
      std::vector<std::string> r{what, get(summary.main)};
      if (!other_runs.empty()) r.push_back(get(summary.other));
      rows.push_back(r);
    };
    row("runs (seeds)", [](const EnsembleSummary& e) { return std::to_string(e.runs); });
    row("people in the runs", [](const EnsembleSummary& e) { return SpreadText(e.people); });
    for (std::size_t z = 0; z < kZones; ++z)
      row(std::string("<span class=\"zone-") + ToString(Zone(z)) + "\">" + ToString(Zone(z)) + "</span>",
          [z](const EnsembleSummary& e) { return SpreadText(e.zone[z]); });
    row("fraction in danger", [](const EnsembleSummary& e) { return SpreadText(e.danger_fraction); });
    row("beyond the tolerance dose (D ≥ 1)", [](const EnsembleSummary& e) { return SpreadText(e.beyond_tolerance); });
    row("longest continuous exposure above F0", [](const EnsembleSummary& e) { return Short(e.longest_exposure_s) + " s"; });
    row("largest chest load (1 s mean)", [](const EnsembleSummary& e) { return Short(e.max_load_n, 4) + " N"; });
    std::vector<std::string> head{"", Escape(options.label)};
    if (!other_runs.empty()) head.push_back(Escape(options.compare_label));
    h += Table(head, rows);
    h += "<p class=\"note\">Counts are the median over the runs, with the smallest and largest run in brackets; each run "
         "is one seed, one possible course of events. Zones from each person's largest chest load (mean over " +
         Short(o.smoothing_s) + " s): safe up to F0 = " + Short(o.f0_n) + " N, uncomfortable up to " + Short(o.danger_n) +
         " N, danger above (section 7).</p>\n";
    if (!other_runs.empty()) h += "<p>" + DangerRatioText(summary.danger_ratio, options.label, options.compare_label, true) + "</p>\n";
  }

  // Validity: whether the states are ones a human crowd can reach (issue 39).
  {
    const analysis::PlausibilityOptions& po = validity_options;
    h += "<h3>Are these states a human crowd can reach?</h3>\n";
    if (!unfinished.empty())
      h += "<p><b>An unfinished run.</b> " + Escape(unfinished) + ". Every figure of this report covers only what it "
           "recorded.</p>\n";
    const auto validity = [&](const std::string& label, const std::vector<RunRisk>& runs) {
      if (runs.empty()) return;
      std::vector<double> peak, equivalent, overlap;
      analysis::Plausibility worst;
      bool first_run = true;
      for (const RunRisk& r : runs) {
        const analysis::Plausibility& p = *r.validity;
        peak.push_back(p.peak_density_per_m2);
        equivalent.push_back(p.peak_equivalent_density_per_m2);
        if (p.contacts_available) overlap.push_back(p.max_overlap_m);
        if (first_run || p.peak_equivalent_density_per_m2 > worst.peak_equivalent_density_per_m2) worst = p;
        first_run = false;
      }
      const Spread sp = SpreadOf(peak), se = SpreadOf(equivalent);
      std::string line = label + ": peak local density " + Short(sp.median) + " persons/m2 (" + Short(sp.low) + "-" +
                         Short(sp.high) + " over " + std::to_string(runs.size()) + (runs.size() == 1 ? " run" : " runs") + "), as real-size people " +
                         Short(se.median) + " (" + Short(se.low) + "-" + Short(se.high) + ")";
      if (!overlap.empty()) line += "; largest overlap " + Short(SpreadOf(overlap).high * 100.0) + " cm";
      line += std::string("; ") + (worst.verdict == analysis::PlausibilityVerdict::kWithin ? "within the range of human crowds"
                                   : worst.verdict == analysis::PlausibilityVerdict::kBeyondStatic
                                       ? "beyond Fruin's critical static density, within what crushes have reached"
                                       : "BEYOND what any human crowd has been measured to reach");
      summary.validity_lines.push_back(line);
      std::string body = line.substr(label.size() + 2);
      body[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(body[0])));
      h += "<p><b>" + Escape(label) + ".</b> " + Escape(body) + ". The run that comes closest "
           "to the edge: " + Escape(worst.Statement(po)) + "</p>\n";
    };
    validity(options.label, main_runs);
    validity(options.compare_label, other_runs);
    h += "<p class=\"note\">Local density: people whose centres lie within 1 m² of a person, the peak over every person "
         "and frame; as real-size people: the same floor covered by ANSUR II median bodies (0.0868 m², thorax with "
         "arms). Range: Fruin's 7.1 /m² (critical static crowd), about 9–10 /m² measured in crushes, 38 % chest "
         "compression (Viano et al. 1989) for overlaps (docs/analysis.md, \"States a human crowd can reach\").</p>\n";
  }

  // Force network at the worst moment.
  std::size_t figures = 0;
  h += "<h2>2. The force network at the worst moment</h2>\n";
  const auto network = [&](const RunRisk& r, const std::string& label, const std::string& prefix) {
    if (!r.has_contacts && !r.contacts_note.empty())
      return "<p class=\"note\">" + Escape(label) + ": " + Escape(r.file.filename().string()) + " " +
             Escape(r.contacts_note) + ", so its force network at that moment cannot be drawn; a report with the "
             "defaults of F0 and smoothing draws it.</p>\n";
    if (!r.has_contacts)
      return "<p class=\"note\">" + Escape(label) + ": " + Escape(r.file.filename().string()) +
             " records no contacts, so its force network cannot be drawn (its chest loads come from table "
             "person_load); simulate with <code>\"run\": {\"contacts\": true}</code> to see it.</p>\n";
    say("drawing the force network of " + r.file.string() + " at t = " + Short(r.worst_time_s) + " s");
    std::uint32_t people = 0;
    for (const FrameRisk& fr : r.frames)
      if (fr.frame == r.worst_frame) people = fr.present;
    viz::RenderSummary whole;
    const std::string whole_figure = ForceNetworkFigure(r.file, r.worst_frame, people, prefix, std::nullopt, &whole);
    const std::string moment = Escape(label) + ": frame " + std::to_string(r.worst_frame) + " (t = " +
                               Short(r.worst_time_s, 4) + " s) of " + Escape(r.file.filename().string()) +
                               ", the moment with the most people above F0";
    const std::string how = "A line from each body's centre to each contact point, its thickness the contact force (the "
                            "paper's Figure 6 a–b).";
    // Where the whole view is too large to read the network (bodies as
    // specks: issue 65), the worst region is the figure, at a readable scale
    // (a square around the most loaded person, moved inside the whole view),
    // and the whole venue an inset beside it with that square marked.
    const double side = options.close_up_m;
    const Vec2 extent = whole.world_max_m - whole.world_min_m;
    if (!(side > 0.0 && r.worst_person > 0 && std::max(extent.x, extent.y) > 3.0 * side)) {
      ++figures;
      return "<figure>" + whole_figure + "<figcaption>" + moment + ". " + how + "</figcaption></figure>\n";
    }
    Vec2 lo = r.worst_place_m - Vec2{side / 2.0, side / 2.0};
    lo.x = std::clamp(lo.x, whole.world_min_m.x, std::max(whole.world_min_m.x, whole.world_max_m.x - side));
    lo.y = std::clamp(lo.y, whole.world_min_m.y, std::max(whole.world_min_m.y, whole.world_max_m.y - side));
    const Vec2 hi = {std::min(lo.x + side, whole.world_max_m.x), std::min(lo.y + side, whole.world_max_m.y)};
    say("drawing its worst region around person " + std::to_string(r.worst_person) + ", and the venue with it marked");
    const std::string close = ForceNetworkFigure(r.file, r.worst_frame, people, prefix + "c-", std::pair{lo, hi});
    const std::string inset = ForceNetworkFigure(r.file, r.worst_frame, people, prefix + "i-", std::nullopt, nullptr,
                                                 std::pair{lo, hi}, 900);
    figures += 2;
    return "<div class=\"inset-pair\"><figure class=\"main\">" + close + "<figcaption>" + moment +
           ": the worst region, x " + Short(lo.x, 4) + " to " + Short(hi.x, 4) + " m, y " + Short(lo.y, 4) + " to " +
           Short(hi.y, 4) + " m, around person " + std::to_string(r.worst_person) +
           ", the most loaded then; its force scale is that of the contacts inside it. " + how +
           "</figcaption></figure><figure class=\"inset\">" + inset +
           "<figcaption>The whole venue at the same moment, the region in red.</figcaption></figure></div>\n";
  };
  h += network(first, options.label, "n1-");
  if (!other_runs.empty()) h += network(other_runs.front(), options.compare_label, "n2-");

  // Distributions.
  h += "<h2>3. Distribution of contact forces and chest loads</h2>\n";
  {
    std::vector<std::pair<std::string, std::vector<double>>> sets;
    if (first.has_contacts) sets.push_back({options.label + ", contacts at the worst moment", first.worst_contact_forces_n});
    if (!other_runs.empty() && other_runs.front().has_contacts)
      sets.push_back({options.compare_label + ", contacts at the worst moment", other_runs.front().worst_contact_forces_n});
    if (sets.empty()) {
      h += "<p class=\"note\">No contacts recorded in these runs: the distributions of contact forces (the paper's "
           "Figure 6 c–d) need runs simulated with <code>\"run\": {\"contacts\": true}</code>.</p>\n";
    } else {
    h += "<figure>" + CdfChart("Contact forces scaled by F0 = " + Short(o.f0_n) + " N (paper, Figure 6 c–d)", "F / F0", sets, o,
                                {"#1f4e79", kOtherColor}) +
         "<figcaption>The fraction of contacts whose force exceeds F (one minus the cumulative distribution), at the "
         "worst moment of the first run of each set, with the zones.</figcaption></figure>\n";
    ++figures;
    // Whole-run distribution from the histogram, per set.
    svg::Chart c;
    c.title = "Contact forces over the whole run";
    c.x_label = "F / F0";
    c.y_label = "fraction above";
    c.log_x = c.log_y = true;
    c.x_min = 1e-2;
    c.x_max = 1e2;
    c.y_min = 1e-7;
    c.y_max = 1.0;
    c.legend_left = c.legend_bottom = true;
    c.bands = {{1e-3, 1.0, kZoneColor[0], "safe"},
               {1.0, o.danger_n / o.f0_n, kZoneColor[1], "uncomfortable"},
               {o.danger_n / o.f0_n, 1e3, kZoneColor[2], "danger"}};
    const auto add = [&](const std::vector<RunRisk>& runs, const std::string& label, const std::string& color) {
      for (std::size_t k = 0; k < runs.size(); ++k) {
        if (!runs[k].has_contacts) continue;
        svg::Series s;
        s.color = color;
        s.width = k == 0 ? 2.0 : 0.8;
        s.label = k == 0 ? label + (runs.size() > 1 ? " (thin: other seeds)" : "") : "";
        for (int b = 0; b < ForceHistogram::kBins; ++b) {
          s.x.push_back(ForceHistogram::UpperEdge(b));
          s.y.push_back(runs[k].contact_forces.FractionAbove(ForceHistogram::UpperEdge(b)));
        }
        c.series.push_back(std::move(s));
      }
    };
    add(main_runs, options.label, "#1f4e79");
    add(other_runs, options.compare_label, kOtherColor);
    h += "<figure>" + c.ToSvg() + "<figcaption>Every contact of every frame (" + std::to_string(first.contact_rows) +
         " contact records in the first run), binned in " + std::to_string(ForceHistogram::kPerDecade) +
         " bins per decade" + (first.contact_forces_from.empty() ? "" : " (" + Escape(first.contact_forces_from) + ")") +
         ".</figcaption></figure>\n";
    ++figures;
    }
    std::vector<std::pair<std::string, std::vector<double>>> loads;
    const auto peak_loads = [](const RunRisk& r) {
      std::vector<double> v;
      for (const PersonRisk& p : r.people) v.push_back(p.max_load_n);
      std::sort(v.begin(), v.end());
      return v;
    };
    loads.push_back({options.label + ": each person's largest chest load", peak_loads(first)});
    if (!other_runs.empty()) loads.push_back({options.compare_label + ": each person's largest chest load", peak_loads(other_runs.front())});
    h += "<figure>" + CdfChart("Chest loads per person (largest 1 s mean), scaled by F0", "chest load / F0", loads, o,
                                {"#1f4e79", kOtherColor}) +
         "<figcaption>The fraction of people whose largest chest load exceeds the value: the per-person measure of "
         "section 7, from which the zones are counted.</figcaption></figure>\n";
    ++figures;
  }

  // Exposure over time.
  h += "<h2>4. Exposure over time</h2>\n";
  const auto exposure_chart = [&](const std::vector<RunRisk>& runs, const std::string& label) {
    svg::Chart c;
    c.title = label + ": people above F0 and in the danger zone";
    c.x_label = "time (s)";
    c.y_label = "people";
    c.legend_left = true;
    for (std::size_t k = 0; k < runs.size(); ++k) {
      svg::Series a, d;
      a.color = kZoneColor[1];
      d.color = kZoneColor[2];
      a.width = d.width = k == 0 ? 2.0 : 0.7;
      a.step = d.step = true;
      if (k == 0) {
        a.label = "above F0 = " + Short(o.f0_n) + " N";
        d.label = "above " + Short(o.danger_n) + " N";
      }
      for (const FrameRisk& f : runs[k].frames) {
        a.x.push_back(f.time_s);
        a.y.push_back(f.above_f0);
        d.x.push_back(f.time_s);
        d.y.push_back(f.above_danger);
      }
      c.series.push_back(std::move(a));
      c.series.push_back(std::move(d));
    }
    c.x_marks.push_back({runs.front().worst_time_s, "worst moment"});
    ++figures;
    return "<figure>" + c.ToSvg() + "<figcaption>Smoothed chest loads (" + Short(o.smoothing_s) +
           " s mean); thick: the first run, thin: the other seeds.</figcaption></figure>\n";
  };
  h += exposure_chart(main_runs, options.label);
  if (!other_runs.empty()) h += exposure_chart(other_runs, options.compare_label);
  // The chest load over time of the most exposed people of each set's first
  // run (a second pass over that run, keeping only their series).
  const auto timelines = [&](const RunRisk& r, const std::string& label) {
    std::vector<const PersonRisk*> order;
    for (const PersonRisk& p : r.people) order.push_back(&p);
    std::stable_sort(order.begin(), order.end(), [](const PersonRisk* a, const PersonRisk* b) {
      return a->dose != b->dose ? a->dose > b->dose : a->max_load_n > b->max_load_n;
    });
    RiskOptions o2 = o;
    o2.progress = options.progress ? std::function<void(std::size_t, std::size_t)>(tenths) : nullptr;
    o2.validity.reset();
    o2.read_contacts = false;  // their loads alone
    for (std::size_t k = 0; k < order.size() && k < 6; ++k) o2.series_of.push_back(order[k]->id);
    say("the chest loads over time of the " + std::to_string(o2.series_of.size()) + " most exposed of " + r.file.string());
    const RunRisk again = AnalyseRunRisk(r.file, o2);
    static const char* colours[] = {"#c0392b", "#1f4e79", "#2e8b57", "#7b3f98", "#d35400", "#555555"};
    svg::Chart c;
    c.title = label + ": chest load of the " + std::to_string(o2.series_of.size()) + " most exposed people";
    c.x_label = "time (s)";
    c.y_label = "chest load, 1 s mean (N)";
    c.legend_left = true;
    for (std::size_t k = 0; k < again.series.size(); ++k) {
      svg::Series s;
      s.color = colours[k % 6];
      s.width = 1.4;
      s.label = "person " + std::to_string(o2.series_of[k]) + " (dose " + Short(order[k]->dose) + ")";
      for (const auto& [t, v] : again.series[k]) {
        s.x.push_back(t);
        s.y.push_back(v);
      }
      c.series.push_back(std::move(s));
    }
    double first_s = 1e300, last_s = -1e300;
    for (const FrameRisk& f : r.frames) {
      first_s = std::min(first_s, f.time_s);
      last_s = std::max(last_s, f.time_s);
    }
    svg::Series f0, danger;
    f0.x = danger.x = {first_s, last_s};
    f0.y = {o.f0_n, o.f0_n};
    danger.y = {o.danger_n, o.danger_n};
    f0.color = kZoneColor[1];
    danger.color = kZoneColor[2];
    f0.dashed = danger.dashed = true;
    f0.label = "F0 = " + Short(o.f0_n) + " N";
    danger.label = Short(o.danger_n) + " N";
    c.series.push_back(f0);
    c.series.push_back(danger);
    ++figures;
    return "<figure>" + c.ToSvg() + "<figcaption>Each line one person (the largest doses of " +
           Escape(r.file.filename().string()) + "), while in the venue; dashed: the zones' edges.</figcaption></figure>\n";
  };
  h += timelines(first, options.label);
  if (!other_runs.empty()) h += timelines(other_runs.front(), options.compare_label);

  // Map.
  h += "<h2>5. Where the people at risk were</h2>\n";
  const auto map = [&](const RunRisk& r, const std::string& label) {
    const runfile::RunFileReader reader(r.file);
    svg::Plan p;
    p.title = label + ": each person at the place of their largest chest load";
    const std::string venue = reader.venue_json();
    if (!venue.empty())
      for (const auto& ring : geometry::ParseVenue(venue, r.file.string() + ": run value venue").walkable_area)
        p.area.push_back(ring);
    for (const runfile::Wall& w : reader.Walls()) {
      std::vector<Vec2> pts = w.points;
      if (w.closed && !pts.empty()) pts.push_back(pts.front());
      p.walls.push_back(pts);
    }
    Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
    const auto grow = [&](Vec2 q) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    };
    for (const auto& ring : p.area) for (Vec2 q : ring) grow(q);
    for (const auto& wall : p.walls) for (Vec2 q : wall) grow(q);
    std::vector<const PersonRisk*> order;
    for (const PersonRisk& pr : r.people) order.push_back(&pr);
    std::stable_sort(order.begin(), order.end(), [](const PersonRisk* a, const PersonRisk* b) { return a->zone < b->zone; });
    for (const PersonRisk* pr : order) {
      grow(pr->max_load_position_m);
      const double radius = pr->zone == Zone::kSafe ? 0.06 : 0.14;
      p.dots.push_back({pr->max_load_position_m, kZoneColor[static_cast<std::size_t>(pr->zone)], radius,
                        "person " + std::to_string(pr->id) + ": " + Short(pr->max_load_n, 4) + " N at " +
                            Short(pr->max_load_time_s, 4) + " s"});
    }
    p.min_m = {lo.x - 0.5, lo.y - 0.5};
    p.max_m = {hi.x + 0.5, hi.y + 0.5};
    p.legend = {{kZoneColor[0], "safe"}, {kZoneColor[1], "uncomfortable"}, {kZoneColor[2], "danger"}};
    ++figures;
    return "<figure>" + p.ToSvg() + "<figcaption>" + Escape(r.file.filename().string()) +
           "; hover a dot for the person, the load and the time.</figcaption></figure>\n";
  };
  h += map(first, options.label);
  if (!other_runs.empty()) h += map(other_runs.front(), options.compare_label);

  // People.
  h += "<h2>6. The people most exposed</h2>\n";
  std::string csv =
      "set,run,id,group,first_seen_s,last_seen_s,max_load_n,max_load_time_s,max_load_x_m,max_load_y_m,max_raw_load_n,"
      "time_above_f0_s,longest_above_f0_s,time_above_danger_s,dose,fell,zone\n";
  const auto people_rows = [&](const std::vector<RunRisk>& runs, const std::string& set) {
    std::vector<std::pair<const RunRisk*, const PersonRisk*>> all;
    for (const RunRisk& r : runs)
      for (const PersonRisk& p : r.people) {
        all.push_back({&r, &p});
        // The label and the file name as RFC 4180 fields (a comma or quote in
        // either would shift the columns); the numbers after them.
        char numbers[512];
        std::snprintf(numbers, sizeof numbers, "%u,%u,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%s\n",
                      p.id, p.group, p.first_seen_s, p.last_seen_s, p.max_load_n, p.max_load_time_s,
                      p.max_load_position_m.x, p.max_load_position_m.y, p.max_raw_load_n, p.time_above_f0_s,
                      p.longest_above_f0_s, p.time_above_danger_s, p.dose, p.fell ? 1 : 0, ToString(p.zone));
        csv += CsvField(set) + "," + CsvField(r.file.filename().string()) + "," + numbers;
      }
    std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
      return a.second->dose != b.second->dose ? a.second->dose > b.second->dose : a.second->max_load_n > b.second->max_load_n;
    });
    std::vector<std::vector<std::string>> rows;
    for (std::size_t k = 0; k < all.size() && k < options.table_rows; ++k) {
      const PersonRisk& p = *all[k].second;
      rows.push_back({Escape(all[k].first->file.filename().string()), std::to_string(p.id), std::to_string(p.group),
                      Short(p.max_load_n, 4), Short(p.max_load_time_s, 4), Short(p.time_above_f0_s),
                      Short(p.longest_above_f0_s), Short(p.time_above_danger_s), Short(p.dose),
                      p.fell ? "yes" : "", std::string("<span class=\"zone-") + ToString(p.zone) + "\">" + ToString(p.zone) + "</span>"});
    }
    return Table({"run", "person", "group", "largest load (N)", "at (s)", "above F0 (s)", "longest above F0 (s)",
                  "above danger (s)", "dose D", "fell", "zone"},
                 rows);
  };
  h += "<p>The " + std::to_string(options.table_rows) +
       " people with the largest dose (then the largest load); every person of every run is in <code>people.csv</code>.</p>\n";
  h += "<h3>" + Escape(options.label) + "</h3>" + people_rows(main_runs, options.label);
  if (!other_runs.empty()) h += "<h3>" + Escape(options.compare_label) + "</h3>" + people_rows(other_runs, options.compare_label);

  // Methods.
  h += "<h2>7. Methods</h2>\n";
  h += "<p><b>Chest load.</b> For each person and frame, from every contact force on the body (other people, walls, "
       "barriers and fallen people alike): along the chest direction d, the contacts on the front push the body back "
       "with P<sub>+</sub> = Σ max(0, −F·d), those on the back push it on with P<sub>−</sub> = Σ max(0, F·d); the load "
       "across the chest is min(P<sub>+</sub>, P<sub>−</sub>), what both sides press together — the rest accelerates "
       "the body. The same across the shoulders (perpendicular to d); the person's load is the larger of the two, "
       "averaged over " + Short(o.smoothing_s) + " s (a breath; single steps of a contact model show spikes). For "
       "contacts on the two faces of the chest this is the force moment tensor's −d·M·d / depth less half the net "
       "force along d, which the moment tensor would count as load on a body pushed from one side only.</p>\n";
  h += "<p><b>Zones</b> (the paper's Figure 6): safe at most F0 = " + Short(o.f0_n) +
       " N (the paper's estimate of the load behind the Madrid Arena deaths; a 2024 wearable-sensor study found "
       "flow stable below 400 N), uncomfortable above F0 (the Surrey barrier tests found loads intolerable after a "
       "few seconds at 116–774 N, mean 418 N; Evans &amp; Hayden 623 N), danger above " + Short(o.danger_n) +
       " N (Hopkins et al. 1993: death after 4–6 minutes at 1112 N).</p>\n";
  h += "<p><b>Dose.</b> A tolerance time T(F) = " + Short(o.lethal_short_s) + " s × (F / " + Short(o.lethal_short_n) +
       " N)<sup>−k</sup>, a power law through Hopkins et al.'s two points (" + Short(o.lethal_short_n) + " N for about " +
       Short(o.lethal_short_s) + " s; " + Short(o.lethal_long_n) + " N for about " + Short(o.lethal_long_s / 60.0) +
       " min), k = " + Short(o.ToleranceExponent(), 4) + "; T(F0) = " + Short(o.ToleranceTime_s(o.f0_n * 1.0000001) / 60.0) +
       " min. The dose D = Σ Δt / T(F) sums the exposure of every frame above F0 (Miner's rule); D ≥ 1 means the "
       "tolerance was reached. Two points from one source fix the curve: its shape between and beyond them, and "
       "individual differences (the Surrey subjects differed sevenfold), are not known; the counts beyond the dose are an "
       "order of magnitude, not a prediction of deaths.</p>\n";
  // The crowd model: each profile of the runs and what the validation suite says of it.
  {
    std::vector<std::string> profiles{first.profile};
    if (!other_runs.empty() && other_runs.front().profile != first.profile) profiles.push_back(other_runs.front().profile);
    h += "<p><b>The crowd model.</b> ";
    for (const std::string& name : profiles) {
      const auto found = std::find_if(options.validation.begin(), options.validation.end(),
                                      [&](const ReportOptions::ProfileValidation& v) { return v.profile == name; });
      h += "Profile <b>" + Escape(name) + "</b>";
      if (found == options.validation.end()) {
        h += options.validation.empty()
                 ? ": its verdicts on the validation suite were not given to this report (<code>crowdrecon validate</code>, "
                   "docs/validation.md; <code>report --validation results.json</code>). "
                 : ": not among the profiles of the validation results given (" + Escape(options.validation_source) + "). ";
        continue;
      }
      h += ": on the validation suite (the field's standard tests and experiments, " + Escape(options.validation_source) +
           ") it passes " + std::to_string(found->passed) + " of " + std::to_string(found->tests) + " tests";
      if (!found->failed.empty()) {
        h += "; it fails ";
        for (std::size_t k = 0; k < found->failed.size(); ++k)
          h += (k == 0 ? "" : k + 1 == found->failed.size() ? " and " : ", ") + Escape(found->failed[k]);
      }
      h += ". ";
    }
    h += "A result that rests on what a profile fails (a door's flow, a counter-flow) carries that limit.</p>\n";
  }
  h += "<p><b>The model's simplifications.</b> A 2D model of torsos (spheropolygons) with contact forces, a drive "
       "toward the target, a back force and a torque (the paper's equations 1–19); loads are horizontal forces on the "
       "torso; people cannot climb, stack or be lifted; a fall (when the run's timeline has them) turns a person into a "
       "fixed obstacle on the floor that still carries load. Forces of a soft contact model grow with overlap: where "
       "loads reach kilonewtons the bodies overlap by centimetres.</p>\n";
  h += "<p><b>Options of this report:</b> F0 " + Short(o.f0_n) + " N, danger " + Short(o.danger_n) + " N, tolerance (" +
       Short(o.lethal_short_n) + " N, " + Short(o.lethal_short_s) + " s) and (" + Short(o.lethal_long_n) + " N, " +
       Short(o.lethal_long_s) + " s), smoothing " + Short(o.smoothing_s) + " s.</p>\n";

  // Reproducibility.
  h += "<h2>8. Reproducibility</h2>\n<p>crowdrecon " + Escape(CROWDRECON_GIT_VERSION) + "; command: <code>" +
       Escape(options.command_line) + "</code></p>\n";
  {
    std::vector<std::vector<std::string>> rows;
    const auto list = [&](const std::vector<RunRisk>& runs, const std::string& set) {
      for (const RunRisk& r : runs) {
        say("checksum of " + r.file.string());
        const runfile::RunFileReader reader(r.file);
        rows.push_back({Escape(set), Escape(r.file.string()), Escape(r.profile), Escape(r.seed), Short(r.duration_s, 5) + " s",
                        std::to_string(r.people.size()), "<code>" + Sha256OfFile(r.file) + "</code>",
                        "<code>" + Sha256Hex(reader.RunValue("scenario")) + "</code>",
                        "<code>" + Sha256Hex(reader.venue_json()) + "</code>"});
      }
    };
    list(main_runs, options.label);
    list(other_runs, options.compare_label);
    h += Table({"set", "run file", "profile", "seed", "simulated", "people", "SHA-256 of the run file", "of its scenario", "of its venue"}, rows);
    h += "<p class=\"note\">The scenario (as given, with its model profile's values written in where it gives none of its "
         "own) and the venue are stored in each run file (table run, keys scenario and venue); their checksums are of that "
         "text; the profile's name is run value profile. Check a run file with <code>sha256sum</code>; regenerate it with "
         "<code>crowdrecon simulate</code> on the scenario (same input and seed give the same file content, whatever "
         "the number of threads).</p>\n";
    const runfile::RunFileReader reader(first.file);
    h += "<details><summary>The scenario of " + Escape(first.file.filename().string()) + "</summary><pre>" +
         Escape(reader.RunValue("scenario")) + "</pre></details>\n";
    h += "<details><summary>Its venue</summary><pre>" + Escape(reader.venue_json()) + "</pre></details>\n";
  }
  h += SelfCheckScript(figures);
  h += "</body></html>\n";

  // --- Files: the folder replaced as a whole, or not at all -------------------
  WriteReportFolder(options, chromium, h, &csv, &summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace crowdrecon::reports
