// AnalyzeRun: reads a run file once, frame by frame (runfile::RunFileReader),
// and builds the series of run_analysis.hpp; then classifies the regime and
// summarises. Its named steps, in order: OpenRun (people and frames) ->
// DesiredDirections -> ChooseMeasurementLine -> FramePass (one pass over the
// frames) -> Flows -> regime -> AvalancheSizes -> Summarize.
#include "crowdrecon/analysis/run_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::analysis {

namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTimeTolerance_s = 1e-6;  // frame times run up to a time step late

bool InRange(double value, double lo, double hi, const char* name, const char* unit, std::string* error) {
  if (value >= lo && value <= hi) return true;
  *error = std::string(name) + " = " + FormatNumber(value) + " " + unit + ", expected [" + FormatNumber(lo) + ", " +
           FormatNumber(hi) + "]";
  return false;
}

// Bounding box of every coordinate pair in a WKT polygon text; enough to place
// a default measurement line without a WKT parser.
bool WktBounds(const std::string& wkt, Vec2* lo, Vec2* hi) {
  std::vector<double> numbers;
  const char* p = wkt.c_str();
  while (*p) {
    if ((*p >= '0' && *p <= '9') || *p == '-' || *p == '+' || *p == '.') {
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end == p) {
        ++p;
        continue;
      }
      numbers.push_back(v);
      p = end;
    } else {
      ++p;
    }
  }
  if (numbers.size() < 2) return false;
  *lo = {numbers[0], numbers[1]};
  *hi = *lo;
  for (std::size_t i = 0; i + 1 < numbers.size(); i += 2) {
    lo->x = std::min(lo->x, numbers[i]);
    lo->y = std::min(lo->y, numbers[i + 1]);
    hi->x = std::max(hi->x, numbers[i]);
    hi->y = std::max(hi->y, numbers[i + 1]);
  }
  return true;
}

// The run's venue, as the run file stores it (run value `venue`), so that the
// analysis does not depend on where the run file is opened. A run without one
// (written before run files stored their venue) or with one that cannot be
// read is a note, not an error: the analysis falls back to definitions that
// need no venue.
struct VenueLookup {
  std::optional<geometry::Venue> venue;
  std::string note;  // why there is none
};

VenueLookup VenueOfRun(const runfile::RunFileReader& run) {
  VenueLookup result;
  const std::string json = run.venue_json();
  if (json.empty()) {
    result.note = "the run file stores no venue (written before run files stored their venue)";
    return result;
  }
  try {
    result.venue = geometry::ParseVenue(json, run.file() + ": run value venue");
  } catch (const std::exception& e) {
    result.note = std::string("the run's venue could not be read: ") + e.what();
  }
  return result;
}

// Linear interpolation between order statistics of sorted values.
double Quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return kNaN;
  const double position = q * static_cast<double>(sorted.size() - 1);
  const std::size_t below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double w = position - static_cast<double>(below);
  return sorted[below] * (1.0 - w) + sorted[above] * w;
}

double MeanFrom(const std::vector<double>& values, std::size_t first) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t k = first; k < values.size(); ++k)
    if (std::isfinite(values[k])) {
      sum += values[k];
      ++count;
    }
  return count > 0 ? sum / static_cast<double>(count) : kNaN;
}

}  // namespace

bool AnalysisOptions::IsValid(std::string* error) const {
  if (!regime.IsValid(error)) return false;
  if (!lanes.IsValid(error)) return false;
  if (!passages.IsValid(error)) return false;
  if (!InRange(stopped_person_speed_m_per_s, 1e-4, 2.0, "stopped_person_speed_m_per_s", "m/s", error)) return false;
  if (!InRange(flow_window_s, 0.01, 600.0, "flow_window_s", "s", error)) return false;
  if (!InRange(load_threshold_n, 0.0, 1e6, "load_threshold_n", "N", error)) return false;
  if (!InRange(load_histogram_bin_n, 0.1, 1e5, "load_histogram_bin_n", "N", error)) return false;
  if (!InRange(load_histogram_max_n, load_histogram_bin_n, 1e6, "load_histogram_max_n", "N", error)) return false;
  if (load_histogram_max_n / load_histogram_bin_n > 10000.0) {
    *error = "load histogram: more than 10000 bins (" + FormatNumber(load_histogram_max_n) + " N / " +
             FormatNumber(load_histogram_bin_n) + " N)";
    return false;
  }
  if (!InRange(avalanche_move_m, 0.0, 100.0, "avalanche_move_m", "m", error)) return false;
  if (line && !(line->length_m() > 0.0)) {
    *error = "measurement line has zero length";
    return false;
  }
  return true;
}

