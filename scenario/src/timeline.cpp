#include "crowdrecon/scenario/timeline.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::scenario {

namespace {

constexpr double kMaxTime_s = 1e6;     // as run.duration_s
constexpr double kMaxRate_per_s = 1e3;  // persons per second at one entry

// The parameters a timed event may change: the numbers of the parameter
// table that a run can take up mid-way, and the desired speed. Per group only
// those the engine keeps per group (Gamma, lambda) and the desired speed,
// which is each person's own.
bool ChangeableParameter(const std::string& name) {
  if (name == "desired_speed_m_per_s") return true;
  const engine::ParameterInfo* info = engine::FindModelParameter(name);
  // (The step's settings are chosen once for the run: Simulation::SetParameters.)
  return info && info->kind == engine::ParameterInfo::Kind::kNumber && name != "time_step_s" &&
         name != "time_step_safety" && name != "adaptive_max_safety" && name != "adaptive_reference_speed_m_per_s";
}

bool GroupParameter(const std::string& name) {
  return name == "back_force_gamma" || name == "torsion_stiffness_lambda" || name == "desired_speed_m_per_s";
}

std::filesystem::path Resolve(const std::filesystem::path& base, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : (base / p).lexically_normal();
}

void CheckPoints(const std::vector<std::pair<double, double>>& points, const std::string& where) {
  if (points.empty()) throw InputError(where + ": an empty schedule; expected at least one point [time_s, rate_per_s]");
  for (std::size_t k = 1; k < points.size(); ++k)
    if (!(points[k].first > points[k - 1].first))
      throw InputError(where + ": times must increase: point " + std::to_string(k) + " at " +
                       FormatNumber(points[k].first) + " s follows " + FormatNumber(points[k - 1].first) + " s");
}

// `every_scale`: the timeline's "rate_scale", which multiplies every inflow's
// schedule together with the inflow's own (nullptr where absent).
RateSchedule ReadRate(const JsonReader& inflow, const std::string& id, const std::filesystem::path& base_dir,
                      const JsonReader* every_scale) {
  RateSchedule rate;
  const bool inline_rate = inflow.Has("rate_per_s"), csv = inflow.Has("rate_csv");
  if (inline_rate == csv) inflow.Fail("give exactly one of \"rate_per_s\" (a number or [[time_s, rate], ...]) and \"rate_csv\"");
  if (csv) {
    const JsonReader file = inflow.At("rate_csv");
    try {
      rate = ReadRateCsv(Resolve(base_dir, file.AsString()));
    } catch (const InputError& e) {
      file.Fail(std::string("cannot use the rate CSV: ") + e.what());
    }
  } else {
    const JsonReader r = inflow.At("rate_per_s");
    if (r.IsNumber()) {
      rate.points = {{0.0, r.AsNumber(0.0, kMaxRate_per_s)}};
    } else {
      if (!r.IsArray() || r.Size() == 0)
        r.Fail("expected a rate in persons/s (0.." + FormatNumber(kMaxRate_per_s) +
               ") or a non-empty list of points [time_s, rate_per_s]");
      for (std::size_t k = 0; k < r.Size(); ++k) {
        const JsonReader point = r.Element(k);
        if (!point.IsArray() || point.Size() != 2) point.Fail("expected a point [time_s, rate_per_s]");
        rate.points.emplace_back(point.Element(0).AsNumber(0.0, kMaxTime_s), point.Element(1).AsNumber(0.0, kMaxRate_per_s));
      }
      CheckPoints(rate.points, r.Where());
    }
  }
  rate.linear = inflow.Choice("interpolation", "step", {"step", "linear"}) == "linear";
  const auto own_scale = inflow.Find("rate_scale");
  if (own_scale || every_scale) {
    const double k = (own_scale ? own_scale->AsNumber(0.0, 10.0) : 1.0) * (every_scale ? every_scale->AsNumber(0.0, 10.0) : 1.0);
    const JsonReader& blamed = own_scale ? *own_scale : *every_scale;
    for (auto& point : rate.points) {
      const double unscaled = point.second;
      point.second *= k;
      if (point.second > kMaxRate_per_s)
        blamed.Fail("scales inflow \"" + id + "\"'s rate " + FormatNumber(unscaled) + " persons/s at " +
                    FormatNumber(point.first) + " s beyond " + FormatNumber(kMaxRate_per_s) + " persons/s" +
                    (own_scale && every_scale ? " (with the timeline's rate_scale)" : ""));
    }
  }
  if (auto cap = inflow.Find("max_rate_per_s")) rate.Cap(cap->AsNumber(0.0, kMaxRate_per_s));
  rate.Prepare();
  return rate;
}

}  // namespace

