// The validation suite's measures (measures.hpp): one definition of every
// statistic, applied alike to runs and to experiments' trajectories.
#include "crowdrecon/validate/measures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "crowdrecon/analysis/passages.hpp"
#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/observe/fundamental_diagram.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::validate {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const std::vector<std::pair<MeasureKind, const char*>>& KindNames() {
  static const std::vector<std::pair<MeasureKind, const char*>> names = {
      {MeasureKind::kTravel, "travel"},
      {MeasureKind::kWalls, "walls"},
      {MeasureKind::kWalkingSpeed, "walking_speed"},
      {MeasureKind::kPassages, "passages"},
      {MeasureKind::kClearance, "clearance"},
      {MeasureKind::kFundamentalDiagram, "fundamental_diagram"},
      {MeasureKind::kHeadway, "headway"},
      {MeasureKind::kLanes, "lanes"},
      {MeasureKind::kStartTimes, "start_times"},
      {MeasureKind::kRunState, "run_state"}};
  return names;
}

// Where along [p, q] the segment crosses [a, b] (the fraction from p), or a
// negative number if it does not. Touching at an end counts (a step that
// ends exactly on a line crosses it then).
double CrossingFraction(Vec2 p, Vec2 q, Vec2 a, Vec2 b) {
  const Vec2 r = q - p, s = b - a;
  const double denominator = Cross(r, s);
  if (denominator == 0.0) return -1.0;  // parallel: never counted as a crossing
  const double t = Cross(a - p, s) / denominator;
  const double u = Cross(a - p, r) / denominator;
  if (t < 0.0 || t > 1.0 || u < 0.0 || u > 1.0) return -1.0;
  return t;
}

// Velocity samples of every frame that is a multiple of the step, with the
// positions: what the headway and the walking direction read.
struct Sample {
  Vec2 position_m, velocity_m_per_s;
};

std::map<std::int64_t, std::vector<Sample>> SamplesByFrame(const observe::Trajectories& t,
                                                           const std::vector<observe::Track>& tracks,
                                                           const MeasureSpec& spec) {
  const int half_span = std::max(1, int(std::lround(0.5 * spec.velocity_span_s * t.fps)));
  std::map<std::int64_t, std::vector<Sample>> by_frame;
  for (const observe::Track& track : tracks)
    for (std::size_t k = 0; k < track.frame.size(); ++k) {
      if ((track.frame[k] - t.first_frame) % spec.frame_step != 0) continue;
      if (double(track.frame[k] - t.first_frame) / t.fps < spec.skip_s) continue;
      Vec2 v;
      if (!observe::VelocityAt(track, k, half_span, t.fps, t.box, &v)) continue;
      by_frame[track.frame[k]].push_back({track.position_m[k], v});
    }
  return by_frame;
}

void MeasureTravel(const observe::Trajectories& t, const std::vector<observe::Track>& tracks, const MeasureSpec& spec,
                   Statistics* out) {
  std::vector<double> times, speeds;
  // The distance walked between the lines: from the first line's middle to the second.
  const Vec2 from_mid = 0.5 * (spec.from_line.a_m + spec.from_line.b_m);
  const Vec2 to_mid = 0.5 * (spec.to_line.a_m + spec.to_line.b_m);
  const double distance_m = Length(to_mid - from_mid);
  std::size_t arrived = 0;
  for (const observe::Track& track : tracks) {
    const double start = FirstCrossing_s(track, t.fps, spec.from_line, {}, -1e300);
    if (!std::isfinite(start)) continue;
    const double end = FirstCrossing_s(track, t.fps, spec.to_line, {}, start);
    if (!std::isfinite(end)) continue;
    ++arrived;
    // (times relative to the file's first frame cancel in the difference)
    times.push_back(end - start);
    speeds.push_back(end > start ? distance_m / (end - start) : kNaN);
  }
  (*out)["travel_time_s"] = times;
  (*out)["speed_m_per_s"] = speeds;
  (*out)["arrived_share"] = {tracks.empty() ? kNaN : double(arrived) / double(tracks.size())};
}