std::vector<MetricSeries::Column> MetricSeries::Columns(std::vector<std::string>* group_names) const {
  std::vector<Column> columns = {
      {"flow_forward_per_m_s", &flow_forward_per_m_s},
      {"flow_backward_per_m_s", &flow_backward_per_m_s},
      {"mean_speed_m_per_s", &mean_speed_m_per_s},
  };
  for (std::size_t g = 0; g < group_mean_speed_m_per_s.size(); ++g)
    columns.push_back({"mean_speed_g" + std::to_string(g) + "_m_per_s", &group_mean_speed_m_per_s[g]});
  if (group_names)
    for (std::size_t g = 0; g < group_mean_speed_m_per_s.size(); ++g) group_names->push_back(columns[3 + g].name);
  columns.push_back({"lane_order", &lane_order});
  columns.push_back({"stopped_fraction", &stopped_fraction});
  columns.push_back({"mean_load_n", &mean_load_n});
  columns.push_back({"max_load_n", &max_load_n});
  columns.push_back({"above_load_fraction", &above_load_fraction});
  return columns;
}

namespace {

// The people and frames of a run (step 1).
struct RunContents {
  std::vector<runfile::Person> people;  // index = person index
  std::vector<std::int64_t> frame;
  std::vector<double> time_s;
  std::uint32_t first_group = 0;  // the lowest group with people
};

// 1. Open: status, periodic box, people (ids 1..N) and frames.
RunContents OpenRun(const runfile::RunFileReader& run, RunAnalysis* out) {
  const std::string& file = run.file();
  out->run_file = file;
  out->status = run.RunValue("status");
  if (out->status != "complete")
    out->notes.push_back("run status \"" + out->status + "\": the analysis covers the frames written so far");
  out->box = run.periodic_box();
  RunContents c;
  c.people = run.People();
  for (const runfile::FrameTime& t : run.FrameTimes()) {
    c.frame.push_back(t.frame);
    c.time_s.push_back(t.time_s);
  }
  if (c.frame.size() < 2)
    throw InputError(file + ": the run has " + std::to_string(c.frame.size()) +
                     " frame(s); the analysis needs at least 2" +
                     (out->status.empty() ? "" : " (status: " + out->status + ")"));
  if (c.people.empty()) throw InputError(file + ": the run has no people");
  out->people = c.people.size();
  out->frames = c.frame.size();
  out->duration_s = c.time_s.back() - c.time_s.front();
  std::uint32_t max_group = 0;
  c.first_group = std::numeric_limits<std::uint32_t>::max();
  for (const runfile::Person& p : c.people) {
    max_group = std::max(max_group, p.group);
    c.first_group = std::min(c.first_group, p.group);
  }
  out->groups = static_cast<std::size_t>(max_group) + 1;
  // A group is a direction of travel, named after its people's target (or
  // "group <k>" if they have different ones).
  out->group_people.assign(out->groups, 0);
  out->group_name.assign(out->groups, "");
  for (const runfile::Person& p : c.people) {
    std::string& name = out->group_name[p.group];
    if (out->group_people[p.group]++ == 0) name = p.target;
    else if (name != p.target) name.clear();
  }
  for (std::size_t g = 0; g < out->groups; ++g)
    if (out->group_name[g].empty()) out->group_name[g] = "group " + std::to_string(g);
  return c;
}

// 2. Desired directions: the venue's fixed-direction targets, else the
//    direction of each group's mean velocity (along the periodic axis when
//    there is exactly one, i.e. its sign, as in the hallway).
void DesiredDirections(const runfile::RunFileReader& run, const RunContents& c, const VenueLookup& venue,
                       RunAnalysis* out) {
  out->group_direction.assign(out->groups, Vec2{1.0, 0.0});
  bool from_venue = false;
  std::string venue_problem = venue.note;
  if (venue.venue) {
    std::vector<std::optional<Vec2>> direction(out->groups);
    from_venue = true;
    for (const runfile::Person& p : c.people) {
      const std::optional<geometry::Target> target = venue.venue->FindTarget(p.target);
      if (!target || target->kind != geometry::Target::Kind::kDirection) {
        venue_problem = "target \"" + p.target + "\" is not a fixed direction of the run's venue";
        from_venue = false;
        break;
      }
      const Vec2 d = Normalized(target->direction);
      if (direction[p.group] && LengthSquared(*direction[p.group] - d) > 1e-12) {
        venue_problem = "group " + std::to_string(p.group) + " has people with different targets";
        from_venue = false;
        break;
      }
      direction[p.group] = d;
    }
    if (from_venue)
      for (std::size_t g = 0; g < out->groups; ++g)
        if (direction[g]) out->group_direction[g] = *direction[g];
  }
  if (from_venue) {
    out->direction_source = "venue targets (the venue stored in the run file)";
    return;
  }
  std::vector<Vec2> sum = run.GroupVelocitySums();
  sum.resize(out->groups);
  const bool one_axis = out->box.x != out->box.y;
  for (std::size_t g = 0; g < out->groups; ++g) {
    Vec2 d = sum[g];
    if (one_axis) d = out->box.x ? Vec2{d.x, 0.0} : Vec2{0.0, d.y};
    if (LengthSquared(d) > 0.0) out->group_direction[g] = Normalized(d);
    else out->notes.push_back("group " + std::to_string(g) + " has no mean velocity; its direction is taken as +x");
  }
  out->direction_source = std::string("group mean velocity") + (one_axis ? " (sign along the periodic axis)" : "") +
                          (venue_problem.empty() ? "" : "; " + venue_problem);
}

// 3. Measurement line: given, the venue's first, or across the middle of the
//    walkable area; `forward` on the side the flow axis points to.
void ChooseMeasurementLine(const AnalysisOptions& options, const VenueLookup& venue, const runfile::RunFileReader& run,
                           Vec2 flow_axis, RunAnalysis* out) {
  if (options.line) {
    out->line = *options.line;
    out->line_source = "given";
    // A line wholly beside the walkable area counts no one (issue 65, P10).
    Vec2 lo, hi;
    const Vec2 a = options.line->a_m, b = options.line->b_m;
    if (WktBounds(run.walkable_wkt(), &lo, &hi) &&
        (std::max(a.x, b.x) < lo.x || std::min(a.x, b.x) > hi.x || std::max(a.y, b.y) < lo.y || std::min(a.y, b.y) > hi.y))
      throw InputError("--line " + FormatNumber(a.x) + "," + FormatNumber(a.y) + "," + FormatNumber(b.x) + "," +
                       FormatNumber(b.y) + ": lies wholly beside the venue's walkable area, (" + FormatNumber(lo.x) +
                       ", " + FormatNumber(lo.y) + ") to (" + FormatNumber(hi.x) + ", " + FormatNumber(hi.y) +
                       ") m; expected a line across it");
  } else if (venue.venue && !venue.venue->measurement_lines.empty()) {
    const geometry::MeasurementLine& l = venue.venue->measurement_lines.front();
    out->line = {l.a, l.b};
    out->line_source = "venue line \"" + l.id + "\"";
  } else {
    Vec2 lo, hi;
    if (!WktBounds(run.walkable_wkt(), &lo, &hi)) {
      lo = {0.0, 0.0};
      hi = {0.0, 0.0};
    }
    if (out->box.x) {
      lo.x = out->box.min_m.x;
      hi.x = out->box.max_m.x;
    }
    if (out->box.y) {
      lo.y = out->box.min_m.y;
      hi.y = out->box.max_m.y;
    }
    const Vec2 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    const Vec2 across = Perp(flow_axis);
    const double reach = std::abs(across.x) * half.x + std::abs(across.y) * half.y;
    out->line = {centre - across * reach, centre + across * reach};
    out->line_source = "middle of the walkable area, across group 0's direction";
    if (!(reach > 0.0)) throw InputError(run.file() + ": no measurement line: the walkable area is empty");
  }
  out->forward = Normalized(Perp(out->line.b_m - out->line.a_m));
  if (Dot(out->forward, flow_axis) < 0.0) out->forward = -out->forward;
  if (std::abs(Dot(out->forward, flow_axis)) < 1e-9)
    out->notes.push_back("the measurement line runs along the flow: forward/backward are arbitrary");
}

// The first frame of the stationary stage (regime.hpp, StationaryStart);
// 0, with a note, when the run is not longer than the transient.
std::size_t FirstStationaryFrame(const std::vector<double>& time_s, const AnalysisOptions& options, RunAnalysis* out) {
  const double start_s = StationaryStart(time_s.front(), time_s.back(), options.regime) - kTimeTolerance_s;
  std::size_t first = time_s.size();
  for (std::size_t k = 0; k < time_s.size(); ++k)
    if (time_s[k] >= start_s) {
      first = k;
      break;
    }
  if (first + 1 >= time_s.size()) {
    out->notes.push_back("the run is not longer than the transient (" + FormatNumber(options.regime.transient_s) +
                         " s): stationary averages use every frame");
    first = 0;
  }
  return first;
}

// 4. One pass over the frames: the per-frame series, line crossings, loads,
//    and each person's cumulative displacement along their desired direction
//    (unwrapped across seams) per frame, for the sizes of avalanches (frames x
//    people floats: a 60 s run of 500 people holds 1.2 MB).
class FramePass {
 public:
  FramePass(const RunContents& c, const AnalysisOptions& options, std::size_t first_stationary, RunAnalysis* out)
      : c_(c), options_(options), first_stationary_(first_stationary), out_(*out), n_people_(c.people.size()),
        n_frames_(c.frame.size()) {
    MetricSeries& s = out_.series;
    s.frame = c.frame;
    s.time_s = c.time_s;
    for (std::vector<double>* series : {&s.flow_forward_per_m_s, &s.flow_backward_per_m_s, &s.mean_speed_m_per_s,
                                        &s.lane_order, &s.stopped_fraction, &s.mean_load_n, &s.max_load_n,
                                        &s.above_load_fraction})
      series->assign(n_frames_, kNaN);
    s.group_mean_speed_m_per_s.assign(out_.groups, std::vector<double>(n_frames_, kNaN));
    crossed_forward.assign(n_frames_, 0);
    crossed_backward.assign(n_frames_, 0);
    passage_times.assign(out_.groups, {});
    group_sign_.assign(out_.groups, 1);
    for (std::size_t g = 0; g < out_.groups; ++g)
      group_sign_[g] = Dot(out_.group_direction[g], out_.forward) < 0.0 ? -1 : 1;
    displacement.assign(n_frames_ * n_people_, 0.0f);
    present_.assign(n_people_, 0);
    was_present_.assign(n_people_, 0);
    position_.resize(n_people_);
    previous_.resize(n_people_);
    velocity_.resize(n_people_);
    load_.assign(n_people_, 0.0);
    cumulative_.assign(n_people_, 0.0);
    above_since_.assign(n_people_, kNaN);
    ever_above_.assign(n_people_, 0);
    out_.max_load_n = -1.0;
  }

