#include "crowdrecon/scenario/settle.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "state_bytes.hpp"

namespace crowdrecon::scenario {

using detail::StateReader;
using detail::StateWriter;

namespace {

constexpr double kTimeTolerance_s = 1e-6;  // frame times exceed nominal ones by less than a step
constexpr char kStateMagic[8] = {'S', 'E', 'T', 'T', 'L', 'E', '1', '\0'};

// The numbers of run.stop_when_settled with their ranges: one list for the
// reader and for IsValid.
struct SettleKey {
  const char* name;
  double SettleOptions::*field;
  double min, max;
  const char* unit;
};
constexpr SettleKey kSettleKeys[] = {
    {"frozen_window_s", &SettleOptions::frozen_window_s, 1.0, 3600.0, "s"},
    {"frozen_displacement_m", &SettleOptions::frozen_displacement_m, 0.0, 1.0, "m"},
    {"frozen_load_change", &SettleOptions::frozen_load_change, 0.0, 1.0, ""},
    {"lanes_window_s", &SettleOptions::lanes_window_s, 1.0, 3600.0, "s"},
    {"sample_interval_s", &SettleOptions::sample_interval_s, 0.01, 60.0, "s"},
};


}  // namespace

bool SettleOptions::IsValid(std::string* error) const {
  for (const SettleKey& k : kSettleKeys) {
    const double value = this->*k.field;
    if (value >= k.min && value <= k.max) continue;
    *error = std::string("run.stop_when_settled.") + k.name + " = " + FormatNumber(value) + (*k.unit ? " " : "") +
             k.unit + ", expected [" + FormatNumber(k.min) + ", " + FormatNumber(k.max) + "]";
    return false;
  }
  return true;
}

SettleOptions ReadSettleOptions(const JsonReader& settle) {
  if (!settle.IsObject())
    settle.Fail("expected an object {\"frozen_window_s\": ..., \"lanes_window_s\": ...} (may be empty: the "
                "defaults), found " + settle.ValueText());
  SettleOptions o;
  o.enabled = true;
  for (const SettleKey& k : kSettleKeys) o.*k.field = settle.Number(k.name, o.*k.field, k.min, k.max);
  settle.Finish();
  return o;
}

SettleOptions SettleOptionsOfScenario(const std::string& scenario_json, const std::string& origin) {
  const JsonDocument doc = JsonDocument::Parse(scenario_json, origin);
  if (auto run = doc.Root().Find("run"))
    if (auto settle = run->Find("stop_when_settled")) return ReadSettleOptions(*settle);
  SettleOptions o;
  o.enabled = true;
  return o;
}

SettleDetector::SettleDetector(const SettleOptions& options, std::vector<std::uint32_t> group,
                               std::vector<std::string> group_names, PeriodicBox box)
    : options_(options), group_(std::move(group)), group_names_(std::move(group_names)), box_(box) {
  for (std::uint32_t g : group_)
    if (g >= group_names_.size()) group_names_.resize(g + 1);
  for (std::size_t g = 0; g < group_names_.size(); ++g)
    if (group_names_[g].empty()) group_names_[g] = "group " + std::to_string(g);
  group_speed_.assign(group_names_.size(), {});
  group_people_.assign(group_names_.size(), 0);
  for (std::uint32_t g : group_) ++group_people_[g];
}

std::string SettleDetector::Add(const Frame& f) {
  const std::size_t n = group_.size();
  if (f.position_m->size() != n || f.velocity_m_per_s->size() != n || f.desired_direction->size() != n ||
      f.load_n->size() != n || f.present->size() != n)
    throw std::logic_error("SettleDetector: a frame's arrays differ in size from the people");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sum(group_names_.size(), 0.0);
  std::vector<std::size_t> count(group_names_.size(), 0);
  double crowd_sum = 0.0;
  std::size_t crowd_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(*f.present)[i]) continue;
    const double along = Dot((*f.velocity_m_per_s)[i], (*f.desired_direction)[i]);
    sum[group_[i]] += along;
    ++count[group_[i]];
    crowd_sum += along;
    ++crowd_count;
  }
  time_s_.push_back(f.time_s);
  // As in the analysis: a frame with nobody in it has no flow.
  crowd_speed_.push_back(crowd_count ? crowd_sum / static_cast<double>(crowd_count) : 0.0);
  for (std::size_t g = 0; g < group_names_.size(); ++g)
    group_speed_[g].push_back(count[g] ? sum[g] / static_cast<double>(count[g]) : nan);

  if (next_sample_s_ >= 0.0 && f.time_s < next_sample_s_ - kTimeTolerance_s) return {};
  next_sample_s_ = (next_sample_s_ < 0.0 ? f.time_s : next_sample_s_) + options_.sample_interval_s;
  samples_.push_back({f.time_s, *f.position_m, *f.load_n});
  // Keep the samples of the window, and the newest one at least a window old.
  while (samples_.size() >= 2 && samples_[1].time_s <= f.time_s - options_.frozen_window_s + kTimeTolerance_s)
    samples_.erase(samples_.begin());
  return Evaluate();
}

