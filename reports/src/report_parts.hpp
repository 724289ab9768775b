// The injury-risk report's parts shared by its files (internal to reports):
// report.cpp writes the page of an ensemble (WriteReport's named sections),
// report_figures.cpp its figures and numbers, report_folder.cpp its inputs
// and its folder, envelope_report.cpp the page of a sweep's folder.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/reports/html_page.hpp"
#include "crowdrecon/reports/svg.hpp"
#include "crowdrecon/reports/report.hpp"
#include "crowdrecon/reports/risk.hpp"

namespace crowdrecon::viz {
struct RenderSummary;
}

namespace crowdrecon::reports::detail {

inline constexpr const char* kGenerator = "<meta name=\"generator\" content=\"crowdrecon report\">";
inline constexpr std::array<const char*, kZones> kZoneColor = {"#2e8b57", "#e0a800", "#c0392b"};
inline constexpr const char* kOtherColor = "#7b3f98";
// Runs of at least this many frames get progress lines during their pass.
inline constexpr std::size_t kFramesForProgress = 1000;

// Counts whole (a median of an even number of runs may end in .5); other
// values with `digits` significant digits.
std::string Value(double v, int digits);
std::string SpreadText(const Spread& s, int digits = 3);

// The force network of `frame` of a run, drawn by viz (the paper's Figure 6
// a-b): the whole view, or with `window` (its lower-left and upper-right
// corners) that part of it; `summary` (may be null) receives the layout.
std::string ForceNetworkFigure(const std::filesystem::path& run, std::int64_t frame, std::uint32_t people,
                               const std::string& id_prefix, const std::optional<std::pair<Vec2, Vec2>>& window,
                               viz::RenderSummary* summary = nullptr,
                               const std::optional<std::pair<Vec2, Vec2>>& mark = std::nullopt, int width_px = 0);
// 1 - CDF of each set of forces (N, sorted) against F / F0, with the zones.
std::string CdfChart(const std::string& title, const std::string& x_label,
                     const std::vector<std::pair<std::string, std::vector<double>>>& sets, const RiskOptions& o,
                     const std::vector<std::string>& colors);

// The browser that prints the PDF ("" without --pdf); without one, the clear
// error before any work.
std::string ChromiumFor(const ReportOptions& options);
// Writes the report's folder as a whole: people.csv (if given), report.html
// and, with a browser, report.pdf printed from it.
void WriteReportFolder(const ReportOptions& options, const std::string& chromium, const std::string& html,
                       const std::string* csv, ReportSummary* summary);
// Expands inputs into run files (folders: every *.sqlite run file below,
// sorted; what is left out is said in `notes`); throws InputError naming an
// input that is neither, or a run given twice.
std::vector<std::filesystem::path> RunFilesOf(const std::vector<std::filesystem::path>& inputs,
                                              std::vector<std::string>* notes);

// The report of a sweep's folder: the venue-design envelope per variant.
ReportSummary WriteEnvelopeReport(const ReportOptions& options);

}  // namespace crowdrecon::reports::detail

// The names every file of the report uses (internal: included by reports/src only).
namespace crowdrecon::reports {
namespace fs = std::filesystem;
using svg::Escape;
using svg::Short;
using namespace detail;
using html::Css;
using html::PrintPdf;
using html::SelfCheckScript;
using html::Table;
}  // namespace crowdrecon::reports
