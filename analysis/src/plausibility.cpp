// States a human crowd can reach (plausibility.hpp; docs/analysis.md).
#include "crowdrecon/analysis/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::analysis {

bool PlausibilityOptions::IsValid(std::string* error) const {
  const auto bad = [&](const char* name, double v, double lo, double hi) {
    if (std::isfinite(v) && v >= lo && v <= hi) return false;
    if (error) *error = std::string(name) + " = " + FormatNumber(v) + ", expected in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
    return true;
  };
  return !(bad("disc_area_m2", disc_area_m2, 0.01, 100.0) || bad("reference_body_area_m2", reference_body_area_m2, 0.01, 1.0) ||
           bad("reference_chest_depth_m", reference_chest_depth_m, 0.05, 1.0) ||
           bad("static_critical_per_m2", static_critical_per_m2, 0.1, 100.0) ||
           bad("crush_highest_per_m2", crush_highest_per_m2, static_critical_per_m2, 100.0) ||
           bad("critical_compression", critical_compression, 0.01, 1.0));
}

const char* ToString(PlausibilityVerdict v) {
  switch (v) {
    case PlausibilityVerdict::kWithin: return "within";
    case PlausibilityVerdict::kBeyondStatic: return "beyond_static_critical";
    case PlausibilityVerdict::kBeyondMeasured: return "beyond_measured";
  }
  return "?";
}

namespace {

// People within a disc of radius r around each person: a grid of cells at
// least r wide (wrapped on periodic axes), each person checked against the
// 3 x 3 cells around its own. Returns, per person, the count (self included)
// and the sum of the counted bodies' areas.
struct Neighbourhoods {
  std::vector<int> count;
  std::vector<double> area_sum;
};

Neighbourhoods CountWithin(const std::vector<Vec2>& p, const std::vector<double>& area, double r, const PeriodicBox& box) {
  const std::size_t n = p.size();
  Neighbourhoods out{std::vector<int>(n, 0), std::vector<double>(n, 0.0)};
  if (n == 0) return out;
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (Vec2 q : p) {
    lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
    hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
  }
  // Per axis: origin, cell width and cell count; a periodic axis is cut into
  // whole cells of its period (at least r wide), so that indices wrap.
  struct Axis {
    double origin, width;
    long cells;
    bool wrap;
  };
  const auto axis = [&](bool periodic, double box_lo, double box_hi, double p_lo, double p_hi) {
    if (periodic) {
      const double length = box_hi - box_lo;
      const long cells = std::max(1L, static_cast<long>(std::floor(length / r)));
      return Axis{box_lo, length / double(cells), cells, true};
    }
    return Axis{p_lo, r, std::max(1L, static_cast<long>(std::floor((p_hi - p_lo) / r)) + 1), false};
  };
  const Axis ax = axis(box.x, box.min_m.x, box.max_m.x, lo.x, hi.x);
  const Axis ay = axis(box.y, box.min_m.y, box.max_m.y, lo.y, hi.y);
  const auto index = [](const Axis& a, double v) {
    long i = static_cast<long>(std::floor((v - a.origin) / a.width));
    if (a.wrap) i = ((i % a.cells) + a.cells) % a.cells;
    return std::clamp(i, 0L, a.cells - 1);
  };
  std::unordered_map<long, std::vector<std::uint32_t>> cells;
  std::vector<long> cx(n), cy(n);
  for (std::size_t i = 0; i < n; ++i) {
    cx[i] = index(ax, p[i].x);
    cy[i] = index(ay, p[i].y);
    cells[cy[i] * ax.cells + cx[i]].push_back(static_cast<std::uint32_t>(i));
  }
  const auto neighbours = [](const Axis& a, long c) {
    std::vector<long> near;
    for (long d = -1; d <= 1; ++d) {
      long k = c + d;
      if (a.wrap) k = ((k % a.cells) + a.cells) % a.cells;
      else if (k < 0 || k >= a.cells) continue;
      if (std::find(near.begin(), near.end(), k) == near.end()) near.push_back(k);
    }
    return near;
  };
  const double r2 = r * r;
  for (std::size_t i = 0; i < n; ++i)
    for (long y : neighbours(ay, cy[i]))
      for (long x : neighbours(ax, cx[i])) {
        const auto it = cells.find(y * ax.cells + x);
        if (it == cells.end()) continue;
        for (std::uint32_t j : it->second) {
          const Vec2 d = box.MinimumImage(p[j] - p[i]);
          if (d.x * d.x + d.y * d.y <= r2) {
            ++out.count[i];
            out.area_sum[i] += area[j];
          }
        }
      }
  return out;
}

}  // namespace