void MeasureWalls(const std::vector<observe::Track>& tracks, const std::vector<runfile::Wall>& walls,
                  const PeriodicBox& box, Statistics* out) {
  double outside = 0, crossings = 0;
  for (const observe::Track& track : tracks)
    for (std::size_t k = 0; k < track.position_m.size(); ++k) {
      const Vec2 p = track.position_m[k];
      bool in_wall = false;
      for (const runfile::Wall& w : walls) {
        const std::size_t n = w.points.size();
        const std::size_t segments = w.closed ? n : (n == 0 ? 0 : n - 1);
        for (std::size_t s = 0; s < segments && !in_wall; ++s) {
          const Vec2 a = w.points[s], b = w.points[(s + 1) % n];
          if (w.radius_m > 0.0 && DistanceToSegment(p, a, b) < w.radius_m) in_wall = true;
          // A step across the wall's line (not across a periodic seam: a
          // wrapped step is no walk).
          if (k > 0 && track.frame[k] == track.frame[k - 1] + 1) {
            const Vec2 q = track.position_m[k - 1];
            const Vec2 step = p - q;
            if (Length(box.MinimumImage(step)) + 1e-12 < Length(step)) continue;
            if (CrossingFraction(q, p, a, b) >= 0.0) crossings += 1;
          }
        }
      }
      if (in_wall) outside += 1;
    }
  (*out)["outside_walls"] = {outside};
  (*out)["wall_crossings"] = {crossings};
  (*out)["people"] = {double(tracks.size())};
}

void MeasureWalkingSpeed(const observe::Trajectories& t, const std::vector<observe::Track>& tracks,
                         const MeasureSpec& spec, const std::vector<std::string>& group_names, Statistics* out) {
  std::vector<double> speeds;
  std::map<std::string, std::vector<double>> by_group;
  for (const observe::Track& track : tracks) {
    // A walking speed is the distance covered over the time taken (RiMEA's
    // tests time a walk over a distance; PedPy's passing speed likewise):
    // per stretch of consecutive frames inside the area, the length of the
    // displacement from its first frame to its last (the steps summed as
    // vectors: a periodic seam is crossed by minimum images), so that a
    // gait's sway across the way is not counted as distance.
    double path = 0, time = 0;
    Vec2 stretch{};
    for (std::size_t k = 1; k <= track.position_m.size(); ++k) {
      const bool step = k < track.position_m.size() && track.frame[k] == track.frame[k - 1] + 1 &&
                        spec.area.Contains(track.position_m[k]) && spec.area.Contains(track.position_m[k - 1]);
      if (step) {
        stretch += t.box.MinimumImage(track.position_m[k] - track.position_m[k - 1]);
        time += 1.0 / t.fps;
      } else {
        path += Length(stretch);
        stretch = Vec2{};
      }
    }
    if (time <= 0.0) continue;
    const double v = path / time;
    speeds.push_back(v);
    const std::string name =
        track.group < group_names.size() ? group_names[track.group] : "group" + std::to_string(track.group);
    // (an experiment's people have no group: "group0")
    by_group[name].push_back(v);
  }
  (*out)["speed_m_per_s"] = speeds;
  for (auto& [name, v] : by_group) (*out)["speed_m_per_s@" + name] = v;
}