std::string SettleDetector::Evaluate() const {
  const analysis::RegimeOptions regime_options;
  std::vector<analysis::DirectionSeries> directions;
  for (std::size_t g = 0; g < group_names_.size(); ++g)
    if (group_people_[g] > 0) directions.push_back({group_names_[g], group_people_[g], group_speed_[g]});
  const analysis::RegimeResult r =
      analysis::ClassifyByDirection(time_s_, crowd_speed_, directions, {}, regime_options);
  const double now = time_s_.back();

  if (r.regime == analysis::Regime::kClogging) {
    for (const analysis::DirectionRegime& d : r.directions)
      if (!d.result.frozen_at_end) return {};  // one direction still walks: not absorbing
    if (samples_.front().time_s > now - options_.frozen_window_s + kTimeTolerance_s) return {};
    const Sample& last = samples_.back();
    double moved = 0.0, change = 0.0;
    for (const Sample& s : samples_) {
      double diff = 0.0, total = 0.0;
      for (std::size_t i = 0; i < group_.size(); ++i) {
        moved = std::max(moved, Length(box_.MinimumImage(last.position_m[i] - s.position_m[i])));
        diff += std::abs(last.load_n[i] - s.load_n[i]);
        total += last.load_n[i];
      }
      change = std::max(change, total > 0.0 ? diff / total : (diff > 0.0 ? 1.0 : 0.0));
    }
    if (moved >= options_.frozen_displacement_m || change >= options_.frozen_load_change) return {};
    return "settled frozen at " + FormatFixed(now, 1) + " s: " + r.reason + "; for the last " +
           FormatNumber(options_.frozen_window_s) + " s nobody moved more than " + FormatFixed(100.0 * moved, 1) +
           " cm (limit " + FormatNumber(100.0 * options_.frozen_displacement_m) + " cm) and the loads changed by " +
           FormatFixed(100.0 * change, 1) + " % at most (limit " + FormatNumber(100.0 * options_.frozen_load_change) +
           " %)";
  }
  if (r.regime == analysis::Regime::kLanes) {
    if (time_s_.front() > now - options_.lanes_window_s + kTimeTolerance_s) return {};
    double slowest = std::numeric_limits<double>::infinity();
    std::string slowest_name;
    for (std::size_t k = time_s_.size(); k-- > 0 && time_s_[k] >= now - options_.lanes_window_s - kTimeTolerance_s;)
      for (std::size_t g = 0; g < group_names_.size(); ++g) {
        const double v = group_speed_[g][k];
        if (std::isfinite(v) && v < slowest) {
          slowest = v;
          slowest_name = group_names_[g];
        }
      }
    if (!(slowest >= regime_options.stop_speed_m_per_s)) return {};
    return "settled in lanes at " + FormatFixed(now, 1) + " s: " + r.reason + "; for the last " +
           FormatNumber(options_.lanes_window_s) + " s no direction stopped (slowest frame: " + slowest_name + " " +
           FormatFixed(slowest, 3) + " m/s, stop speed " + FormatNumber(regime_options.stop_speed_m_per_s) + " m/s)";
  }
  return {};
}

std::string SettleDetector::SaveState() const {
  StateWriter w;
  w.out.append(kStateMagic, sizeof kStateMagic);
  w.Put<std::uint64_t>(group_.size());
  w.Put<std::uint64_t>(group_names_.size());
  w.Put(next_sample_s_);
  w.PutDoubles(time_s_);
  w.PutDoubles(crowd_speed_);
  for (const std::vector<double>& g : group_speed_) w.PutDoubles(g);
  w.Put<std::uint64_t>(samples_.size());
  for (const Sample& s : samples_) {
    w.Put(s.time_s);
    std::vector<double> xy;
    for (Vec2 p : s.position_m) {
      xy.push_back(p.x);
      xy.push_back(p.y);
    }
    w.PutDoubles(xy);
    w.PutDoubles(s.load_n);
  }
  return w.out;
}

void SettleDetector::LoadState(const std::string& state) {
  StateReader r(state, "the run's settle check");
  r.Need(sizeof kStateMagic);
  if (state.compare(0, sizeof kStateMagic, std::string(kStateMagic, sizeof kStateMagic)) != 0) r.Fail();
  for (std::size_t i = 0; i < sizeof kStateMagic; ++i) r.Get<char>();
  if (r.Get<std::uint64_t>() != group_.size() || r.Get<std::uint64_t>() != group_names_.size()) r.Fail();
  next_sample_s_ = r.Get<double>();
  time_s_ = r.GetDoubles();
  crowd_speed_ = r.GetDoubles(time_s_.size());
  for (std::vector<double>& g : group_speed_) g = r.GetDoubles(time_s_.size());
  const auto samples = r.Get<std::uint64_t>();
  if (samples > 1000000) r.Fail();
  samples_.assign(samples, {});
  for (Sample& s : samples_) {
    s.time_s = r.Get<double>();
    const std::vector<double> xy = r.GetDoubles(2 * group_.size());
    for (std::size_t i = 0; i < group_.size(); ++i) s.position_m.push_back({xy[2 * i], xy[2 * i + 1]});
    s.load_n = r.GetDoubles(group_.size());
  }
  if (!r.AtEnd()) r.Fail();
}

}  // namespace crowdrecon::scenario