  // `validity` is given every frame of people read (the run's validity in
  // the same pass).
  void Run(const runfile::RunFileReader& run, PlausibilityPass* validity) {
    runfile::PersonFrameStream stream = run.PersonFrames(c_.frame.back());
    runfile::PersonFrame rows;
    bool have_rows = stream.Next(&rows);
    // The chest loads, where the run records them (else person_state.load_n).
    out_.chest_loads = run.HasPersonLoads();
    std::optional<runfile::PersonLoadStream> loads;
    std::int64_t load_frame = -1;
    std::vector<runfile::PersonLoad> load_rows;
    bool have_loads = false;
    if (out_.chest_loads) {
      loads.emplace(run.PersonLoads(c_.frame.back()));
      have_loads = loads->Next(&load_frame, &load_rows);
    }
    for (std::size_t k = 0; k < n_frames_; ++k) {
      std::fill(present_.begin(), present_.end(), 0);
      // Rows of frames without a frame_time entry cannot exist (a frame is
      // one transaction), but are skipped rather than trusted.
      while (have_rows && rows.frame < c_.frame[k]) have_rows = stream.Next(&rows);
      if (have_rows && rows.frame == c_.frame[k]) {
        validity->AddPeople(rows);
        for (std::size_t r = 0; r < rows.person.size(); ++r) {
          const std::size_t i = rows.person[r];
          if (i >= n_people_) continue;
          present_[i] = 1;
          position_[i] = rows.position_m[r];
          velocity_[i] = rows.velocity_m_per_s[r];
          load_[i] = out_.chest_loads ? 0.0 : rows.load_n[r];
        }
        have_rows = stream.Next(&rows);
      }
      while (have_loads && load_frame < c_.frame[k]) have_loads = loads->Next(&load_frame, &load_rows);
      if (have_loads && load_frame == c_.frame[k]) {
        for (const runfile::PersonLoad& l : load_rows)
          if (l.person < n_people_ && present_[l.person]) load_[l.person] = std::max(l.chest_n, l.lateral_n);
        have_loads = loads->Next(&load_frame, &load_rows);
      }
      Process(k);
      previous_ = position_;
      was_present_ = present_;
    }
    if (out_.max_load_n < 0.0) out_.max_load_n = 0.0;
    for (char e : ever_above_) out_.people_ever_above_load += e ? 1 : 0;
    for (std::size_t k = 1; k < n_frames_; ++k) {
      out_.crossings_forward += crossed_forward[k];
      out_.crossings_backward += crossed_backward[k];
    }
  }