double RateSchedule::RateAt(double t) const {
  if (points.empty() || t < points.front().first) return 0.0;
  const auto next = std::upper_bound(points.begin(), points.end(), t,
                                     [](double x, const std::pair<double, double>& p) { return x < p.first; });
  if (next == points.end()) return points.back().second;
  const auto& [t0, r0] = *(next - 1);
  if (!linear) return r0;
  const auto& [t1, r1] = *next;
  return r0 + (r1 - r0) * (t - t0) / (t1 - t0);
}

void RateSchedule::Cap(double cap) {
  std::vector<std::pair<double, double>> capped;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (linear && k > 0) {  // where a linear piece crosses the cap, a point at the crossing keeps it exact
      const auto& [t0, r0] = points[k - 1];
      const auto& [t1, r1] = points[k];
      if ((r0 < cap && r1 > cap) || (r0 > cap && r1 < cap)) {
        const double tc = t0 + (cap - r0) * (t1 - t0) / (r1 - r0);
        if (tc > t0 && tc < t1) capped.emplace_back(tc, cap);
      }
    }
    capped.emplace_back(points[k].first, std::min(points[k].second, cap));
  }
  points = std::move(capped);
  Prepare();
}

void RateSchedule::Prepare() {
  prefix.assign(points.size(), 0.0);
  for (std::size_t k = 1; k < points.size(); ++k) {
    const auto& [t0, r0] = points[k - 1];
    const auto& [t1, r1] = points[k];
    prefix[k] = prefix[k - 1] + (linear ? 0.5 * (r0 + r1) : r0) * (t1 - t0);
  }
}

double RateSchedule::Cumulative(double t) const {
  if (points.empty() || !(t > points.front().first)) return 0.0;
  if (prefix.size() != points.size()) {  // not prepared: the same sum, piece by piece
    RateSchedule copy = *this;
    copy.Prepare();
    return copy.Cumulative(t);
  }
  const auto next = std::upper_bound(points.begin(), points.end(), t,
                                     [](double x, const std::pair<double, double>& p) { return x < p.first; });
  const std::size_t k = static_cast<std::size_t>(next - points.begin()) - 1;  // last point at or before t
  const auto& [tk, rk] = points[k];
  const double piece = linear ? 0.5 * (rk + RateAt(t)) * (t - tk) : rk * (t - tk);
  return prefix[k] + piece;
}

double RateSchedule::Integral(double a, double b) const {
  if (!(b > a)) return 0.0;
  return Cumulative(b) - Cumulative(a);
}

double RateSchedule::TimeOfCumulative(double count) const {
  if (points.empty()) return std::numeric_limits<double>::infinity();
  if (prefix.size() != points.size()) {  // not prepared: as Cumulative
    RateSchedule copy = *this;
    copy.Prepare();
    return copy.TimeOfCumulative(count);
  }
  if (!(count > 0.0)) return points.front().first;
  // The first point by which the integral has reached `count`, if any.
  const std::size_t k = static_cast<std::size_t>(std::lower_bound(prefix.begin(), prefix.end(), count) - prefix.begin());
  if (k == points.size()) {  // after the last point the rate stays at its last value
    const auto& [t_last, r_last] = points.back();
    if (!(r_last > 0.0)) return std::numeric_limits<double>::infinity();
    return t_last + (count - prefix.back()) / r_last;
  }
  // Within the piece [k - 1, k] (k >= 1: prefix[0] = 0 < count).
  const auto& [t0, r0] = points[k - 1];
  const auto& [t1, r1] = points[k];
  const double need = count - prefix[k - 1];
  double s = 0.0;
  if (!linear || r1 == r0) {
    s = need / r0;  // r0 > 0: the piece adds to the integral
  } else {
    // r0 s + a s^2 = need, a = (r1 - r0) / (2 (t1 - t0)); the root in a
    // form without cancellation.
    const double a = 0.5 * (r1 - r0) / (t1 - t0);
    s = 2.0 * need / (r0 + std::sqrt(std::max(0.0, r0 * r0 + 4.0 * a * need)));
  }
  return std::min(t0 + s, t1);
}