void MeasurePassages(const observe::Trajectories& t, const std::vector<observe::Track>& tracks,
                     const MeasureSpec& spec, Statistics* out) {
  std::vector<double> passages;
  for (const observe::Track& track : tracks) {
    // (times from the file's first frame: an experiment's frames start anywhere)
    const double c = FirstCrossing_s(track, t.fps, spec.line, spec.direction) - double(t.first_frame) / t.fps;
    if (std::isfinite(c)) passages.push_back(c);
  }
  std::sort(passages.begin(), passages.end());
  const double end_s = double(t.last_frame - t.first_frame) / t.fps;
  const std::size_t n = passages.size();
  (*out)["passed"] = {double(n)};
  (*out)["passed_share"] = {tracks.empty() ? kNaN : double(n) / double(tracks.size())};
  const bool everyone = n == tracks.size();
  (*out)["open_lapse_s"] = {everyone ? 0.0 : end_s - (n ? passages.back() : 0.0)};
  (*out)["time_to_all_s"] = {everyone && n ? passages.back() : kNaN};
  const std::size_t n95 = std::size_t(std::ceil(0.95 * double(tracks.size())));
  (*out)["time_to_95_s"] = {n95 >= 1 && n >= n95 ? passages[n95 - 1] : kNaN};
  if (n < 2) return;
  const double span = passages.back() - passages.front();
  (*out)["span_s"] = {span};
  (*out)["flow_per_s"] = {span > 0 ? double(n - 1) / span : kNaN};
  // Over the whole run: a clog that lasts to the end counts as time without
  // passages (the flow while people pass flatters a run that clogged early).
  const double until = everyone ? passages.back() : end_s;
  (*out)["sustained_flow_per_s"] = {until > passages.front() ? double(n - 1) / (until - passages.front()) : kNaN};
  analysis::PassageOptions options;
  const analysis::PassageStatistics p = analysis::AnalyzePassages(passages, passages.front(), passages.back(), options);
  (*out)["lapse_s"] = p.lapses_s;
  (*out)["median_lapse_s"] = {p.median_lapse_s};
  (*out)["max_lapse_s"] = {p.max_lapse_s};
  (*out)["tail_exponent"] = {p.tail_exponent};
  if (!spec.has_area) return;
  // Front density: the people in the area, frame by frame between the
  // first and the last passage.
  const std::int64_t f0 = t.first_frame + std::int64_t(std::ceil(passages.front() * t.fps));
  const std::int64_t f1 = t.first_frame + std::int64_t(std::floor(passages.back() * t.fps));
  std::map<std::int64_t, int> counts;
  for (std::int64_t f = f0; f <= f1; ++f) counts[f] = 0;
  for (const observe::Track& track : tracks)
    for (std::size_t k = 0; k < track.frame.size(); ++k)
      if (track.frame[k] >= f0 && track.frame[k] <= f1 && spec.area.Contains(track.position_m[k]))
        ++counts[track.frame[k]];
  double sum = 0;
  for (const auto& [f, c] : counts) sum += c;
  if (!counts.empty()) (*out)["front_density_per_m2"] = {sum / double(counts.size()) / spec.area.Area_m2()};
}

void MeasureClearance(const observe::Trajectories& t, const std::vector<observe::Track>& tracks, Statistics* out) {
  std::vector<double> left;
  for (const observe::Track& track : tracks)
    if (!track.frame.empty() && track.frame.back() < t.last_frame)
      left.push_back(double(track.frame.back() - t.first_frame) / t.fps);
  std::sort(left.begin(), left.end());
  const std::size_t n = tracks.size();
  (*out)["left_share"] = {n ? double(left.size()) / double(n) : kNaN};
  (*out)["time_to_all_s"] = {n && left.size() == n ? left.back() : kNaN};
  const std::size_t n95 = std::size_t(std::ceil(0.95 * double(n)));
  (*out)["time_to_95_s"] = {n95 >= 1 && left.size() >= n95 ? left[n95 - 1] : kNaN};
}

void MeasureFundamentalDiagram(const observe::Trajectories& t, const MeasureSpec& spec, Statistics* out) {
  const observe::FundamentalDiagram fd =
      observe::ComputeFundamentalDiagram(t, spec.area, spec.velocity_span_s, spec.frame_step);
  std::vector<double> rho, v;
  const double t0 = double(t.first_frame) / t.fps;
  for (const observe::FundamentalDiagramPoint& p : fd.points) {
    if (p.time_s - t0 < spec.skip_s || !std::isfinite(p.speed_m_per_s)) continue;
    rho.push_back(p.density_per_m2);
    v.push_back(p.speed_m_per_s);
  }
  double sr = 0, sv = 0, sj = 0;
  for (std::size_t i = 0; i < rho.size(); ++i) {
    sr += rho[i];
    sv += v[i];
    sj += rho[i] * v[i];
  }
  const double n = double(rho.size());
  (*out)["density_per_m2"] = {n > 0 ? sr / n : kNaN};
  (*out)["speed_m_per_s"] = {n > 0 ? sv / n : kNaN};
  (*out)["specific_flow_per_m_s"] = {n > 0 ? sj / n : kNaN};
  (*out)["fd_density_per_m2"] = rho;
  (*out)["fd_speed_m_per_s"] = v;
}