  std::vector<std::int64_t> crossed_forward, crossed_backward;  // per frame
  // Per group: times of crossings of the line along the group's own desired
  // direction, interpolated within the frame interval.
  std::vector<std::vector<double>> passage_times;
  std::vector<float> displacement;                               // frame * people + person
  std::vector<double> stationary_loads;                          // every person-frame of the stationary stage

 private:
  void Process(std::size_t k) {
    MetricSeries& s = out_.series;
    const double t = c_.time_s[k];
    std::size_t count = 0, stopped = 0, above = 0;
    double speed_sum = 0.0, load_sum = 0.0, load_max = 0.0;
    std::vector<double> group_sum(out_.groups, 0.0);
    std::vector<std::size_t> group_count(out_.groups, 0);
    lane_position_.clear();
    lane_group_.clear();
    for (std::size_t i = 0; i < n_people_; ++i) {
      if (!present_[i]) {
        // Removed people leave the averages; an above-threshold stretch ends.
        above_since_[i] = kNaN;
        continue;
      }
      const std::uint32_t group = c_.people[i].group;
      const Vec2 e = out_.group_direction[group];
      if (k > 0 && was_present_[i]) {
        cumulative_[i] += Dot(out_.box.MinimumImage(position_[i] - previous_[i]), e);
        double fraction = 1.0;
        const int crossing =
            CrossingDirection(out_.line, out_.forward, previous_[i], position_[i], out_.box, &fraction);
        if (crossing > 0) crossed_forward[k] += crossing;
        if (crossing < 0) crossed_backward[k] -= crossing;
        if (crossing * group_sign_[group] > 0)
          passage_times[group].push_back(c_.time_s[k - 1] + fraction * (t - c_.time_s[k - 1]));
      }
      const double along = Dot(velocity_[i], e);
      ++count;
      speed_sum += along;
      group_sum[group] += along;
      ++group_count[group];
      if (Length(velocity_[i]) < options_.stopped_person_speed_m_per_s) ++stopped;
      lane_position_.push_back(position_[i]);
      lane_group_.push_back(group);
      const double load = load_[i];
      load_sum += load;
      load_max = std::max(load_max, load);
      if (load > out_.max_load_n) {
        out_.max_load_n = load;
        out_.max_load_person = static_cast<std::int64_t>(i + 1);
        out_.max_load_time_s = t;
      }
      if (load > options_.load_threshold_n) {
        ++above;
        ever_above_[i] = 1;
        if (std::isnan(above_since_[i])) above_since_[i] = t;
        out_.longest_above_load_s = std::max(out_.longest_above_load_s, t - above_since_[i]);
      } else {
        above_since_[i] = kNaN;
      }
      if (k >= first_stationary_) stationary_loads.push_back(load);
    }
    for (std::size_t i = 0; i < n_people_; ++i) displacement[k * n_people_ + i] = static_cast<float>(cumulative_[i]);
    if (count == 0) return;
    const double people_now = static_cast<double>(count);
    s.mean_speed_m_per_s[k] = speed_sum / people_now;
    for (std::size_t g = 0; g < out_.groups; ++g)
      if (group_count[g] > 0) s.group_mean_speed_m_per_s[g][k] = group_sum[g] / static_cast<double>(group_count[g]);
    s.stopped_fraction[k] = static_cast<double>(stopped) / people_now;
    s.lane_order[k] = LaneOrder(lane_position_, lane_group_, out_.group_direction[c_.first_group], options_.lanes,
                                out_.box).order;
    s.mean_load_n[k] = load_sum / people_now;
    s.max_load_n[k] = load_max;
    s.above_load_fraction[k] = static_cast<double>(above) / people_now;
  }

