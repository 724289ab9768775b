// The injury-risk report's inputs and its folder (report_parts.hpp).
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

// The browser that prints the PDF ("" without --pdf); without one, the clear
// error before any work.
std::string ChromiumFor(const ReportOptions& options) {
  return options.pdf ? html::ChromiumOrError(options.chromium) : "";
}

// Writes the report's folder as a whole (common/staged_folder.hpp):
// people.csv (if given), report.html and, with a browser, report.pdf printed
// from it. Until all are complete the folder is untouched: a browser that
// fails, Ctrl-C or a kill leaves the previous report as it was.
void WriteReportFolder(const ReportOptions& options, const std::string& chromium, const std::string& html,
                       const std::string* csv, ReportSummary* summary) {
  StagedFolder staged(options.output_dir, ReportFolderOutput());
  for (const fs::path& left : staged.removed())
    summary->notes.push_back("removed " + left.string() + ", left by a report that was killed");
  // What a report of an earlier version left inside its folder (the folder
  // is replaced as a whole, but the note says what went).
  std::error_code ec;
  if (fs::is_directory(options.output_dir, ec) && ReportFolderOutput().is_previous(options.output_dir))
    for (const fs::path& left : RemoveLeftovers(options.output_dir, {".chromium-profile", ".chromium.log"}))
      summary->notes.push_back("removed " + left.string() + ", left by a report that was killed");
  if (csv) {
    staged.Write("people.csv", *csv);
    summary->csv = options.output_dir / "people.csv";
  }
  staged.Write("report.html", html);
  summary->html = options.output_dir / "report.html";
  if (options.pdf) {
    if (options.progress) options.progress("printing report.pdf with " + chromium);
    PrintPdf(chromium, staged.path() / "report.html", staged.path() / "report.pdf");
    summary->pdf = options.output_dir / "report.pdf";
  }
  staged.Commit();
}

std::vector<fs::path> RunFilesOf(const std::vector<fs::path>& inputs, std::vector<std::string>* notes) {
  std::vector<fs::path> files;
  for (const fs::path& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      std::vector<fs::path> found, skipped;
      for (const auto& e : fs::recursive_directory_iterator(in, ec))
        if (e.is_regular_file() && e.path().extension() == ".sqlite")
          (runfile::IsRunFile(e.path()) ? found : skipped).push_back(e.path());
      std::sort(skipped.begin(), skipped.end());
      for (const fs::path& f : skipped)
        notes->push_back("left out " + f.string() + ": a .sqlite file that is not a crowdrecon run file (or is damaged)");
      if (found.empty())
        throw InputError(in.string() + ": a folder without crowdrecon run files (*.sqlite); expected run files, e.g. "
                         "a sweep's folder made with \"keep_runs\": true");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(in, ec)) {
      if (!runfile::IsRunFile(in))
        throw InputError(in.string() + ": " + runfile::DescribeNonRunFile(in) +
                         ", not a crowdrecon run file; expected the SQLite file of crowdrecon simulate");
      files.push_back(in);
    } else {
      throw InputError(in.string() + ": no such file or folder; expected a run file or a folder of run files");
    }
  }
  // The same run twice would count as two seeds (issue 40).
  RefuseRepeatedFiles(files, "each run counts once in an ensemble");
  return files;
}

}  // namespace detail

bool ReportOptions::IsValid(std::string* error) const {
  if (inputs.empty()) {
    if (error) *error = "no run given; expected run files or folders of run files";
    return false;
  }
  if (output_dir.empty()) {
    if (error) *error = "-o: expected the report's folder";
    return false;
  }
  if (table_rows == 0 || table_rows > 100000) {
    if (error) *error = "table rows = " + std::to_string(table_rows) + ", expected in [1, 100000]";
    return false;
  }
  if (!(close_up_m == 0.0 || (close_up_m >= 0.5 && close_up_m <= 1e4))) {
    if (error) *error = "--close-up: " + FormatNumber(close_up_m) + " m, expected 0 (none) or 0.5 .. 10000";
    return false;
  }
  return risk.IsValid(error);
}

OutputKind ReportFolderOutput() {
  return {"a report folder (report.html, report.pdf, people.csv)", true, [](const fs::path& dir) {
            std::error_code ec;
            if (!fs::is_regular_file(dir / "report.html", ec)) return false;
            if (ReadInputFile(dir / "report.html", "report").find(kGenerator) == std::string::npos) return false;
            // With what a killed report of an earlier version left in it (removed
            // when the folder is replaced).
            return FolderHoldsOnly(dir, [](const fs::directory_entry& e) {
              const std::string name = e.path().filename().string();
              return name == "report.html" || name == "report.pdf" || name == "people.csv" ||
                     name == ".chromium-profile" || name == ".chromium.log" || IsStalePartial(e.path());
            });
          }};
}

std::string ReportSummary::BriefReport() const {
  std::string said;
  for (const std::string& n : notes) said += "note: " + n + "\n";
  if (envelope) {
    std::string s = said + "design envelope: " + html.string() + (pdf.empty() ? "" : ", " + pdf.string()) + " (" +
                    std::to_string(envelope_runs) + " runs)\n";
    for (const std::string& line : envelope_lines) s += "  " + line + "\n";
    return s + "  " + Short(seconds) + " s\n";
  }
  std::string s = said + "report: " + html.string() + (pdf.empty() ? "" : ", " + pdf.string()) + ", " + csv.string() + "\n";
  const auto line = [](const EnsembleSummary& e) {
    return "  " + e.label + " (" + std::to_string(e.runs) + (e.runs == 1 ? " run" : " runs") + "): people " +
           Value(e.people.median, 3) + "; safe " + Value(e.zone[0].median, 3) + ", uncomfortable " +
           Value(e.zone[1].median, 3) + ", danger " + Value(e.zone[2].median, 3) + " (medians); beyond tolerance " +
           Value(e.beyond_tolerance.median, 3) +
           "; longest exposure above F0 " + Short(e.longest_exposure_s) + " s; largest load " + Short(e.max_load_n, 4) +
           " N\n";
  };
  s += line(main);
  if (other.runs > 0) s += line(other);
  for (const std::string& v : validity_lines) s += "  validity: " + v + "\n";
  if (danger_ratio.Pairs() > 0) s += "  " + DangerRatioText(danger_ratio, main.label, other.label, false) + "\n";
  s += "  " + Short(seconds) + " s\n";
  return s;
}

}  // namespace crowdrecon::reports