std::size_t ArrivalsDue(const RateSchedule& rate, double t_s) {
  return static_cast<std::size_t>(std::floor(rate.Integral(0.0, t_s) + 1e-9));  // (nothing is due before t = 0)
}

double ArrivalDueTime(const RateSchedule& rate, std::size_t k) {
  return std::max(0.0, rate.TimeOfCumulative(rate.Cumulative(0.0) + static_cast<double>(k)));
}

RateSchedule ReadRateCsv(const std::filesystem::path& file) {
  std::istringstream in(ReadInputFile(file, "rate CSV"));
  std::string line;
  RateSchedule rate;
  std::size_t number = 0;
  const std::string name = file.string();
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (number == 1 || (rate.points.empty() && line.find_first_of("abcdefghijklmnopqrstuvwxyz") != std::string::npos)) {
      if (line != "time_s,rate_per_s")
        throw InputError(name + ":" + std::to_string(number) + ": header \"" + line +
                         "\"; expected \"time_s,rate_per_s\"");
      continue;
    }
    const std::size_t comma = line.find(',');
    const auto number_at = [&](const std::string& text, const char* what, double max) {
      std::size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      while (used < text.size() && (text[used] == ' ' || text[used] == '\t')) ++used;
      if (text.empty() || used != text.size() || !std::isfinite(value) || value < 0.0 || value > max)
        throw InputError(name + ":" + std::to_string(number) + ": " + what + " \"" + text + "\"; expected a number in [0, " +
                         FormatNumber(max) + "]");
      return value;
    };
    if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos)
      throw InputError(name + ":" + std::to_string(number) + ": \"" + line + "\"; expected two values: time_s,rate_per_s");
    const double t = number_at(line.substr(0, comma), "time", kMaxTime_s);
    const double r = number_at(line.substr(comma + 1), "rate", kMaxRate_per_s);
    if (!rate.points.empty() && !(t > rate.points.back().first))
      throw InputError(name + ":" + std::to_string(number) + ": time " + FormatNumber(t) +
                       " s does not follow the previous row's " + FormatNumber(rate.points.back().first) +
                       " s; expected increasing times");
    if (rate.points.size() >= 1000000) throw InputError(name + ":" + std::to_string(number) + ": more than 1,000,000 rows");
    rate.points.emplace_back(t, r);
  }
  if (rate.points.empty()) throw InputError(name + ": no rows; expected a header time_s,rate_per_s and at least one row");
  return rate;
}