void MeasureHeadway(const observe::Trajectories& t, const std::vector<observe::Track>& tracks, const MeasureSpec& spec,
                    Statistics* out) {
  const auto by_frame = SamplesByFrame(t, tracks, spec);
  std::vector<double> headways, densities;
  const double area = spec.area.Area_m2();
  for (const auto& [frame, samples] : by_frame) {
    std::size_t in_area = 0;
    for (const Sample& s : samples) {
      if (!spec.area.Contains(s.position_m)) continue;
      ++in_area;
      const double speed = Length(s.velocity_m_per_s);
      if (speed < 0.1) continue;  // standing people have no "ahead"
      const Vec2 e = s.velocity_m_per_s / speed;
      double best = std::numeric_limits<double>::infinity();
      for (const Sample& o : samples) {
        if (&o == &s) continue;
        const Vec2 d = t.box.MinimumImage(o.position_m - s.position_m);
        const double along = Dot(d, e);
        if (along <= 0.0 || std::abs(Cross(e, d)) > spec.lane_half_width_m) continue;
        best = std::min(best, along);
      }
      if (best <= spec.max_headway_m) headways.push_back(best);
    }
    densities.push_back(double(in_area) / area);
  }
  double sum = 0;
  for (double d : densities) sum += d;
  (*out)["headway_m"] = headways;
  (*out)["density_per_m2"] = {densities.empty() ? kNaN : sum / double(densities.size())};
}

// A run's group names by index: a timeline's (run value groups), else the
// population's two (main, counter).
// Each person's observed start against their pre-movement time: the first
// frame from one second before their time at which their centre is 0.01 m
// from where it was then (a person standing in place does not move at all in
// the model; 0.01 m is far above rounding and far below a step). Measured
// from a second before, so that a push long before (people walking past a
// standing person move them) is counted apart, as moved_early.
Statistics MeasureStartTimes(const observe::Trajectories& t, const std::vector<runfile::Event>& events) {
  constexpr double kMoved_m = 0.01, kBefore_s = 1.0;
  std::map<std::uint32_t, double> due;  // id -> the time the run started them
  double gone = 0;                      // not walking at their time (pushed out, fallen)
  std::vector<double> premovement, delay;
  for (const runfile::Event& e : events) {
    if (e.kind != "start" || e.person < 0) continue;
    premovement.push_back(e.time_s);  // everyone's time, there at it or not
    if (e.detail.find("not walking") != std::string::npos) {
      gone += 1;
      continue;
    }
    due[static_cast<std::uint32_t>(e.person + 1)] = e.time_s;
  }
  double early = 0, never = 0;
  for (const observe::Track& track : observe::TracksOf(t)) {
    const auto it = due.find(track.id);
    if (it == due.end() || track.position_m.empty()) continue;
    const auto time_of = [&](std::size_t k) { return double(track.frame[k] - t.first_frame) / t.fps; };
    std::size_t from = 0;
    while (from + 1 < track.position_m.size() && time_of(from + 1) <= it->second - kBefore_s) ++from;
    if (Length(t.box.MinimumImage(track.position_m[from] - track.position_m[0])) > kMoved_m) early += 1;
    double started = kNaN;
    for (std::size_t k = from; k < track.position_m.size(); ++k)
      if (Length(t.box.MinimumImage(track.position_m[k] - track.position_m[from])) > kMoved_m) {
        started = time_of(k);
        break;
      }
    if (!std::isfinite(started)) never += 1;
    delay.push_back(started - it->second);
  }
  Statistics out;
  out["premovement_s"] = premovement;
  out["start_delay_s"] = delay;
  out["moved_early"] = {early};
  out["never_started"] = {never};
  out["started_people"] = {double(due.size()) + gone};
  out["gone_before_start"] = {gone};
  return out;
}

