// AnalyzeRun: reads a run file once, frame by frame, and builds the series of
// run_analysis.hpp; then classifies the regime and summarises. The order of
// the stages: open -> people and frames -> desired directions -> measurement
// line -> pass over the frames -> flows -> regime -> avalanche sizes -> summary.
#include "crowdrecon/analysis/run_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/scenario/run_file.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/sqlite.hpp"

namespace crowdrecon::analysis {

namespace {

using sqlite::Database;
using sqlite::Statement;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTimeTolerance_s = 1e-6;  // frame times run up to a time step late

struct Person {
  std::uint32_t group = 0;
  std::string target;
};

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

// The run's venue, found through the scenario it records: run value `scenario`
// names the venue relative to the scenario file, whose path (run value
// `scenario_file`) is as given to `crowdrecon simulate`, i.e. relative to the
// directory it ran in. That directory is unknown here, so the candidates are
// the current directory, the project's data directory and the run file's
// directory. A venue that cannot be found is a note, not an error: the
// analysis falls back to definitions that need no venue.
struct VenueLookup {
  std::optional<geometry::Venue> venue;
  std::string file;
  std::string note;  // why there is none
};

VenueLookup FindVenue(const scenario::RunFileReader& run, const fs::path& run_file) {
  VenueLookup result;
  std::string venue_text;
  try {
    const nlohmann::json j = nlohmann::json::parse(run.RunValue("scenario"));
    if (j.is_object() && j.contains("venue") && j["venue"].is_string()) venue_text = j["venue"].get<std::string>();
  } catch (const std::exception&) {
    // not JSON: no venue
  }
  if (venue_text.empty()) {
    result.note = "the run's scenario names no venue";
    return result;
  }
  const fs::path scenario_file = run.RunValue("scenario_file");
  std::vector<fs::path> scenario_dirs;
  if (scenario_file.is_absolute()) {
    scenario_dirs.push_back(scenario_file.parent_path());
  } else {
    scenario_dirs.push_back(fs::current_path() / scenario_file.parent_path());
    scenario_dirs.push_back(scenario::DataDirectory() / scenario_file.parent_path());
    scenario_dirs.push_back(run_file.parent_path() / scenario_file.parent_path());
  }
  const fs::path venue_path = venue_text;
  std::vector<fs::path> candidates;
  if (venue_path.is_absolute()) candidates.push_back(venue_path);
  else
    for (const fs::path& dir : scenario_dirs) candidates.push_back((dir / venue_path).lexically_normal());
  for (const fs::path& candidate : candidates) {
    std::error_code ec;
    if (!fs::is_regular_file(candidate, ec)) continue;
    try {
      result.venue = geometry::LoadVenue(candidate);
      result.file = candidate.string();
    } catch (const InputError& e) {
      result.note = std::string("the run's venue could not be read: ") + e.what();
    }
    return result;
  }
  result.note = "the run's venue \"" + venue_text + "\" was not found (looked in " + candidates.front().string() +
                (candidates.size() > 1 ? " and " + std::to_string(candidates.size() - 1) + " other place(s)" : "") + ")";
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

RunAnalysis AnalyzeRun(const fs::path& run_file, const AnalysisOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("analysis options: " + error);
  const std::string file = run_file.string();

  // 1. Open (RunFileReader names missing, foreign and non-run files).
  std::optional<scenario::RunFileReader> reader;
  reader.emplace(run_file);
  const scenario::RunFileReader& run = *reader;
  RunAnalysis out;
  out.run_file = file;
  out.status = run.RunValue("status");
  if (out.status != "complete")
    out.notes.push_back("run status \"" + out.status + "\": the analysis covers the frames written so far");
  out.box = ParsePeriodicity(run.RunValue("periodic_box"), file);
  Database db(file, SQLITE_OPEN_READONLY);

  // 2. People (ids 1..N) and frames.
  std::vector<Person> people;
  {
    Statement q(db, "SELECT id, grp, target FROM person ORDER BY id");
    q.Describe("person", {0});
    while (q.Next()) {
      const std::int64_t id = q.Integer(0, 1, scenario::run_limits::kPersonId);
      if (static_cast<std::size_t>(id) > people.size()) people.resize(static_cast<std::size_t>(id));
      people[static_cast<std::size_t>(id - 1)] = {static_cast<std::uint32_t>(q.Integer(1, 0, scenario::run_limits::kGroup)),
                                                  q.Text(2)};
    }
  }
  const std::size_t n_people = people.size();
  std::vector<std::int64_t> frame_numbers;
  std::vector<double> time_s;
  {
    Statement q(db, "SELECT frame, time_s FROM frame_time ORDER BY frame");
    q.Describe("frame_time", {0});
    while (q.Next()) {
      frame_numbers.push_back(q.Integer(0, 0, scenario::run_limits::kFrame));
      time_s.push_back(q.Real(1, 0.0, scenario::run_limits::kTime_s));
    }
  }
  const std::size_t n_frames = frame_numbers.size();
  if (n_frames < 2)
    throw InputError(file + ": the run has " + std::to_string(n_frames) +
                     " frame(s); the analysis needs at least 2" +
                     (out.status.empty() ? "" : " (status: " + out.status + ")"));
  if (n_people == 0) throw InputError(file + ": the run has no people");
  out.people = n_people;
  out.frames = n_frames;
  out.duration_s = time_s.back() - time_s.front();
  std::uint32_t max_group = 0;
  for (const Person& p : people) max_group = std::max(max_group, p.group);
  out.groups = static_cast<std::size_t>(max_group) + 1;

  // 3. Desired directions: the venue's fixed-direction targets, else the
  //    direction of each group's mean velocity (along the periodic axis when
  //    there is exactly one, i.e. its sign, as in the hallway).
  const VenueLookup venue = FindVenue(run, run_file);
  out.group_direction.assign(out.groups, Vec2{1.0, 0.0});
  bool from_venue = false;
  std::string venue_problem = venue.note;
  if (venue.venue) {
    std::vector<std::optional<Vec2>> direction(out.groups);
    from_venue = true;
    for (const Person& p : people) {
      const std::optional<geometry::Target> target = venue.venue->FindTarget(p.target);
      if (!target || target->kind != geometry::Target::Kind::kDirection) {
        venue_problem = "target \"" + p.target + "\" is not a fixed direction of " + venue.file;
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
      for (std::size_t g = 0; g < out.groups; ++g)
        if (direction[g]) out.group_direction[g] = *direction[g];
  }
  if (from_venue) {
    out.direction_source = "venue targets (" + venue.file + ")";
  } else {
    std::vector<Vec2> sum(out.groups);
    Statement q(db,
                "SELECT p.grp, SUM(s.vel_x), SUM(s.vel_y) FROM person_state s JOIN person p ON p.id = s.id "
                "GROUP BY p.grp");
    while (q.Next()) {
      const std::int64_t g = q.Int(0);
      if (g >= 0 && static_cast<std::size_t>(g) < out.groups) sum[static_cast<std::size_t>(g)] = {q.Double(1), q.Double(2)};
    }
    const bool one_axis = out.box.x != out.box.y;
    for (std::size_t g = 0; g < out.groups; ++g) {
      Vec2 d = sum[g];
      if (one_axis) d = out.box.x ? Vec2{d.x, 0.0} : Vec2{0.0, d.y};
      if (LengthSquared(d) > 0.0) out.group_direction[g] = Normalized(d);
      else out.notes.push_back("group " + std::to_string(g) + " has no mean velocity; its direction is taken as +x");
    }
    out.direction_source = std::string("group mean velocity") + (one_axis ? " (sign along the periodic axis)" : "") +
                           (venue_problem.empty() ? "" : "; " + venue_problem);
  }
  // Lanes run along, and "forward" points along, the direction of the lowest
  // group with people (group 0, the main flow, in every scenario).
  std::uint32_t first_group = max_group;
  for (const Person& p : people) first_group = std::min(first_group, p.group);
  const Vec2 flow_axis = out.group_direction[first_group];

  // 4. Measurement line: given, the venue's first, or across the middle of
  //    the walkable area.
  if (options.line) {
    out.line = *options.line;
    out.line_source = "given";
  } else if (venue.venue && !venue.venue->measurement_lines.empty()) {
    const geometry::MeasurementLine& l = venue.venue->measurement_lines.front();
    out.line = {l.a, l.b};
    out.line_source = "venue line \"" + l.id + "\"";
  } else {
    Vec2 lo, hi;
    if (!WktBounds(run.walkable_wkt(), &lo, &hi)) {
      lo = {0.0, 0.0};
      hi = {0.0, 0.0};
    }
    if (out.box.x) {
      lo.x = out.box.min_m.x;
      hi.x = out.box.max_m.x;
    }
    if (out.box.y) {
      lo.y = out.box.min_m.y;
      hi.y = out.box.max_m.y;
    }
    const Vec2 centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
    const Vec2 across = Perp(flow_axis);
    const double reach = std::abs(across.x) * half.x + std::abs(across.y) * half.y;
    out.line = {centre - across * reach, centre + across * reach};
    out.line_source = "middle of the walkable area, across group 0's direction";
    if (!(reach > 0.0)) throw InputError(file + ": no measurement line: the walkable area is empty");
  }
  out.forward = Normalized(Perp(out.line.b_m - out.line.a_m));
  if (Dot(out.forward, flow_axis) < 0.0) out.forward = -out.forward;
  if (std::abs(Dot(out.forward, flow_axis)) < 1e-9)
    out.notes.push_back("the measurement line runs along the flow: forward/backward are arbitrary");

  // 5. One pass over the frames.
  MetricSeries& s = out.series;
  s.frame = frame_numbers;
  s.time_s = time_s;
  s.flow_forward_per_m_s.assign(n_frames, kNaN);
  s.flow_backward_per_m_s.assign(n_frames, kNaN);
  s.mean_speed_m_per_s.assign(n_frames, kNaN);
  s.group_mean_speed_m_per_s.assign(out.groups, std::vector<double>(n_frames, kNaN));
  s.lane_order.assign(n_frames, kNaN);
  s.stopped_fraction.assign(n_frames, kNaN);
  s.mean_load_n.assign(n_frames, kNaN);
  s.max_load_n.assign(n_frames, kNaN);
  s.above_load_fraction.assign(n_frames, kNaN);
  std::vector<std::int64_t> crossed_forward(n_frames, 0), crossed_backward(n_frames, 0);
  // Cumulative displacement of each person along their desired direction
  // (unwrapped across seams), per frame, for the sizes of avalanches: frames x
  // people floats (a 60 s run of 500 people holds 1.2 MB).
  std::vector<float> displacement(n_frames * n_people, 0.0f);

  const double stationary_start_s = time_s.front() + options.regime.transient_s - kTimeTolerance_s;
  std::size_t first_stationary = n_frames;
  for (std::size_t k = 0; k < n_frames; ++k)
    if (time_s[k] >= stationary_start_s) {
      first_stationary = k;
      break;
    }
  if (first_stationary + 1 >= n_frames) {
    out.notes.push_back("the run is not longer than the transient (" + FormatNumber(options.regime.transient_s) +
                        " s): stationary averages use every frame");
    first_stationary = 0;
  }

  std::vector<char> present(n_people, 0), was_present(n_people, 0);
  std::vector<Vec2> position(n_people), previous(n_people), velocity(n_people);
  std::vector<double> load(n_people, 0.0), cumulative(n_people, 0.0);
  std::vector<double> above_since(n_people, kNaN);
  std::vector<double> stationary_loads;
  std::vector<char> ever_above(n_people, 0);
  out.max_load_n = -1.0;

  auto process_frame = [&](std::size_t k) {
    const double t = time_s[k];
    std::size_t count = 0, stopped = 0, above = 0;
    double speed_sum = 0.0, load_sum = 0.0, load_max = 0.0;
    std::vector<double> group_sum(out.groups, 0.0);
    std::vector<std::size_t> group_count(out.groups, 0);
    std::vector<Vec2> lane_position;
    std::vector<std::uint32_t> lane_group;
    for (std::size_t i = 0; i < n_people; ++i) {
      if (!present[i]) {
        // Removed people leave the averages; an above-threshold stretch ends.
        above_since[i] = kNaN;
        continue;
      }
      const Vec2 e = out.group_direction[people[i].group];
      if (k > 0 && was_present[i]) {
        cumulative[i] += Dot(out.box.MinimumImage(position[i] - previous[i]), e);
        const int crossing = CrossingDirection(out.line, out.forward, previous[i], position[i], out.box);
        if (crossing > 0) crossed_forward[k] += crossing;
        if (crossing < 0) crossed_backward[k] -= crossing;
      }
      const double along = Dot(velocity[i], e);
      ++count;
      speed_sum += along;
      group_sum[people[i].group] += along;
      ++group_count[people[i].group];
      if (Length(velocity[i]) < options.stopped_person_speed_m_per_s) ++stopped;
      lane_position.push_back(position[i]);
      lane_group.push_back(people[i].group);
      load_sum += load[i];
      load_max = std::max(load_max, load[i]);
      if (load[i] > out.max_load_n) {
        out.max_load_n = load[i];
        out.max_load_person = static_cast<std::int64_t>(i + 1);
        out.max_load_time_s = t;
      }
      if (load[i] > options.load_threshold_n) {
        ++above;
        ever_above[i] = 1;
        if (std::isnan(above_since[i])) above_since[i] = t;
        out.longest_above_load_s = std::max(out.longest_above_load_s, t - above_since[i]);
      } else {
        above_since[i] = kNaN;
      }
      if (k >= first_stationary) stationary_loads.push_back(load[i]);
    }
    for (std::size_t i = 0; i < n_people; ++i)
      displacement[k * n_people + i] = static_cast<float>(cumulative[i]);
    if (count == 0) return;
    const double people_now = static_cast<double>(count);
    s.mean_speed_m_per_s[k] = speed_sum / people_now;
    for (std::size_t g = 0; g < out.groups; ++g)
      if (group_count[g] > 0) s.group_mean_speed_m_per_s[g][k] = group_sum[g] / static_cast<double>(group_count[g]);
    s.stopped_fraction[k] = static_cast<double>(stopped) / people_now;
    s.lane_order[k] = LaneOrder(lane_position, lane_group, flow_axis, options.lanes, out.box).order;
    s.mean_load_n[k] = load_sum / people_now;
    s.max_load_n[k] = load_max;
    s.above_load_fraction[k] = static_cast<double>(above) / people_now;
  };

  {
    Statement q(db,
                "SELECT t.frame AS frame, t.id AS id, t.pos_x AS pos_x, t.pos_y AS pos_y, "
                "s.vel_x AS \"person_state.vel_x\", s.vel_y AS \"person_state.vel_y\", "
                "s.load_n AS \"person_state.load_n\" FROM trajectory_data t "
                "JOIN person_state s ON s.frame = t.frame AND s.id = t.id WHERE t.frame <= ?1 "
                "ORDER BY t.frame, t.id");
    q.Bind(1, frame_numbers.back()).Describe("trajectory_data", {0, 1});
    using namespace scenario::run_limits;
    std::size_t k = 0;  // index of the frame being collected
    bool have_row = q.Next();
    while (k < n_frames) {
      std::fill(present.begin(), present.end(), 0);
      // Rows of frames without a frame_time entry cannot exist (a frame is one
      // transaction), but are skipped rather than trusted.
      while (have_row && q.Int(0) < frame_numbers[k]) have_row = q.Next();
      while (have_row && q.Int(0) == frame_numbers[k]) {
        const std::int64_t id = q.Int(1);
        if (id >= 1 && static_cast<std::size_t>(id) <= n_people) {
          const std::size_t i = static_cast<std::size_t>(id - 1);
          present[i] = 1;
          position[i] = {q.Real(2, -kCoordinate_m, kCoordinate_m), q.Real(3, -kCoordinate_m, kCoordinate_m)};
          velocity[i] = {q.Real(4, -kSpeed_m_per_s, kSpeed_m_per_s), q.Real(5, -kSpeed_m_per_s, kSpeed_m_per_s)};
          load[i] = q.Real(6, 0.0, kForce_n);
        }
        have_row = q.Next();
      }
      process_frame(k);
      previous = position;
      was_present = present;
      ++k;
    }
  }
  if (out.max_load_n < 0.0) out.max_load_n = 0.0;
  for (char e : ever_above) out.people_ever_above_load += e ? 1 : 0;
  for (std::size_t k = 1; k < n_frames; ++k) {
    out.crossings_forward += crossed_forward[k];
    out.crossings_backward += crossed_backward[k];
  }

  // 6. Flows: crossings per second per metre of line in a trailing window of
  //    flow_window_s (intervals ending inside it), and over the stationary stage.
  const double line_m = out.line.length_m();
  for (std::size_t k = 1; k < n_frames; ++k) {
    std::size_t j0 = k;
    while (j0 > 1 && time_s[j0 - 1] > time_s[k] - options.flow_window_s + kTimeTolerance_s) --j0;
    std::int64_t fwd = 0, bwd = 0;
    for (std::size_t j = j0; j <= k; ++j) {
      fwd += crossed_forward[j];
      bwd += crossed_backward[j];
    }
    const double window_s = time_s[k] - time_s[j0 - 1];
    s.flow_forward_per_m_s[k] = static_cast<double>(fwd) / (window_s * line_m);
    s.flow_backward_per_m_s[k] = static_cast<double>(bwd) / (window_s * line_m);
  }
  {
    std::int64_t fwd = 0, bwd = 0;
    for (std::size_t k = first_stationary + 1; k < n_frames; ++k) {
      fwd += crossed_forward[k];
      bwd += crossed_backward[k];
    }
    const double span_s = time_s.back() - time_s[first_stationary];
    out.flow_forward_per_m_s = static_cast<double>(fwd) / (span_s * line_m);
    out.flow_backward_per_m_s = static_cast<double>(bwd) / (span_s * line_m);
  }

  // 7. Regime. The mean speed of a frame with nobody in it is taken as 0 (an
  //    empty corridor has no flow).
  std::vector<double> speed_for_regime = s.mean_speed_m_per_s;
  for (double& v : speed_for_regime)
    if (std::isnan(v)) v = 0.0;
  out.regime = ClassifyRegime(time_s, speed_for_regime, s.lane_order, options.regime);

  // 8. Avalanche sizes: people who advanced at least avalanche_move_m.
  for (Avalanche& a : out.regime.avalanches) {
    int moved = 0;
    for (std::size_t i = 0; i < n_people; ++i) {
      const double advance = static_cast<double>(displacement[a.end_index * n_people + i]) -
                             static_cast<double>(displacement[a.start_index * n_people + i]);
      if (advance >= options.avalanche_move_m) ++moved;
    }
    a.people_moved = moved;
  }

  // 9. Summary over the stationary stage.
  out.mean_speed_m_per_s = MeanFrom(speed_for_regime, first_stationary);
  for (std::size_t g = 0; g < out.groups; ++g)
    out.group_mean_speed_m_per_s.push_back(MeanFrom(s.group_mean_speed_m_per_s[g], first_stationary));
  out.mean_stopped_fraction = MeanFrom(s.stopped_fraction, first_stationary);
  out.mean_lane_order = MeanFrom(s.lane_order, first_stationary);
  out.max_above_load_fraction = 0.0;
  for (double f : s.above_load_fraction)
    if (std::isfinite(f)) out.max_above_load_fraction = std::max(out.max_above_load_fraction, f);
  {
    int count = 0;
    double duration_sum = 0.0, distance_sum = 0.0, people_sum = 0.0;
    for (const Avalanche& a : out.regime.avalanches) {
      if (!a.stationary) continue;
      ++count;
      duration_sum += a.duration_s;
      distance_sum += a.distance_m;
      people_sum += a.people_moved;
      out.avalanche_max_duration_s = std::max(out.avalanche_max_duration_s, a.duration_s);
    }
    if (count > 0) {
      out.avalanche_mean_duration_s = duration_sum / count;
      out.avalanche_mean_distance_m = distance_sum / count;
      out.avalanche_mean_people = people_sum / count;
    }
  }
  std::sort(stationary_loads.begin(), stationary_loads.end());
  out.load_histogram_bin_n = options.load_histogram_bin_n;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(options.load_histogram_max_n / options.load_histogram_bin_n - 1e-9));
  out.load_histogram.assign(bins + 1, 0);
  double load_sum = 0.0;
  std::size_t above = 0;
  for (double f : stationary_loads) {
    load_sum += f;
    if (f > options.load_threshold_n) ++above;
    const std::size_t bin = f >= options.load_histogram_max_n
                                ? bins
                                : std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, f) / options.load_histogram_bin_n));
    ++out.load_histogram[bin];
  }
  if (!stationary_loads.empty()) {
    const double count = static_cast<double>(stationary_loads.size());
    out.mean_load_n = load_sum / count;
    out.above_load_person_frames = static_cast<double>(above) / count;
    out.load_p50_n = Quantile(stationary_loads, 0.50);
    out.load_p90_n = Quantile(stationary_loads, 0.90);
    out.load_p99_n = Quantile(stationary_loads, 0.99);
  }
  return out;
}

}  // namespace crowdrecon::analysis