TimelineSpec ReadTimeline(const JsonReader& reader, const geometry::Venue& venue, const std::filesystem::path& base_dir,
                          const std::string& main_target, const std::string& counter_target) {
  if (!reader.IsObject()) reader.Fail("expected a timeline object {\"inflows\": [...], \"events\": [...], ...}");
  TimelineSpec t;
  t.enabled = true;
  t.groups = {"main", "counter"};
  const auto group_index = [&](const std::string& name) -> std::size_t {
    return static_cast<std::size_t>(std::find(t.groups.begin(), t.groups.end(), name) - t.groups.begin());
  };
  const auto exit_named = [&](const JsonReader& key) {
    const std::string id = key.AsString();
    if (!venue.FindExit(id)) {
      std::string known;
      for (const geometry::Exit& e : venue.exits) known += (known.empty() ? "" : ", ") + ("\"" + e.id + "\"");
      key.Fail("the venue has no exit \"" + id + "\"; its exits: " + (known.empty() ? "none" : known));
    }
    return id;
  };

  const auto every_scale = reader.Find("rate_scale");
  if (every_scale) every_scale->AsNumber(0.0, 10.0);  // checked even without inflows
  if (auto inflows = reader.Find("inflows")) {
    if (!inflows->IsArray()) inflows->Fail("expected a list of inflows [{\"id\": ..., \"entry\": ..., ...}]");
    std::set<std::string> ids;
    for (std::size_t k = 0; k < inflows->Size(); ++k) {
      const JsonReader item = inflows->Element(k);
      if (!item.IsObject()) item.Fail("expected an inflow {\"id\": ..., \"entry\": ..., \"rate_per_s\": ...}");
      InflowSpec f;
      f.where = item.Where();
      f.id = item.String("id", "inflow" + std::to_string(k + 1));
      if (!ids.insert(f.id).second) item.At("id").Fail("a second inflow \"" + f.id + "\"; expected unique ids");
      const JsonReader entry = item.At("entry");
      f.entry = entry.AsString();
      const auto e = std::find_if(venue.entries.begin(), venue.entries.end(),
                                  [&](const geometry::EntryZone& z) { return z.id == f.entry; });
      if (e == venue.entries.end()) {
        std::string known;
        for (const geometry::EntryZone& z : venue.entries) known += (known.empty() ? "" : ", ") + ("\"" + z.id + "\"");
        entry.Fail("the venue has no entry zone \"" + f.entry + "\"; its entries: " + (known.empty() ? "none" : known));
      }
      f.entry_index = static_cast<std::size_t>(e - venue.entries.begin());
      f.group = item.String("group", "main");
      if (f.group.empty() || f.group.size() > 64) item.At("group").Fail("expected a group name of 1 to 64 characters");
      if (group_index(f.group) == t.groups.size()) {
        if (t.groups.size() >= 64) item.At("group").Fail("more than 64 groups");
        t.groups.push_back(f.group);
      }
      const std::string fallback = f.group == "main" ? main_target : f.group == "counter" ? counter_target : "";
      f.target = item.String("target", fallback);
      if (f.target.empty())
        item.Fail("group \"" + f.group + "\" needs a \"target\" (only \"main\" and \"counter\" default to the population's)");
      if (!venue.FindTarget(f.target))
        (item.Has("target") ? item.At("target") : item).Fail("the venue has no target or exit \"" + f.target + "\"");
      f.rate = ReadRate(item, f.id, base_dir, every_scale ? &*every_scale : nullptr);
      f.on_at_start = item.Bool("active", true);
      if (auto speed = item.Find("desired_speed_m_per_s")) {
        if (!speed->IsArray() || speed->Size() != 2) speed->Fail("expected [min, max] in m/s");
        const double lo = speed->Element(0).AsNumber(0.0, 10.0);
        f.desired_speed_m_per_s = std::pair{lo, speed->Element(1).AsNumber(lo, 10.0)};
      }
      item.Finish();
      t.inflows.push_back(std::move(f));
    }
  }
  if (auto exits = reader.Find("exits")) {
    if (!exits->IsArray()) exits->Fail("expected a list of exit ids");
    for (std::size_t k = 0; k < exits->Size(); ++k) t.exits.push_back(exit_named(exits->Element(k)));
  } else {
    for (const geometry::Exit& e : venue.exits) t.exits.push_back(e.id);
  }
  if (auto closed = reader.Find("closed_exits")) {
    if (!closed->IsArray()) closed->Fail("expected a list of exit ids");
    for (std::size_t k = 0; k < closed->Size(); ++k) t.closed_exits.push_back(exit_named(closed->Element(k)));
  }
  const auto inflow_named = [&](const JsonReader& key) {
    const std::string id = key.AsString();
    if (std::none_of(t.inflows.begin(), t.inflows.end(), [&](const InflowSpec& f) { return f.id == id; }))
      key.Fail("no inflow \"" + id + "\" in /timeline/inflows");
    return id;
  };
  if (auto events = reader.Find("events")) {
    if (!events->IsArray()) events->Fail("expected a list of events [{\"time_s\": ..., ...}]");
    for (std::size_t k = 0; k < events->Size(); ++k) {
      const JsonReader item = events->Element(k);
      if (!item.IsObject()) item.Fail("expected an event {\"time_s\": ..., \"set\" | \"target\" | ...: ...}");
      TimelineEvent e;
      e.where = item.Where();
      e.time_s = item.Number("time_s", 0.0, kMaxTime_s);
      const char* kinds[] = {"set", "target", "open_exit", "close_exit", "start_inflow", "stop_inflow", "fall"};
      int found = -1, count = 0;
      for (int c = 0; c < 7; ++c)
        if (item.Has(kinds[c])) found = c, ++count;
      if (count != 1)
        item.Fail("expected exactly one of \"set\", \"target\", \"open_exit\", \"close_exit\", \"start_inflow\", "
                  "\"stop_inflow\", \"fall\"");
      e.kind = static_cast<TimelineEvent::Kind>(found);
      if (item.Has("group")) {
        const JsonReader g = item.At("group");
        e.group = g.AsString();
        if (group_index(e.group) == t.groups.size())
          g.Fail("no group \"" + e.group + "\"; the groups are \"main\", \"counter\" and those the inflows name");
        if (e.kind != TimelineEvent::Kind::kSetParameters && e.kind != TimelineEvent::Kind::kTarget)
          g.Fail("only \"set\" and \"target\" events apply to a group");
      }
      switch (e.kind) {
        case TimelineEvent::Kind::kSetParameters: {
          const JsonReader set = item.At("set");
          if (!set.IsObject() || set.Keys().empty()) set.Fail("expected {\"parameter\": value, ...}");
          for (const std::string& name : set.Keys()) {
            const JsonReader value = set.At(name);
            if (!ChangeableParameter(name))
              value.Fail("\"" + name + "\" cannot change during a run; expected a number of the parameter table "
                         "(docs/model.md) or \"desired_speed_m_per_s\"");
            if (!e.group.empty() && !GroupParameter(name))
              value.Fail("\"" + name + "\" is the same for everyone; per group only \"back_force_gamma\", "
                         "\"torsion_stiffness_lambda\" and \"desired_speed_m_per_s\" may change (or drop \"group\")");
            const engine::ParameterInfo* info = engine::FindModelParameter(name);
            e.parameters.emplace_back(name, info ? value.AsNumber(info->min, info->max) : value.AsNumber(0.0, 10.0));
          }
          break;
        }
        case TimelineEvent::Kind::kTarget: {
          const JsonReader target = item.At("target");
          e.name = target.AsString();
          if (!venue.FindTarget(e.name)) target.Fail("the venue has no target or exit \"" + e.name + "\"");
          break;
        }
        case TimelineEvent::Kind::kOpenExit: e.name = exit_named(item.At("open_exit")); break;
        case TimelineEvent::Kind::kCloseExit: e.name = exit_named(item.At("close_exit")); break;
        case TimelineEvent::Kind::kStartInflow: e.name = inflow_named(item.At("start_inflow")); break;
        case TimelineEvent::Kind::kStopInflow: e.name = inflow_named(item.At("stop_inflow")); break;
        case TimelineEvent::Kind::kFall: {
          const JsonReader fall = item.At("fall");
          if (!fall.IsObject()) fall.Fail("expected {\"at\": [x, y], \"count\": n, \"within_m\": r}");
          const JsonReader at = fall.At("at");
          if (!at.IsArray() || at.Size() != 2) at.Fail("expected [x, y] in m");
          e.fall_at_x = at.Element(0).AsNumber(-1e6, 1e6);
          e.fall_at_y = at.Element(1).AsNumber(-1e6, 1e6);
          if (!geometry::IsWalkable(venue, Vec2{e.fall_at_x, e.fall_at_y}))
            at.Fail("(" + FormatNumber(e.fall_at_x) + ", " + FormatNumber(e.fall_at_y) +
                    ") is not in the venue's walkable area; expected a point where people stand");
          e.fall_count = static_cast<std::size_t>(fall.Integer("count", 1, 10000));
          e.fall_within_m = fall.Number("within_m", 2.0, 0.01, 1000.0);
          e.name = item.path();
          fall.Finish();
          break;
        }
      }
      item.Finish();
      t.events.push_back(std::move(e));
    }
    std::stable_sort(t.events.begin(), t.events.end(),
                     [](const TimelineEvent& a, const TimelineEvent& b) { return a.time_s < b.time_s; });
  }
  if (auto falls = reader.Find("falls")) {
    FallSpec& f = t.falls;
    const std::string c = falls->Choice("criterion", "acceleration", {"none", "acceleration", "load"});
    f.criterion = c == "none" ? FallSpec::Criterion::kNone
                  : c == "load" ? FallSpec::Criterion::kLoad
                                : FallSpec::Criterion::kAcceleration;
    f.threshold_m_per_s2 = falls->Number("threshold_m_per_s2", f.threshold_m_per_s2, 0.01, 1000.0);
    f.window_s = falls->Number("window_s", f.window_s, 0.01, 10.0);
    f.sample_s = falls->Number("sample_s", f.sample_s, 0.001, 1.0);
    if (f.sample_s > f.window_s) falls->At("sample_s").Fail("must not exceed window_s (" + FormatNumber(f.window_s) + " s)");
    f.load_n = falls->Number("load_n", f.load_n, 1.0, 1e6);
    f.load_duration_s = falls->Number("load_duration_s", f.load_duration_s, 0.0, 3600.0);
    f.trip_over_fallen = falls->Bool("trip_over_fallen", f.trip_over_fallen);
    if (f.trip_over_fallen && f.criterion != FallSpec::Criterion::kAcceleration)
      falls->At("trip_over_fallen").Fail("applies to the criterion \"acceleration\" only (the criterion is \"" + c + "\")");
    // A setting of a criterion the falls do not use (issue 65, D07: a threshold
    // with the criterion "none" was accepted without a word).
    for (const auto& [key, criterion] : {std::pair{"threshold_m_per_s2", "acceleration"}, std::pair{"window_s", "acceleration"},
                                         std::pair{"load_n", "load"}, std::pair{"load_duration_s", "load"}})
      if (falls->Has(key) && c != criterion)
        falls->At(key).Fail(std::string("applies to the criterion \"") + criterion + "\" only (the criterion is \"" + c + "\")");
    if (falls->Has("sample_s") && c == "none")
      falls->At("sample_s").Fail("applies to the criteria \"acceleration\" and \"load\" (the criterion is \"none\")");
    falls->Finish();
  }
  t.max_present = static_cast<std::size_t>(reader.Integer("max_present", 0, 0, 200000));
  if (auto pre = reader.Find("premovement")) {
    PremovementSpec& p = t.premovement;
    p.enabled = true;
    p.where = pre->Where();
    if (HasDistribution(*pre) == pre->Has("times_s"))
      pre->Fail("expected exactly one of a distribution (uniform_s [low, high], gamma, lognormal, weibull) and "
                "times_s [t, ...]");
    if (HasDistribution(*pre)) {
      p.distribution = ReadDistribution(*pre);
    } else {
      const JsonReader times = pre->At("times_s");
      if (!times.IsArray() || times.Size() == 0) times.Fail("expected a list of times in seconds, one per person of the start");
      if (times.Size() > 200000) times.Fail("more times than the largest head count (200000)");
      for (std::size_t k = 0; k < times.Size(); ++k) p.times_s.push_back(times.Element(k).AsNumber(0.0, 1e6));
    }
    pre->Finish();
  }
  t.entry_clearance_m = reader.Number("entry_clearance_m", t.entry_clearance_m, 0.0, 2.0);
  t.stop_when_left_fraction = reader.Number("stop_when_left_fraction", 0.0, 0.0, 1.0);
  if (auto clock = reader.Find("clock_start")) {
    t.clock_start = clock->AsString();
    const std::string& c = t.clock_start;
    const bool ok = c.size() == 5 && std::isdigit(static_cast<unsigned char>(c[0])) &&
                    std::isdigit(static_cast<unsigned char>(c[1])) && c[2] == ':' &&
                    std::isdigit(static_cast<unsigned char>(c[3])) && std::isdigit(static_cast<unsigned char>(c[4])) &&
                    std::stoi(c.substr(0, 2)) < 24 && std::stoi(c.substr(3, 2)) < 60;
    if (!ok) clock->Fail("\"" + c + "\" is not a time of day; expected \"HH:MM\" (24-hour clock)");
  }
  t.clock_scale = reader.Number("clock_scale", 1.0, 1e-3, 1e4);
  if (auto recorded = reader.Find("recorded")) {
    if (!recorded->IsArray()) recorded->Fail("expected a list of marks [{\"time_s\": ..., \"label\": ...}]");
    for (std::size_t k = 0; k < recorded->Size(); ++k) {
      const JsonReader item = recorded->Element(k);
      if (!item.IsObject()) item.Fail("expected a mark {\"time_s\": ..., \"label\": ..., \"kind\": ...}");
      RecordedMark m;
      m.time_s = item.Number("time_s", 0.0, kMaxTime_s);
      m.label = item.String("label", "");
      if (m.label.size() > 200) item.At("label").Fail("a label of at most 200 characters");
      m.kind = item.Choice("kind", "avalanche", {"avalanche", "fatal", "other"});
      if (item.Has("max_speed_m_per_s") || item.Has("max_speed_uncertainty_m_per_s")) {
        // A reading has its uncertainty: both or neither.
        m.max_speed_m_per_s = item.Number("max_speed_m_per_s", 0.0, 20.0);
        m.max_speed_uncertainty_m_per_s = item.Number("max_speed_uncertainty_m_per_s", 1e-3, 20.0);
      }
      item.Finish();
      t.recorded.push_back(std::move(m));
    }
  }
  reader.Finish();
  return t;
}

}  // namespace crowdrecon::scenario