  const RunContents& c_;
  const AnalysisOptions& options_;
  std::size_t first_stationary_;
  RunAnalysis& out_;
  std::size_t n_people_, n_frames_;
  std::vector<char> present_, was_present_, ever_above_;
  std::vector<Vec2> position_, previous_, velocity_, lane_position_;
  std::vector<std::uint32_t> lane_group_;
  std::vector<double> load_, cumulative_, above_since_;
  std::vector<int> group_sign_;  // +1 if the group walks forward across the line, -1 if backward
};

// 5. Flows: crossings per second per metre of line in a trailing window of
//    flow_window_s (intervals ending inside it), and over the stationary stage.
void Flows(const FramePass& pass, const AnalysisOptions& options, std::size_t first_stationary, RunAnalysis* out) {
  const std::vector<double>& time_s = out->series.time_s;
  const std::size_t n_frames = time_s.size();
  const double line_m = out->line.length_m();
  for (std::size_t k = 1; k < n_frames; ++k) {
    std::size_t j0 = k;
    while (j0 > 1 && time_s[j0 - 1] > time_s[k] - options.flow_window_s + kTimeTolerance_s) --j0;
    std::int64_t fwd = 0, bwd = 0;
    for (std::size_t j = j0; j <= k; ++j) {
      fwd += pass.crossed_forward[j];
      bwd += pass.crossed_backward[j];
    }
    const double window_s = time_s[k] - time_s[j0 - 1];
    out->series.flow_forward_per_m_s[k] = static_cast<double>(fwd) / (window_s * line_m);
    out->series.flow_backward_per_m_s[k] = static_cast<double>(bwd) / (window_s * line_m);
  }
  std::int64_t fwd = 0, bwd = 0;
  for (std::size_t k = first_stationary + 1; k < n_frames; ++k) {
    fwd += pass.crossed_forward[k];
    bwd += pass.crossed_backward[k];
  }
  const double span_s = time_s.back() - time_s[first_stationary];
  out->flow_forward_per_m_s = static_cast<double>(fwd) / (span_s * line_m);
  out->flow_backward_per_m_s = static_cast<double>(bwd) / (span_s * line_m);
}

// 7. Avalanche sizes: people who advanced at least avalanche_move_m.
void AvalancheSizes(const FramePass& pass, std::size_t n_people, const AnalysisOptions& options, RunAnalysis* out) {
  for (Avalanche& a : out->regime.avalanches) {
    int moved = 0;
    for (std::size_t i = 0; i < n_people; ++i) {
      const double advance = static_cast<double>(pass.displacement[a.end_index * n_people + i]) -
                             static_cast<double>(pass.displacement[a.start_index * n_people + i]);
      if (advance >= options.avalanche_move_m) ++moved;
    }
    a.people_moved = moved;
  }
}

// 8. Summary over the stationary stage: speeds, stopped fraction, lane order,
//    avalanches, and the distribution of loads.
void Summarize(const std::vector<double>& speed_for_regime, std::size_t first_stationary,
               std::vector<double> stationary_loads, const AnalysisOptions& options, RunAnalysis* out) {
  const MetricSeries& s = out->series;
  out->mean_speed_m_per_s = MeanFrom(speed_for_regime, first_stationary);
  for (std::size_t g = 0; g < out->groups; ++g)
    out->group_mean_speed_m_per_s.push_back(MeanFrom(s.group_mean_speed_m_per_s[g], first_stationary));
  out->mean_stopped_fraction = MeanFrom(s.stopped_fraction, first_stationary);
  out->mean_lane_order = MeanFrom(s.lane_order, first_stationary);
  out->max_above_load_fraction = 0.0;
  for (double f : s.above_load_fraction)
    if (std::isfinite(f)) out->max_above_load_fraction = std::max(out->max_above_load_fraction, f);
  {
    int count = 0;
    double duration_sum = 0.0, distance_sum = 0.0, people_sum = 0.0, rise_sum = 0.0;
    for (const Avalanche& a : out->regime.avalanches) {
      if (!a.stationary) continue;
      ++count;
      duration_sum += a.duration_s;
      distance_sum += a.distance_m;
      people_sum += a.people_moved;
      rise_sum += a.rise_time_s;
      out->avalanche_max_duration_s = std::max(out->avalanche_max_duration_s, a.duration_s);
    }
    if (count > 0) {
      out->avalanche_mean_duration_s = duration_sum / count;
      out->avalanche_mean_distance_m = distance_sum / count;
      out->avalanche_mean_people = people_sum / count;
      out->avalanche_mean_rise_time_s = rise_sum / count;
    }
  }
  std::sort(stationary_loads.begin(), stationary_loads.end());
  out->load_histogram_bin_n = options.load_histogram_bin_n;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(options.load_histogram_max_n / options.load_histogram_bin_n - 1e-9));
  out->load_histogram.assign(bins + 1, 0);
  double load_sum = 0.0;
  std::size_t above = 0;
  for (double f : stationary_loads) {
    load_sum += f;
    if (f > options.load_threshold_n) ++above;
    const std::size_t bin = f >= options.load_histogram_max_n
                                ? bins
                                : std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, f) / options.load_histogram_bin_n));
    ++out->load_histogram[bin];
  }
  if (!stationary_loads.empty()) {
    const double count = static_cast<double>(stationary_loads.size());
    out->mean_load_n = load_sum / count;
    out->above_load_person_frames = static_cast<double>(above) / count;
    out->load_p50_n = Quantile(stationary_loads, 0.50);
    out->load_p90_n = Quantile(stationary_loads, 0.90);
    out->load_p99_n = Quantile(stationary_loads, 0.99);
  }
}

}  // namespace

