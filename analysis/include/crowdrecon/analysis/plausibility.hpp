// States a human crowd can reach (issue 39): a run's peak local density and
// its largest body overlap, against a stated validity range with sources, so
// that an output whose states leave that range says so in plain words.
//
// Local density: for each person present in a frame (walking or fallen), the
// number of people whose centres lie within the disc of area
// `disc_area_m2` (1 m^2: radius 0.564 m) centred on the person, the person
// included, per m^2; the peak is over every person and frame. A density of
// model bodies is not one of real people when the bodies are smaller than
// people (ERRATA 7: the paper's bodies cover about two-thirds of a real
// thorax's area), so it is also given as the density of real-size people
// covering the same floor: count x (mean area of the counted bodies) /
// `reference_body_area_m2`, and the range is checked on that figure.
//
// Overlap: the largest overlap of two bodies (or a body and a wall) in the
// run's contacts, as a share of a chest's depth; the run must have been
// written with contacts.
//
// Validity range (docs/analysis.md, "States a human crowd can reach"):
//   up to 7.1 /m^2      Fruin's critical density of a static crowd
//   up to 10 /m^2       the highest densities measured in crushes (about 9-10 /m^2)
//   beyond 10 /m^2      no human crowd has been measured there
//   overlap above 38 %  of a chest's depth: Viano et al. (1989) put a 25 % risk
//                       of critical injury at 38 % chest compression; beyond it
//                       rigid outlines no longer stand for chests
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::runfile {
class RunFileReader;
struct PersonFrame;
struct Contact;
}  // namespace crowdrecon::runfile

namespace crowdrecon::analysis {

struct PlausibilityOptions {
  double disc_area_m2 = 1.0;               // the local density's disc (about 1 m^2, as the issue asks)
  double reference_body_area_m2 = 0.0868;  // ANSUR II median thorax with arms (docs/bodies.md)
  double reference_chest_depth_m = 0.249;  // ANSUR II median chest depth (docs/bodies.md)
  double static_critical_per_m2 = 7.1;     // Fruin
  double crush_highest_per_m2 = 10.0;      // highest densities measured in crushes
  double critical_compression = 0.38;      // Viano et al. 1989, 25 % risk of critical injury
  bool IsValid(std::string* error) const;
};

enum class PlausibilityVerdict {
  kWithin,          // at most Fruin's critical static density, overlaps within the chest's tolerance
  kBeyondStatic,    // beyond Fruin's 7.1 /m^2, within what crushes have reached
  kBeyondMeasured,  // beyond any density measured in a human crowd, or overlaps beyond a chest's tolerance
};
const char* ToString(PlausibilityVerdict v);

struct Plausibility {
  std::size_t frames = 0;
  double peak_density_per_m2 = 0.0;             // model bodies per m^2
  double peak_equivalent_density_per_m2 = 0.0;  // real-size people per m^2 covering the same floor
  double peak_mean_body_area_m2 = 0.0;          // mean area of the bodies counted at the peak
  double peak_time_s = 0.0;
  Vec2 peak_place_m;
  std::int64_t peak_person = 0;              // id (1-based) at the disc's centre
  double time_beyond_static_s = 0.0;         // frames whose peak equivalent density exceeds 7.1 /m^2, as time
  double time_beyond_measured_s = 0.0;       // ... exceeds 10 /m^2
  bool contacts_available = false;
  double max_overlap_m = 0.0;
  double max_overlap_time_s = 0.0;
  bool max_overlap_with_wall = false;
  PlausibilityVerdict verdict = PlausibilityVerdict::kWithin;
  // One paragraph in plain words: the figures, the range and what they mean.
  std::string Statement(const PlausibilityOptions& options) const;
};

// Reads every frame of the run (positions, and contacts if it has them).
// Throws InputError for a file that is not a run or a run without frames.
Plausibility ComputePlausibility(const std::filesystem::path& run_file, const PlausibilityOptions& options = {});

// ComputePlausibility's pass, for a reader of the run's frames that reads
// them anyway (AnalyzeRun, the risk report): a run of many gigabytes is then
// read once, not once more for its validity. Give it every frame of people of
// the run in order (runfile::PersonFrameStream) and, optionally, the contacts
// of every frame that has any; Finish returns what ComputePlausibility
// returns, reading the run's largest contact overlap from its table only if
// no contacts were given.
class PlausibilityPass {
 public:
  // Throws InputError for a run without frames or invalid options.
  explicit PlausibilityPass(const runfile::RunFileReader& reader, const PlausibilityOptions& options = {});
  void AddPeople(const runfile::PersonFrame& frame);
  void AddContacts(std::int64_t frame, const std::vector<runfile::Contact>& contacts);
  Plausibility Finish(const runfile::RunFileReader& reader);

 private:
  PlausibilityOptions options_;
  std::unordered_map<std::int64_t, double> time_of_;
  double frame_s_ = 0.0;
  std::vector<double> shape_area_;
  std::vector<std::uint32_t> person_shape_;
  PeriodicBox box_;
  double radius_ = 0.0;
  Plausibility result_;
  bool contacts_given_ = false;
  double largest_overlap_m_ = 0.0;
  std::int64_t largest_overlap_frame_ = 0;
  bool largest_overlap_wall_ = false;
  std::vector<Vec2> position_;
  std::vector<double> area_;
  std::vector<std::uint32_t> who_;
};

}  // namespace crowdrecon::analysis
