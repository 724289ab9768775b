// The pieces every HTML report shares (html_page.hpp).
#include "crowdrecon/reports/html_page.hpp"

#include <unistd.h>

#include <cstdlib>
#include <sstream>

#include "crowdrecon/common/child_process.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"

namespace crowdrecon::reports::html {

namespace fs = std::filesystem;

std::string Table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
  std::string s = "<table><thead><tr>";
  for (const auto& h : head) s += "<th>" + h + "</th>";
  s += "</tr></thead><tbody>\n";
  for (const auto& r : rows) {
    s += "<tr>";
    for (const auto& cell : r) s += "<td>" + cell + "</td>";
    s += "</tr>\n";
  }
  return s + "</tbody></table>\n";
}

std::string FindChromium(const std::string& given) {
  if (!given.empty()) return given;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
      const fs::path p = fs::path(dir) / name;
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) return p.string();
    }
  return "";
}

// How long Chromium may take to print a report (a few seconds as a rule).
namespace {
constexpr double kPrintTimeLimitS = 180.0;
}  // namespace

void PrintPdf(const std::string& chromium, const fs::path& html, const fs::path& pdf) {
  if (chromium.empty())
    throw InputError("report.pdf: no Chromium found (looked for chromium, chromium-browser and google-chrome on PATH); "
                     "install Debian's chromium (scripts/install-deps.sh) or give --chromium PATH, or --no-pdf");
  const fs::path profile = pdf.parent_path() / ".chromium-profile";
  const fs::path log = pdf.parent_path() / ".chromium.log";
  // Chromium's own files go, whatever happens (an interruption included).
  struct Tidy {
    const fs::path &profile, &log;
    ~Tidy() {
      std::error_code ec;
      fs::remove_all(profile, ec);
      fs::remove(log, ec);
    }
  };
  std::string log_text;
  ChildResult run;
  {
    Tidy tidy{profile, log};
    run = RunChildProcess({chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                           "--user-data-dir=" + profile.string(), "--no-pdf-header-footer",
                           "--print-to-pdf=" + pdf.string(), "file://" + fs::absolute(html).string()},
                          log, kPrintTimeLimitS);
    std::error_code ec;
    if (!run.problem.empty() && fs::is_regular_file(log, ec)) log_text = ReadInputFile(log, "Chromium log");
  }
  std::error_code ec;
  const bool printed = fs::is_regular_file(pdf, ec) && fs::file_size(pdf, ec) > 0;
  if (run.problem.empty() && !printed) run.problem = "exit status 0 but no PDF written";
  if (!run.problem.empty())
    throw InputError("report.pdf: " + chromium + " could not print " + html.string() + " (" + run.problem + ")" +
                     (log_text.empty() ? "" : ": " + log_text.substr(0, 400)));
}

std::string Css() {
  return R"CSS(
body { font-family: "DejaVu Sans", Arial, sans-serif; color: #222; max-width: 1120px; margin: 24px auto; padding: 0 16px; line-height: 1.45; font-size: 14px; }
h1 { font-size: 24px; margin-bottom: 4px; } h2 { font-size: 19px; border-bottom: 2px solid #ddd; padding-bottom: 3px; margin-top: 30px; }
h3 { font-size: 16px; }
.sub { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 8px 0 14px; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; vertical-align: top; }
th { background: #f1f1ee; } td:first-child, th:first-child { text-align: left; }
.range { color: #666; font-size: 12px; }
.zone-safe { color: #2e8b57; font-weight: bold; } .zone-uncomfortable { color: #a07800; font-weight: bold; } .zone-danger { color: #c0392b; font-weight: bold; }
.key { display: grid; grid-template-columns: repeat(4, 1fr); gap: 10px; margin: 12px 0; }
.key div { border: 1px solid #ddd; border-radius: 6px; padding: 8px 10px; background: #fafaf8; }
.key b { display: block; font-size: 22px; }
svg.chart, svg.plan { max-width: 100%; height: auto; display: block; margin: 6px 0 14px; }
img.network, svg.network { max-width: 100%; height: auto; display: block; border: 1px solid #ddd; }
figure { margin: 10px 0 18px; page-break-inside: avoid; } figcaption { color: #444; font-size: 13px; }
pre { background: #f6f6f3; padding: 8px; overflow-x: auto; font-size: 11px; white-space: pre-wrap; word-break: break-all; }
code { font-size: 12px; } td code { word-break: break-all; } .note { color: #555; font-size: 13px; }
.caveat { border-left: 4px solid #b35806; background: #fff4e6; padding: 6px 10px; margin: 8px 0; }
.inset-pair { display: flex; gap: 12px; align-items: flex-start; } .inset-pair .main { flex: 3; margin: 0; }
.inset-pair .inset { flex: 1.2; margin: 0; } .inset-pair img, .inset-pair svg { max-width: 100%; height: auto; }
@page { size: A4; margin: 14mm; }
@media print { body { max-width: none; margin: 0; font-size: 11px; } h2 { page-break-after: avoid; } details { display: block; } details > summary { display: none; } }
)CSS";
}

// The page checks itself in the browser: any missing image or figure is a
// console error (the browser test fails on console errors).
std::string SelfCheckScript(std::size_t figures) {
  return "<script>\nwindow.addEventListener('load', function () {\n"
         "  for (const img of document.images) if (!img.complete || img.naturalWidth === 0) console.error('missing image: ' + img.src);\n"
         "  const n = document.querySelectorAll('svg, img').length;\n"
         "  if (n < " + std::to_string(figures) + ") console.error('expected " + std::to_string(figures) + " figures, found ' + n);\n"
         "  document.body.setAttribute('data-figures', String(n));\n});\n</script>\n";
}

std::string ChromiumOrError(const std::string& given) {
  const std::string chromium = FindChromium(given);
  if (chromium.empty()) PrintPdf(chromium, {}, {});
  // A browser given by the user is checked too, before any work (issue 65,
  // M15, K41: a path that did not exist failed after the whole report or
  // suite was computed): a program found as given, or by name on PATH.
  if (!given.empty()) {
    const auto runnable = [](const fs::path& p) {
      std::error_code ec;
      return fs::is_regular_file(p, ec) && access(p.c_str(), X_OK) == 0;
    };
    bool found = given.find('/') != std::string::npos && runnable(given);
    if (given.find('/') == std::string::npos) {
      const char* path = std::getenv("PATH");
      std::stringstream dirs(path ? path : "/usr/bin");
      for (std::string dir; !found && std::getline(dirs, dir, ':');) found = runnable(fs::path(dir) / given);
    }
    if (!found)
      throw InputError("--chromium " + given + ": no such program (or not executable); give a Chromium that can print "
                       "the PDF, or --no-pdf for the HTML report alone");
  }
  return chromium;
}

}  // namespace crowdrecon::reports::html