RunAnalysis AnalyzeRun(const fs::path& run_file, const AnalysisOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("analysis options: " + error);
  // RunFileReader names missing, foreign and non-run files.
  const runfile::RunFileReader run(run_file);
  RunAnalysis out;
  const RunContents contents = OpenRun(run, &out);
  const VenueLookup venue = VenueOfRun(run);
  DesiredDirections(run, contents, venue, &out);
  // Lanes run along, and "forward" points along, the direction of the lowest
  // group with people (group 0, the main flow, in every scenario).
  ChooseMeasurementLine(options, venue, run, out.group_direction[contents.first_group], &out);
  const std::size_t first_stationary = FirstStationaryFrame(contents.time_s, options, &out);
  PlausibilityPass validity(run);  // issue 39: states a human crowd can reach
  FramePass pass(contents, options, first_stationary, &out);
  pass.Run(run, &validity);
  Flows(pass, options, first_stationary, &out);
  // 6. Regime. The mean speed of a frame with nobody in it is taken as 0 (an
  //    empty corridor has no flow).
  std::vector<double> speed_for_regime = out.series.mean_speed_m_per_s;
  for (double& v : speed_for_regime)
    if (std::isnan(v)) v = 0.0;
  std::vector<DirectionSeries> directions;
  for (std::size_t g = 0; g < out.groups; ++g)
    if (out.group_people[g] > 0)
      directions.push_back({out.group_name[g], out.group_people[g], out.series.group_mean_speed_m_per_s[g]});
  out.regime = ClassifyByDirection(contents.time_s, speed_for_regime, directions, out.series.lane_order,
                                   options.regime);
  out.regime_single_release = ClassifyByDirection(contents.time_s, speed_for_regime, directions, out.series.lane_order,
                                                  SingleReleaseReading(options.regime));
  AvalancheSizes(pass, contents.people.size(), options, &out);
  // 9. Passages per direction over the stationary stage.
  for (std::size_t g = 0; g < out.groups; ++g)
    out.passages.push_back(AnalyzePassages(std::move(pass.passage_times[g]), contents.time_s[first_stationary],
                                           contents.time_s.back(), options.passages));
  Summarize(speed_for_regime, first_stationary, std::move(pass.stationary_loads), options, &out);
  out.plausibility = validity.Finish(run);
  return out;
}

}  // namespace crowdrecon::analysis
