// Injury risk of a run: each person's chest load over time (chest_load.hpp),
// exposure against tolerance, and the paper's safe / uncomfortable / danger
// zones (docs/reports.md gives the tolerance model, its sources and limits).
//
//   reports::RiskOptions options;             // F0 = 400 N, ...
//   reports::RunRisk risk = reports::AnalyseRunRisk("run.sqlite", options);
//   risk.counts[reports::Zone::kDanger] ...
//
// The run's contacts are read frame by frame (never the whole table at once).
// Errors a user can cause (no run file, a run without contacts, an option out
// of range) are InputError naming the file or the option.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/reports/worst_moment.hpp"

namespace crowdrecon::reports {

// The paper's zones (Figure 6 c-d), per person from the peak of the smoothed
// chest load: below F0, between F0 and the danger load, above it.
enum class Zone : std::uint8_t { kSafe = 0, kUncomfortable = 1, kDanger = 2 };
inline constexpr std::size_t kZones = 3;
const char* ToString(Zone z);

struct RiskOptions {
  // F0: the load the paper takes as the onset of risk ("a reasonable
  // estimation of the load might be 400 N"; Figure 6 scales forces by it).
  double f0_n = kDefaultF0_n;
  // The danger zone's lower edge: the smallest load Hopkins et al. (1993)
  // report as fatal (death after 4-6 minutes at 1112 N).
  double danger_n = 1112.0;
  // Tolerance time T(F) = short_s (F / short_n)^-k, a power law through
  // Hopkins et al.'s two points (6227 N for about 15 s; 1112 N for 4-6 min,
  // taken as 5 min); loads at or below F0 add no dose.
  double lethal_short_n = 6227.0, lethal_short_s = 15.0;
  double lethal_long_n = 1112.0, lethal_long_s = 300.0;
  // The chest load is a moving mean over this window (s): a contact model's
  // loads spike within single steps; a chest is compressed over a breath.
  double smoothing_s = kDefaultSmoothing_s;
  // Called after each frame with (frames done, frames in all); may be empty.
  std::function<void(std::size_t, std::size_t)> progress;
  // People (ids, 1-based) whose smoothed chest-load series RunRisk::series
  // keeps (the report's exposure timelines of the most exposed).
  std::vector<std::uint32_t> series_of;
  // Also the run's validity (analysis/plausibility.hpp) with these options,
  // in the same pass (RunRisk::validity): a long run is read once.
  std::optional<analysis::PlausibilityOptions> validity;
  // false: the run's contacts are read only where it records no chest loads
  // (table person_load) -- the loads alone, for callers that draw no force
  // figures (a sweep's risk columns, an ensemble's scores): in a long run the
  // contact table is most of the file. RunRisk::has_contacts is then false
  // and the contact force statistics are empty.
  bool read_contacts = true;

  bool IsValid(std::string* error) const;
  // The exponent k of the tolerance power law.
  double ToleranceExponent() const;
  // T(F) in seconds; infinite at or below F0.
  double ToleranceTime_s(double load_n) const;
  Zone ZoneOf(double load_n) const;
};

// One person's exposure over the run (loads are the smoothed chest load,
// the larger of across the chest and across the shoulders).
struct PersonRisk {
  std::uint32_t id = 0;  // 1-based, as in the run file
  std::uint32_t group = 0;
  double first_seen_s = std::numeric_limits<double>::quiet_NaN();
  double last_seen_s = std::numeric_limits<double>::quiet_NaN();
  double max_load_n = 0.0;
  double max_load_time_s = 0.0;
  Vec2 max_load_position_m;
  double max_raw_load_n = 0.0;        // the largest single-frame load (unsmoothed)
  double time_above_f0_s = 0.0;
  double longest_above_f0_s = 0.0;    // the longest continuous stretch
  double time_above_danger_s = 0.0;
  double dose = 0.0;                  // sum of dt / T(F): 1 = the tolerance reached
  bool fell = false;                  // fallen at some frame
  Zone zone = Zone::kSafe;
};

// The crowd at one frame.
struct FrameRisk {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::uint32_t present = 0;
  std::uint32_t above_f0 = 0;      // smoothed load above F0
  std::uint32_t above_danger = 0;  // smoothed load above the danger load
  std::uint32_t contacts = 0;
  double max_load_n = 0.0;
};

struct RunRisk {
  std::filesystem::path file;
  std::string scenario_name;
  // The model profile that made it (run value "profile"; run files from
  // before profiles ran the paper's: said so).
  std::string profile;
  std::string venue_name;
  std::string seed;
  double fps = 0.0;
  double duration_s = 0.0;
  std::vector<PersonRisk> people;  // everyone who appeared, by id
  std::vector<FrameRisk> frames;
  ForceHistogram contact_forces;   // every contact of every frame, |F| / F0
  // The worst moment: the frame with the most people above F0 (ties: the
  // largest load), for the force network and the per-contact distribution.
  std::int64_t worst_frame = 0;
  double worst_time_s = 0.0;
  std::vector<double> worst_contact_forces_n;  // every contact's |F| at the worst frame
  std::vector<double> worst_person_loads_n;    // every present person's smoothed load then
  // The person with the largest smoothed load at the worst moment (id,
  // 1-based; 0: nobody present) and where they stood: the report's close-up.
  std::int64_t worst_person = 0;
  Vec2 worst_place_m;
  std::array<std::uint32_t, kZones> counts{};  // people per zone
  std::uint32_t beyond_tolerance = 0;          // dose >= 1
  std::uint32_t fallen = 0;
  std::uint64_t contact_rows = 0;
  // The smoothed load over time of each of RiskOptions::series_of: (time, load) while present.
  std::vector<std::vector<std::pair<double, double>>> series;
  bool loads_recorded = false;  // chest loads from table person_load (else computed from the contacts)
  bool has_contacts = false;    // the run has a contact table with rows, read: force network and force distributions
  // A run that keeps some frames' contacts (run.contacts as an object;
  // contact_keeper.hpp): its whole-run force distribution comes from its
  // frames' histograms (contact_forces_from says how), and has_contacts says
  // whether it kept the worst moment's rows; if not, contacts_note says why.
  bool keeps_some_contacts = false;
  std::string contact_forces_from;
  std::string contacts_note;
  std::optional<analysis::Plausibility> validity;  // if RiskOptions::validity asked for it
};

RunRisk AnalyseRunRisk(const std::filesystem::path& run_file, const RiskOptions& options);

}  // namespace crowdrecon::reports