// Lane order frame by frame, after the band order parameter of driven binary
// mixtures (Rex and Löwen 2007): each walker's neighbours in a band along the
// walking axis, by direction of travel, (same - opposite) / (same + opposite),
// averaged over the walkers (not squared as there: a walker among people
// coming the other way is the opposite of a lane, -1, not another lane).
// Organized at 0.8 and above; a lane counts as broken once the order falls
// below 0.6 (the gap keeps a flicker at the threshold from counting).
void MeasureLanes(const observe::Trajectories& t, const std::vector<observe::Track>& tracks, const MeasureSpec& spec,
                  Statistics* out) {
  constexpr double kAlong_m = 1.5, kOrganized = 0.8, kBroken = 0.6, kMoving_m_per_s = 0.1;
  const auto by_frame = SamplesByFrame(t, tracks, spec);
  const Vec2 axis = Normalized(spec.direction);
  std::vector<double> order, times;
  for (const auto& [frame, samples] : by_frame) {
    double sum = 0;
    std::size_t counted = 0;
    for (const Sample& a : samples) {
      if (!spec.area.Contains(a.position_m)) continue;
      const double va = Dot(a.velocity_m_per_s, axis);
      if (std::abs(va) < kMoving_m_per_s) continue;
      double same = 0, opposite = 0;
      for (const Sample& b : samples) {
        if (&a == &b) continue;
        const double vb = Dot(b.velocity_m_per_s, axis);
        if (std::abs(vb) < kMoving_m_per_s) continue;
        const Vec2 d = t.box.MinimumImage(b.position_m - a.position_m);
        if (std::abs(Dot(d, axis)) > kAlong_m || std::abs(Cross(axis, d)) > spec.lane_half_width_m) continue;
        ((va > 0) == (vb > 0) ? same : opposite) += 1;
      }
      if (same + opposite == 0) continue;
      sum += (same - opposite) / (same + opposite);
      ++counted;
    }
    if (counted == 0) continue;
    order.push_back(sum / double(counted));
    times.push_back(double(frame - t.first_frame) / t.fps);
  }
  double organized = 0, breaks = 0, reformations = 0, longest = 0, run_start = kNaN;
  bool in_lanes = false, broken_once = false;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (order[k] >= kOrganized) organized += 1;
    if (!in_lanes && order[k] >= kOrganized) {
      in_lanes = true;
      run_start = times[k];
      if (broken_once) reformations += 1;
    } else if (in_lanes && order[k] < kBroken) {
      in_lanes = false;
      broken_once = true;
      breaks += 1;
      longest = std::max(longest, times[k] - run_start);
    }
  }
  if (in_lanes && !times.empty()) longest = std::max(longest, times.back() - run_start);
  (*out)["lane_order"] = order;
  (*out)["organized_share"] = {order.empty() ? kNaN : organized / double(order.size())};
  (*out)["lane_breaks"] = {breaks};
  (*out)["lane_reformations"] = {reformations};
  (*out)["longest_organized_s"] = {longest};
  (*out)["organized_at_end"] = {in_lanes ? 1.0 : 0.0};
}

std::vector<std::string> SplitGroups(const std::string& text) {
  if (text.empty()) return {"main", "counter"};
  std::vector<std::string> names;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) names.push_back(name);
  return names;
}

Statistics Measure(const observe::Trajectories& t, const MeasureSpec& spec, const std::vector<std::string>& group_names,
                   const std::vector<runfile::Wall>* walls) {
  std::string error;
  if (!spec.IsValid(&error)) throw InputError("validation measure: " + error);
  if (!(t.fps > 0)) throw InputError(t.source + ": no frame rate; expected trajectories with one");
  std::vector<observe::Track> tracks = observe::TracksOf(t);
  if (!spec.group.empty()) {
    const auto name_of = [&](std::uint32_t g) {
      return g < group_names.size() ? group_names[g] : "group" + std::to_string(g);
    };
    std::erase_if(tracks, [&](const observe::Track& track) { return name_of(track.group) != spec.group; });
  }
  Statistics out;
  switch (spec.kind) {
    case MeasureKind::kTravel: MeasureTravel(t, tracks, spec, &out); break;
    case MeasureKind::kWalls:
      if (!walls) throw InputError(t.source + ": the walls measure needs a crowdrecon run file (its walls)");
      MeasureWalls(tracks, *walls, t.box, &out);
      break;
    case MeasureKind::kWalkingSpeed: MeasureWalkingSpeed(t, tracks, spec, group_names, &out); break;
    case MeasureKind::kPassages: MeasurePassages(t, tracks, spec, &out); break;
    case MeasureKind::kClearance: MeasureClearance(t, tracks, &out); break;
    case MeasureKind::kFundamentalDiagram: MeasureFundamentalDiagram(t, spec, &out); break;
    case MeasureKind::kHeadway: MeasureHeadway(t, tracks, spec, &out); break;
    case MeasureKind::kLanes: MeasureLanes(t, tracks, spec, &out); break;
    case MeasureKind::kStartTimes:
    case MeasureKind::kRunState:
      throw InputError(t.source + ": the " + ToString(spec.kind) + " measure needs a crowdrecon run file");
  }
  return out;
}

}  // namespace