PlausibilityPass::PlausibilityPass(const runfile::RunFileReader& reader, const PlausibilityOptions& options)
    : options_(options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("plausibility: " + why);
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  if (times.empty()) throw InputError(reader.file() + ": the run has no frames");
  for (const runfile::FrameTime& f : times) time_of_[f.frame] = f.time_s;
  frame_s_ = times.size() > 1 ? (times.back().time_s - times.front().time_s) / double(times.size() - 1) : 0.0;
  for (const runfile::Shape& s : reader.Shapes())
    shape_area_.push_back(geometry::Spheropolygon::Create(s.vertices, s.radius_m).area());
  person_shape_ = reader.PersonShapes();
  box_ = reader.periodic_box();
  radius_ = std::sqrt(options.disc_area_m2 / std::numbers::pi);
}

void PlausibilityPass::AddPeople(const runfile::PersonFrame& frame) {
  const PlausibilityOptions& o = options_;
  ++result_.frames;
  position_.clear();
  area_.clear();
  who_.clear();
  for (std::size_t k = 0; k < frame.person.size(); ++k) {
    if (frame.state[k] == runfile::PersonStatus::kRemoved) continue;
    const std::uint32_t person = frame.person[k];
    position_.push_back(frame.position_m[k]);
    area_.push_back(person < person_shape_.size() && person_shape_[person] < shape_area_.size()
                        ? shape_area_[person_shape_[person]]
                        : o.reference_body_area_m2);
    who_.push_back(person);
  }
  const Neighbourhoods near = CountWithin(position_, area_, radius_, box_);
  double frame_peak_equivalent = 0.0;
  for (std::size_t i = 0; i < position_.size(); ++i) {
    const double density = near.count[i] / o.disc_area_m2;
    const double equivalent = near.area_sum[i] / o.reference_body_area_m2 / o.disc_area_m2;
    frame_peak_equivalent = std::max(frame_peak_equivalent, equivalent);
    if (density > result_.peak_density_per_m2 ||
        (density == result_.peak_density_per_m2 && equivalent > result_.peak_equivalent_density_per_m2)) {
      result_.peak_density_per_m2 = density;
      result_.peak_equivalent_density_per_m2 = equivalent;
      result_.peak_mean_body_area_m2 = near.area_sum[i] / near.count[i];
      result_.peak_time_s = time_of_[frame.frame];
      result_.peak_place_m = position_[i];
      result_.peak_person = static_cast<std::int64_t>(who_[i]) + 1;
    }
  }
  if (frame_peak_equivalent > o.static_critical_per_m2) result_.time_beyond_static_s += frame_s_;
  if (frame_peak_equivalent > o.crush_highest_per_m2) result_.time_beyond_measured_s += frame_s_;
}

// The first largest overlap in the order of frames and rows, as the
// reader's LargestContactOverlap picks it (within a frame: the frame's brief,
// runfile::SummarizeContacts, the rule the writer's table uses).
void PlausibilityPass::AddContacts(std::int64_t frame, const std::vector<runfile::Contact>& contacts) {
  const runfile::ContactSummary brief = runfile::SummarizeContacts(contacts);
  if (brief.contacts > 0 && (!contacts_given_ || brief.max_overlap_m > largest_overlap_m_)) {
    contacts_given_ = true;
    largest_overlap_m_ = brief.max_overlap_m;
    largest_overlap_frame_ = frame;
    largest_overlap_wall_ = brief.max_overlap_wall;
  }
}

