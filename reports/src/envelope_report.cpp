// The design envelope's page: the report of a sweep's folder (report_parts.hpp, envelope.hpp).
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
#include "crowdrecon/reports/svg.hpp"

namespace crowdrecon::reports {

namespace detail {

// The report of a sweep's folder: the venue-design envelope per variant.
ReportSummary WriteEnvelopeReport(const ReportOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path dir = options.inputs.front();
  CheckOutputs({{"-o", options.output_dir, ReportFolderOutput()}}, {{"the sweep folder", dir}}, options.force);
  const std::string chromium = ChromiumFor(options);
  if (options.progress) options.progress("reading " + (dir / "results.sqlite").string());
  const Envelope e = ReadEnvelope(dir, options.envelope_metric, options.envelope_level);
  ReportSummary summary;
  summary.envelope = true;
  summary.envelope_runs = e.runs;
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">" + std::string(kGenerator) +
                  "<title>Design envelope: " + Escape(e.sweep_name) + "</title><style>" + Css() + "</style></head><body>\n";
  h += "<h1>Venue-design envelope</h1>\n<p class=\"sub\">" + Escape(e.sweep_name) + "<br>" + std::to_string(e.runs) +
       " runs (" + std::to_string(e.failed) + " failed, " + std::to_string(e.without_metric) + " without " +
       Escape(e.metric) + "), made by crowdrecon " + Escape(e.crowdrecon_version) + "; this report: crowdrecon " +
       Escape(CROWDRECON_GIT_VERSION) + ".</p>\n";
  h += "<p>Where in the sweep's " +
       (e.y_axis.empty() ? "axis (" + Escape(e.x_axis) + ")" : "plane (" + Escape(e.x_axis) + " × " + Escape(e.y_axis) + ")") +
       " the median over seeds of <b>" +
       Escape(e.metric) + "</b> stays at or below <b>" + Short(e.level) +
       "</b>: inside the blue edge. Each cell shows the median and, in brackets, the smallest and largest seed; a "
       "dashed square marks a cell whose seeds lie on both sides of the level, where the edge is uncertain. Risk "
       "columns are computed per run with the report's default options (F0 = 400 N, danger above 1112 N, "
       "docs/reports.md).</p>\n";
  std::size_t figures = 0;
  for (const auto& [variant, cells] : e.variants) {
    h += "<h2>" + Escape(variant) + "</h2>\n<figure>" + EnvelopeSvg(e, variant) + "</figure>\n";
    ++figures;
    // Per row of the diagram, the largest x still inside (in a row where the
    // envelope is not one interval from the start, the cells say more).
    std::vector<std::vector<std::string>> rows;
    for (double y : e.ys) {
      // From the smallest x on: the last x before the first cell outside.
      double reach = std::nan(""), all_seeds = std::nan("");
      bool broken = false, broken_all = false;
      for (double x : e.xs)
        for (const EnvelopeCell& c : cells) {
          if (c.x != x || c.y != y) continue;
          broken = broken || !(std::isfinite(c.median) && c.median <= e.level);
          broken_all = broken_all || !(std::isfinite(c.high) && c.high <= e.level);
          if (!broken) reach = x;
          if (!broken_all) all_seeds = x;
        }
      rows.push_back({Short(y), std::isnan(reach) ? "none" : Short(reach), std::isnan(all_seeds) ? "none" : Short(all_seeds)});
      summary.envelope_lines.push_back(variant + (e.y_axis.empty() ? std::string() : ": " + e.y_axis + " " + Short(y)) +
                                       ": inside up to " + e.x_axis + " " +
                                       (std::isnan(reach) ? std::string("none") : Short(reach)) + " (every seed: " +
                                       (std::isnan(all_seeds) ? std::string("none") : Short(all_seeds)) + ")");
    }
    h += Table({e.y_axis.empty() ? std::string("(one axis)") : Escape(e.y_axis), "inside up to " + Escape(e.x_axis) + " (median)",
                "every seed inside up to"},
               rows);
  }
  h += "<h2>Reproducibility</h2>\n<p>Sweep file <code>" + Escape(e.sweep_file) + "</code>; results <code>" +
       Escape(e.results.string()) + "</code>, SHA-256 <code>" + Sha256OfFile(e.results) + "</code>; command <code>" +
       Escape(options.command_line) + "</code>. Rerun the sweep with <code>crowdrecon sweep SWEEP_FILE -o DIR</code> "
       "(identical rows whatever the number of jobs).</p>\n";
  h += SelfCheckScript(figures) + "</body></html>\n";
  WriteReportFolder(options, chromium, h, nullptr, &summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace detail

}  // namespace crowdrecon::reports