std::string ToString(MeasureKind kind) {
  for (const auto& [k, name] : KindNames())
    if (k == kind) return name;
  return "unknown";
}

bool FromString(const std::string& name, MeasureKind* kind) {
  for (const auto& [k, n] : KindNames())
    if (name == n) {
      *kind = k;
      return true;
    }
  return false;
}

const std::vector<std::string>& StatisticNames(MeasureKind kind) {
  static const std::map<MeasureKind, std::vector<std::string>> names{
      {MeasureKind::kTravel, {"travel_time_s", "speed_m_per_s", "arrived_share"}},
      {MeasureKind::kWalls, {"outside_walls", "wall_crossings", "people"}},
      {MeasureKind::kWalkingSpeed, {"speed_m_per_s"}},
      {MeasureKind::kPassages,
       {"passed", "passed_share", "open_lapse_s", "time_to_all_s", "time_to_95_s", "span_s", "flow_per_s",
        "sustained_flow_per_s", "lapse_s", "median_lapse_s", "max_lapse_s", "tail_exponent", "front_density_per_m2"}},
      {MeasureKind::kClearance, {"left_share", "time_to_all_s", "time_to_95_s"}},
      {MeasureKind::kFundamentalDiagram,
       {"density_per_m2", "speed_m_per_s", "specific_flow_per_m_s", "fd_density_per_m2", "fd_speed_m_per_s"}},
      {MeasureKind::kHeadway, {"headway_m", "density_per_m2"}},
      {MeasureKind::kLanes,
       {"lane_order", "organized_share", "lane_breaks", "lane_reformations", "longest_organized_s", "organized_at_end"}},
      {MeasureKind::kStartTimes,
       {"premovement_s", "start_delay_s", "moved_early", "never_started", "started_people", "gone_before_start"}},
      {MeasureKind::kRunState,
       {"peak_local_density_per_m2", "peak_local_density_real_per_m2", "time_beyond_measured_s", "largest_overlap_m",
        "duration_s"}},
  };
  return names.at(kind);
}

std::string UnknownStatistic(MeasureKind kind, const std::string& statistic) {
  const std::vector<std::string>& names = StatisticNames(kind);
  if (statistic == "completed" || std::find(names.begin(), names.end(), statistic) != names.end()) return "";
  if (kind == MeasureKind::kWalkingSpeed && statistic.rfind("speed_m_per_s@", 0) == 0 && statistic.size() > 14) return "";
  std::string list;
  for (const std::string& n : names) list += n + ", ";
  return "\"" + statistic + "\" is not a statistic of the measure " + ToString(kind) + "; expected one of " + list +
         "completed" + (kind == MeasureKind::kWalkingSpeed ? " (or speed_m_per_s@GROUP)" : "");
}

std::string MeasureKindNames() {
  std::string s;
  for (const auto& [k, name] : KindNames()) s += (s.empty() ? "" : ", ") + std::string(name);
  return s;
}