Plausibility PlausibilityPass::Finish(const runfile::RunFileReader& reader) {
  Plausibility result = result_;
  if (!contacts_given_)
    if (const auto largest = reader.LargestContactOverlap()) {
      contacts_given_ = true;
      largest_overlap_m_ = largest->overlap_m;
      largest_overlap_frame_ = largest->frame;
      largest_overlap_wall_ = largest->wall;
    }
  // A run with its contacts' briefs (issue 66) knows its overlaps even
  // where no two bodies ever touched.
  if (contacts_given_ || reader.HasContactSummary()) {
    result.contacts_available = true;
    if (largest_overlap_m_ > 0.0) {
      result.max_overlap_m = largest_overlap_m_;
      result.max_overlap_time_s = time_of_[largest_overlap_frame_];
      result.max_overlap_with_wall = largest_overlap_wall_;
    }
  }
  const PlausibilityOptions& o = options_;
  const bool overlap_beyond = result.max_overlap_m > o.critical_compression * o.reference_chest_depth_m;
  result.verdict = result.peak_equivalent_density_per_m2 > o.crush_highest_per_m2 || overlap_beyond
                       ? PlausibilityVerdict::kBeyondMeasured
                   : result.peak_equivalent_density_per_m2 > o.static_critical_per_m2 ? PlausibilityVerdict::kBeyondStatic
                                                                                       : PlausibilityVerdict::kWithin;
  return result;
}

Plausibility ComputePlausibility(const std::filesystem::path& run_file, const PlausibilityOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("plausibility: " + why);
  if (!runfile::IsRunFile(run_file)) throw InputError(run_file.string() + ": not a crowdrecon run file");
  const runfile::RunFileReader reader(run_file);
  PlausibilityPass pass(reader, options);
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  runfile::PersonFrameStream stream = reader.PersonFrames(times.back().frame);
  runfile::PersonFrame frame;
  while (stream.Next(&frame)) pass.AddPeople(frame);
  return pass.Finish(reader);
}

std::string Plausibility::Statement(const PlausibilityOptions& o) const {
  const auto num = [](double v, int digits) { return FormatFixed(v, digits); };
  std::string s = "Peak local density " + num(peak_density_per_m2, 1) + " persons/m2 (people within " +
                  num(o.disc_area_m2, 1) + " m2 of person " + std::to_string(peak_person) + " at t = " + num(peak_time_s, 1) +
                  " s); their bodies cover as much floor as " + num(peak_equivalent_density_per_m2, 1) +
                  " real-size persons/m2 (mean body " + num(peak_mean_body_area_m2, 3) + " m2 against " +
                  num(o.reference_body_area_m2, 4) + " m2 for an ANSUR II median thorax with arms).";
  if (peak_equivalent_density_per_m2 > o.crush_highest_per_m2)
    s += " This is beyond any density measured in a human crowd (about " + num(o.crush_highest_per_m2, 0) +
         " /m2 in the worst crushes) for " + num(time_beyond_measured_s, 1) +
         " s of the run: those states are not ones a real crowd reaches, and their loads are the model's, not a crowd's.";
  else if (peak_equivalent_density_per_m2 > o.static_critical_per_m2)
    s += " This is beyond Fruin's critical density of a static crowd (" + num(o.static_critical_per_m2, 1) + " /m2) for " +
         num(time_beyond_static_s, 1) + " s of the run, within what crushes have reached (about " +
         num(o.crush_highest_per_m2, 0) + " /m2).";
  else
    s += " This is within Fruin's critical density of a static crowd (" + num(o.static_critical_per_m2, 1) + " /m2).";
  if (contacts_available && !(max_overlap_m > 0.0)) {
    s += " No two bodies overlapped.";
  } else if (contacts_available) {
    const double share = max_overlap_m / o.reference_chest_depth_m;
    s += " Largest overlap of two bodies" + std::string(max_overlap_with_wall ? " (a body and a wall)" : "") + ": " +
         num(max_overlap_m * 100.0, 1) + " cm at t = " + num(max_overlap_time_s, 1) + " s, " + num(share * 100.0, 0) +
         " % of a chest's depth";
    s += share > o.critical_compression
             ? "; beyond the " + num(o.critical_compression * 100.0, 0) +
                   " % chest compression at which Viano et al. (1989) put a 25 % risk of critical injury, where rigid "
                   "outlines no longer stand for chests."
             : " (Viano et al. 1989: 25 % risk of critical injury at " + num(o.critical_compression * 100.0, 0) +
                   " % compression).";
  } else {
    s += " Overlaps: not known (the run was written without contacts).";
  }
  return s;
}

}  // namespace crowdrecon::analysis