bool MeasureSpec::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  const bool needs_area = kind == MeasureKind::kWalkingSpeed || kind == MeasureKind::kFundamentalDiagram ||
                          kind == MeasureKind::kHeadway || kind == MeasureKind::kLanes;
  if (needs_area && !has_area) return fail(ToString(kind) + " needs an area");
  if (has_area && (area.polygon_m.size() < 3 || !(area.Area_m2() > 0.0)))
    return fail("the area must be a polygon of at least 3 points with an area > 0");
  if (kind == MeasureKind::kTravel && (from_line.Length_m() <= 0.0 || to_line.Length_m() <= 0.0))
    return fail("travel needs two lines of length > 0 (from, to)");
  if (kind == MeasureKind::kPassages && line.Length_m() <= 0.0) return fail("passages needs a line of length > 0");
  if (kind == MeasureKind::kLanes && !(Length(direction) > 0.0)) return fail("lanes needs a direction");
  if (!(skip_s >= 0.0 && skip_s <= 1e6)) return fail("skip_s must be in [0, 1e6]");
  if (!(velocity_span_s > 0.0 && velocity_span_s <= 10.0)) return fail("velocity_span_s must be in (0, 10]");
  if (!(lane_half_width_m > 0.0 && lane_half_width_m <= 5.0)) return fail("lane_half_width_m must be in (0, 5]");
  if (!(max_headway_m > 0.0 && max_headway_m <= 100.0)) return fail("max_headway_m must be in (0, 100]");
  if (frame_step < 1 || frame_step > 1000) return fail("frame_step must be in [1, 1000]");
  return true;
}

double FirstCrossing_s(const observe::Track& track, double fps, const observe::Line& line, Vec2 direction,
                       double after_s) {
  for (std::size_t k = 1; k < track.position_m.size(); ++k) {
    if (track.frame[k] != track.frame[k - 1] + 1) continue;
    const Vec2 p = track.position_m[k - 1], q = track.position_m[k];
    if (LengthSquared(direction) > 0.0 && Dot(q - p, direction) <= 0.0) continue;
    const double f = CrossingFraction(p, q, line.a_m, line.b_m);
    if (f < 0.0) continue;
    const double time = (double(track.frame[k - 1]) + f) / fps;
    if (time > after_s) return time;
  }
  return kNaN;
}

Statistics MeasureTrajectories(const observe::Trajectories& trajectories, const MeasureSpec& spec) {
  return Measure(trajectories, spec, {}, nullptr);
}

Statistics MeasureRun(const std::filesystem::path& run_file, const MeasureSpec& spec) {
  const runfile::RunFileReader reader(run_file);
  Statistics out;
  const bool complete = reader.RunValue("status") == "complete";
  if (spec.kind == MeasureKind::kRunState) {
    out["completed"] = {complete ? 1.0 : 0.0};
    if (!complete) return out;
    const analysis::Plausibility p = analysis::ComputePlausibility(run_file);
    out["peak_local_density_per_m2"] = {p.peak_density_per_m2};
    out["peak_local_density_real_per_m2"] = {p.peak_equivalent_density_per_m2};
    out["time_beyond_measured_s"] = {p.time_beyond_measured_s};
    out["largest_overlap_m"] = {p.contacts_available ? p.max_overlap_m : kNaN};
    out["duration_s"] = {reader.Frames().empty() ? 0.0 : double(reader.Frames().back()) / reader.fps()};
    return out;
  }
  observe::Trajectories t = observe::ReadTrajectories(run_file);
  // The run's last frame, whether or not anyone is in it (a run that ends
  // once everyone has left writes a last frame without people): whoever's
  // track ends before it has left.
  const std::vector<std::int64_t> frames = reader.Frames();
  if (!frames.empty()) t.last_frame = std::max<std::int64_t>(t.last_frame, frames.back());
  if (spec.kind == MeasureKind::kStartTimes) {
    out = MeasureStartTimes(t, reader.Events());
    out["completed"] = {complete ? 1.0 : 0.0};
    return out;
  }
  const std::vector<runfile::Wall> walls = reader.Walls();
  // (A run's frames start at 0, so times are the run's own.)
  out = Measure(t, spec, SplitGroups(reader.RunValue("groups")), &walls);
  out["completed"] = {complete ? 1.0 : 0.0};
  return out;
}

}  // namespace crowdrecon::validate
