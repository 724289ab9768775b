#include "timeline_systems.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/geometry/population.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "state_bytes.hpp"

namespace crowdrecon::scenario::detail {

namespace {

constexpr double kEventTolerance_s = 1e-9;
// A queue whose head found no room tries again after this (s): a tenth of a
// second, about the time a walking neighbour takes to clear a body's width
// by 10 cm, so that a blocked entry costs a few attempts per second.
constexpr double kRetryInterval_s = 0.1;
// Places drawn per attempt for the queue's head.
constexpr int kPlacesPerAttempt = 20;
// The timeline's checkpoint state; 002 since arrivals are numbered by the
// time they are due (BuiltTimeline::arrival_id). A 001 state belongs to a
// run whose person table numbers them inflow by inflow: this build would
// give its later arrivals other people's rows, so it does not resume it.
constexpr char kStateMagic[8] = {'T', 'L', 'I', 'N', 'E', '0', '0', '2'};
constexpr char kStateMagicInflowByInflow[8] = {'T', 'L', 'I', 'N', 'E', '0', '0', '1'};

std::size_t GroupIndex(const TimelineSpec& spec, const std::string& name) {
  return static_cast<std::size_t>(std::find(spec.groups.begin(), spec.groups.end(), name) - spec.groups.begin());
}

std::uint32_t TargetOf(const TimelineState& s, const std::string& name) {
  const auto it = std::find(s.target_names.begin(), s.target_names.end(), name);
  if (it == s.target_names.end()) throw std::logic_error("internal error: timeline target \"" + name + "\" not built");
  return static_cast<std::uint32_t>(it - s.target_names.begin());
}

std::size_t ExitIndex(const geometry::Venue& venue, const std::string& id) {
  for (std::size_t e = 0; e < venue.exits.size(); ++e)
    if (venue.exits[e].id == id) return e;
  throw std::logic_error("internal error: timeline exit \"" + id + "\" not in the venue");
}

// ---------------------------------------------------------------------------

class TimelineEventSystem : public RunSystem {
 public:
  explicit TimelineEventSystem(TimelineState& s) : s_(s) {}
  std::string_view name() const override { return "timeline_events"; }
  bool acts_every_step() const override { return true; }
  void BeforeStep(engine::Simulation& sim) override {
    const std::vector<TimelineEvent>& events = s_.spec.events;
    while (s_.next_event < events.size() && events[s_.next_event].time_s <= sim.time_s() + kEventTolerance_s)
      Apply(sim, events[s_.next_event++]);
  }
  std::string SaveState() const override { return s_.SaveState(); }
  void LoadState(const std::string& state) override { s_.LoadState(state); }

 private:
  // Every slot now holding someone of `group` ("" = everyone).
  template <typename F>
  void ForGroup(const engine::Simulation& sim, const std::string& group, F&& f) {
    const std::size_t g = group.empty() ? SIZE_MAX : GroupIndex(s_.spec, group);
    const engine::BodyState& b = sim.bodies();
    for (std::uint32_t i = 0; i < b.size(); ++i)
      if (b.state[i] != engine::PersonState::kRemoved && (g == SIZE_MAX || b.group[i] == g)) f(i);
  }

  void Apply(engine::Simulation& sim, const TimelineEvent& e) {
    const double t = sim.time_s();
    const std::string who = e.group.empty() ? "everyone" : "group " + e.group;
    std::string detail;
    switch (e.kind) {
      case TimelineEvent::Kind::kSetParameters: {
        engine::ModelParameters p = sim.definition().parameters;
        bool global = false;
        for (const auto& [name, value] : e.parameters) {
          detail += (detail.empty() ? "" : ", ") + name + " = " + FormatNumber(value);
          if (name == "desired_speed_m_per_s") {
            const double speed = value;  // (a structured binding is not captured before clang 16)
            ForGroup(sim, e.group, [&](std::uint32_t i) { sim.SetDesiredSpeed(i, speed); });
            for (std::size_t g = 0; g < s_.group_speed.size(); ++g)
              if (e.group.empty() || g == GroupIndex(s_.spec, e.group)) s_.group_speed[g] = value;
          } else if (!e.group.empty()) {
            const std::size_t g = GroupIndex(s_.spec, e.group);
            (name == "back_force_gamma" ? s_.group_gamma : s_.group_lambda)[g] = value;
            sim.SetGroupDrive(static_cast<std::uint32_t>(g), s_.group_gamma[g], s_.group_lambda[g]);
          } else {
            global = true;
            // Everyone's: a group's own value of it ends.
            if (name == "back_force_gamma" || name == "torsion_stiffness_lambda") {
              std::vector<double>& own = name == "back_force_gamma" ? s_.group_gamma : s_.group_lambda;
              for (std::size_t g = 0; g < own.size(); ++g)
                if (!std::isnan(own[g])) {
                  own[g] = std::numeric_limits<double>::quiet_NaN();
                  sim.SetGroupDrive(static_cast<std::uint32_t>(g), s_.group_gamma[g], s_.group_lambda[g]);
                }
            }
          }
        }
        if (global) {
          ApplyEventToModel(e, &p);
          try {
            sim.SetParameters(p);
          } catch (const InputError& error) {
            throw InputError(s_.scenario.file.string() + ": " + e.where + ": " + error.what());
          }
        }
        s_.Event(t, "parameters", -1, who + ": " + detail);
        break;
      }
      case TimelineEvent::Kind::kTarget: {
        const std::uint32_t target = TargetOf(s_, e.name);
        ForGroup(sim, e.group, [&](std::uint32_t i) { sim.SetTarget(i, target); });
        for (std::size_t g = 0; g < s_.group_target.size(); ++g)
          if (e.group.empty() || g == GroupIndex(s_.spec, e.group)) s_.group_target[g] = target;
        s_.Event(t, "target", -1, who + " now heads for " + e.name);
        break;
      }
      case TimelineEvent::Kind::kOpenExit:
      case TimelineEvent::Kind::kCloseExit: {
        const bool open = e.kind == TimelineEvent::Kind::kOpenExit;
        const std::size_t x = ExitIndex(s_.scenario.venue, e.name);
        s_.exit_open[x] = open ? 1 : 0;
        sim.SetWallEnabled(s_.built.exit_wall[x], !open);
        s_.Event(t, open ? "exit_opened" : "exit_closed", -1, e.name);
        break;
      }
      case TimelineEvent::Kind::kStartInflow:
      case TimelineEvent::Kind::kStopInflow: {
        const bool on = e.kind == TimelineEvent::Kind::kStartInflow;
        const auto f = static_cast<std::size_t>(
            std::find_if(s_.spec.inflows.begin(), s_.spec.inflows.end(), [&](const InflowSpec& i) { return i.id == e.name; }) -
            s_.spec.inflows.begin());
        if (on && !s_.inflow_on[f]) {
          s_.inflow_on[f] = 1;
          s_.inflow_since[f] = t;
        } else if (!on && s_.inflow_on[f]) {
          s_.inflow_before[f] += s_.spec.inflows[f].rate.Integral(s_.inflow_since[f], t);
          s_.inflow_on[f] = 0;
        }
        s_.Event(t, on ? "inflow_started" : "inflow_stopped", -1, e.name);
        break;
      }
      case TimelineEvent::Kind::kFall: {
        // The walking people nearest the point (ties by id), of those within
        // reach of it: the accounts say where and how many, not who.
        const engine::BodyState& b = sim.bodies();
        const Vec2 at{e.fall_at_x, e.fall_at_y};
        std::vector<std::pair<double, std::uint32_t>> near;  // (distance, slot)
        for (std::uint32_t i = 0; i < b.size(); ++i) {
          if (b.state[i] != engine::PersonState::kWalking) continue;
          const double d = Length(b.position_m[i] - at);
          if (d <= e.fall_within_m) near.emplace_back(d, i);
        }
        std::sort(near.begin(), near.end(), [&](const auto& p, const auto& q) {
          return p.first != q.first ? p.first < q.first : b.id[p.second] < b.id[q.second];
        });
        if (near.size() > e.fall_count) near.resize(e.fall_count);
        const std::string where = "(" + FormatNumber(at.x) + ", " + FormatNumber(at.y) + ") m";
        for (const auto& [d, i] : near)
          s_.Fall(sim, i,
                  "recorded: " + std::to_string(near.size()) + " of the " + std::to_string(e.fall_count) +
                      " nearest " + where + " within " + FormatNumber(e.fall_within_m) + " m (" + e.name +
                      "), this one at " + FormatFixed(d, 2) + " m");
        s_.Event(t, "recorded_fall", -1,
                 std::to_string(near.size()) + " of " + std::to_string(e.fall_count) + " fell at once near " + where +
                     (near.size() < e.fall_count ? ": fewer people walking within " + FormatNumber(e.fall_within_m) + " m"
                                                 : ""));
        break;
      }
    }
  }

  TimelineState& s_;
};

// ---------------------------------------------------------------------------

class InflowSystem : public RunSystem {
 public:
  explicit InflowSystem(TimelineState& s) : s_(s) {}
  std::string_view name() const override { return "inflow"; }
  bool acts_every_step() const override { return true; }
  void BeforeStep(engine::Simulation& sim) override {
    const double t = sim.time_s();
    for (std::size_t f = 0; f < s_.spec.inflows.size(); ++f) {
      const std::uint64_t due = s_.Due(f, t);
      if (s_.placed[f] >= due || t + kEventTolerance_s < s_.next_try_s[f]) continue;
      while (s_.placed[f] < due && s_.placed[f] < s_.built.arrivals[f].size()) {
        if (!PlaceNext(sim, f, t)) {
          s_.next_try_s[f] = t + kRetryInterval_s;
          break;
        }
      }
    }
  }

 private:
  // The queue's head of inflow f into a free place of its entry zone and a
  // free engine slot, if there are both.
  bool PlaceNext(engine::Simulation& sim, std::size_t f, double t) {
    const engine::BodyState& b = sim.bodies();
    std::uint32_t slot = 0;
    while (slot < b.size() && b.state[slot] != engine::PersonState::kRemoved) ++slot;
    if (slot == b.size()) return false;  // the venue holds as many as it can (BuiltTimeline)
    const std::uint64_t k = s_.placed[f];
    engine::PersonDef p = s_.built.arrivals[f][k];
    const std::size_t g = p.group;
    if (s_.group_target[g] >= 0) p.target = static_cast<std::uint32_t>(s_.group_target[g]);
    if (!std::isnan(s_.group_speed[g])) p.desired_speed_m_per_s = s_.group_speed[g];
    const geometry::NavigationField& field = sim.definition().targets[p.target];
    std::mt19937_64& rng = s_.rng[f];
    for (int attempt = 0; attempt < kPlacesPerAttempt; ++attempt) {
      const Vec2 at = s_.entry_area[f].Sample(rng);
      const Vec2 e = field.Direction(at);
      const double jitter = 0.3 * (geometry::UniformUnit(rng()) - 0.5);
      const double theta = (e.x != 0.0 || e.y != 0.0 ? std::atan2(e.y, e.x) : 0.0) + jitter;
      if (!sim.IsFree(p.shape, at, theta, s_.spec.entry_clearance_m)) continue;
      p.position_m = at;
      p.angle_rad = theta;
      p.velocity_m_per_s = e * p.desired_speed_m_per_s;  // walking in at their own pace
      const std::uint32_t id = s_.built.arrival_id[f][k];
      sim.Spawn(slot, p, id);
      ++s_.placed[f];
      s_.Event(t, "enter", id, s_.spec.inflows[f].id + " at " + s_.spec.inflows[f].entry);
      return true;
    }
    return false;
  }

  TimelineState& s_;
};

// ---------------------------------------------------------------------------

class ExitSystem : public RunSystem {
 public:
  explicit ExitSystem(TimelineState& s) : s_(s) {
    for (const std::string& id : s_.spec.exits) removing_.push_back(ExitIndex(s_.scenario.venue, id));
  }
  std::string_view name() const override { return "exits"; }
  bool acts_every_step() const override { return !removing_.empty(); }
  // Every kCheckSteps fixed steps (ticks) and at every frame (so that no frame shows
  // anyone beyond an open exit): the straight path of each walking person's
  // centre since the last check (a few millimetres: 10 steps of ~0.5 ms at
  // walking speed; a person is removed at most that late), for a tenth of
  // the cost of a check every step.
  void AfterStep(engine::Simulation& sim) override {
    if (sim.LastStepReached(kCheckSteps)) Check(sim);
  }
  void AtFrame(FrameContext& c) override { Check(c.sim); }
  std::string SaveState() const override {
    StateWriter w;
    w.PutVector(before_);
    w.PutVector(id_);
    return w.out;
  }
  void LoadState(const std::string& state) override {
    StateReader r(state, "the timeline's exits");
    before_ = r.GetVector<Vec2>();
    id_ = r.GetVector<std::uint32_t>(before_.size());
    if (!r.AtEnd()) r.Fail();
  }

 private:
  void Check(engine::Simulation& sim) {
    const engine::BodyState& b = sim.bodies();
    const geometry::Venue& venue = s_.scenario.venue;
    if (before_.size() == b.size()) {
      for (std::uint32_t i = 0; i < b.size(); ++i) {
        if (b.state[i] != engine::PersonState::kWalking || b.id[i] != id_[i]) continue;  // (a newcomer since)
        const Vec2 from = before_[i], to = from + sim.Separation(b.position_m[i], from);
        for (std::size_t x : removing_) {
          if (!s_.exit_open[x]) continue;
          const geometry::Exit& exit = venue.exits[x];
          // Most paths are nowhere near: a box test first.
          if (std::max(from.x, to.x) < std::min(exit.a.x, exit.b.x) || std::min(from.x, to.x) > std::max(exit.a.x, exit.b.x) ||
              std::max(from.y, to.y) < std::min(exit.a.y, exit.b.y) || std::min(from.y, to.y) > std::max(exit.a.y, exit.b.y))
            continue;
          if (!engine::PathCrossesSegment(from, to, exit.a, exit.b)) continue;
          sim.SetPersonState(i, engine::PersonState::kRemoved);
          ++s_.exit_count[x];
          ++s_.removed;
          s_.Event(sim.time_s(), "exit", b.id[i], exit.id);
          break;
        }
      }
    }
    before_ = b.position_m;
    SlotHolders(b, &id_);
  }

  static constexpr std::uint64_t kCheckSteps = 10;
  TimelineState& s_;
  std::vector<std::size_t> removing_;
  std::vector<Vec2> before_;        // centres at the last check
  std::vector<std::uint32_t> id_;   // who held each slot then
};

// ---------------------------------------------------------------------------

class FallSystem : public RunSystem {
 public:
  explicit FallSystem(TimelineState& s) : s_(s), spec_(s.spec.falls) {}
  std::string_view name() const override { return "falls"; }
  bool acts_every_step() const override { return spec_.criterion != FallSpec::Criterion::kNone; }
  void AfterStep(engine::Simulation& sim) override {
    if (every_ == 0) {  // the sampling in fixed steps (ticks), from the run's step
      every_ = std::max<std::int64_t>(1, std::llround(spec_.sample_s / sim.tick_s()));
      const double sample = static_cast<double>(every_) * sim.tick_s();
      depth_ = static_cast<std::size_t>(std::max<long long>(1, std::llround(spec_.window_s / sample)));
    }
    const engine::BodyState& b = sim.bodies();
    const std::size_t n = b.size();
    if (id_.size() != n) {
      id_.assign(n, UINT32_MAX);
      filled_.assign(n, 0);
      history_.assign(n * (depth_ + 1), Vec2{});
      above_s_.assign(n, 0.0);
      if (spec_.trip_over_fallen) {
        fallen_impulse_.assign(n, Vec2{});
        unheld_.assign(n * (depth_ + 1), Vec2{});
      }
    }
    // Tripping: the impulse of the fallen's hold, every step (none to count
    // until someone has fallen).
    if (spec_.trip_over_fallen && s_.fallen > 0) AddImpulseOfTheFallen(sim);
    if (!sim.LastStepReached(static_cast<std::uint64_t>(every_))) return;
    const double sample_s = static_cast<double>(every_) * sim.tick_s();
    if (spec_.criterion == FallSpec::Criterion::kLoad) PersonChestLoads(sim, &load_);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (b.state[i] != engine::PersonState::kWalking) continue;
      if (id_[i] != b.id[i]) {  // someone new in this slot
        id_[i] = b.id[i];
        filled_[i] = 0;
        above_s_[i] = 0.0;
        if (spec_.trip_over_fallen) fallen_impulse_[i] = Vec2{};
      }
      std::string cause;
      if (spec_.criterion == FallSpec::Criterion::kAcceleration) {
        // A ring of the last depth + 1 velocity samples.
        Vec2* ring = &history_[i * (depth_ + 1)];
        const std::uint64_t count = filled_[i];
        ring[count % (depth_ + 1)] = b.velocity_m_per_s[i];
        // Tripping: also the velocity they would have had without the
        // fallen's hold (pushed onto a fallen body, they go over it).
        Vec2* unheld = spec_.trip_over_fallen ? &unheld_[i * (depth_ + 1)] : nullptr;
        if (unheld) unheld[count % (depth_ + 1)] = b.velocity_m_per_s[i] - fallen_impulse_[i] / b.mass_kg[i];
        filled_[i] = count + 1;
        if (count < depth_) continue;
        const double window = static_cast<double>(depth_) * sample_s;
        // The mean acceleration over the window: the change from the ring's
        // oldest sample to its newest, over the window.
        const auto mean_change = [&](const Vec2* samples) {
          return Length(samples[count % (depth_ + 1)] - samples[(count - depth_) % (depth_ + 1)]) / window;
        };
        const double a = mean_change(ring);
        if (a > spec_.threshold_m_per_s2)
          cause = "acceleration: mean " + FormatFixed(a, 2) + " m/s^2 over " + FormatNumber(window) +
                  " s (threshold " + FormatNumber(spec_.threshold_m_per_s2) + " m/s^2)";
        if (unheld) {
          const double pushed = mean_change(unheld);
          if (cause.empty() && pushed > spec_.threshold_m_per_s2)
            cause = "tripped: pushed onto a fallen person, a mean " + FormatFixed(pushed, 2) + " m/s^2 over " +
                    FormatNumber(window) + " s without the fallen's hold (threshold " +
                    FormatNumber(spec_.threshold_m_per_s2) + " m/s^2)";
        }
      } else {
        above_s_[i] = load_[i] > spec_.load_n ? above_s_[i] + sample_s : 0.0;
        if (above_s_[i] >= spec_.load_duration_s - 1e-9 && load_[i] > spec_.load_n)
          cause = "chest load: above " + FormatNumber(spec_.load_n) + " N for " + FormatNumber(above_s_[i]) + " s (now " +
                  FormatFixed(load_[i], 0) + " N)";
      }
      if (cause.empty()) continue;
      s_.Fall(sim, i, cause);
    }
  }
  std::string SaveState() const override {
    StateWriter w;
    w.Put(every_);
    w.Put<std::uint64_t>(depth_);
    w.PutVector(id_);
    w.PutVector(filled_);
    w.PutVector(history_);
    w.PutVector(above_s_);
    if (spec_.trip_over_fallen) {
      w.PutVector(fallen_impulse_);
      w.PutVector(unheld_);
    }
    return w.out;
  }
  void LoadState(const std::string& state) override {
    StateReader r(state, "the timeline's fall filters");
    every_ = r.Get<std::int64_t>();
    depth_ = r.Get<std::uint64_t>();
    if (every_ < 0 || depth_ > 100000) r.Fail();
    id_ = r.GetVector<std::uint32_t>();
    filled_ = r.GetVector<std::uint64_t>(id_.size());
    history_ = r.GetVector<Vec2>(id_.empty() ? 0 : id_.size() * (depth_ + 1));
    above_s_ = r.GetVector<double>(id_.size());
    if (spec_.trip_over_fallen) {
      fallen_impulse_ = r.GetVector<Vec2>(id_.size());
      unheld_ = r.GetVector<Vec2>(id_.empty() ? 0 : id_.size() * (depth_ + 1));
    }
    if (!r.AtEnd()) r.Fail();
  }

 private:
  TimelineState& s_;
  const FallSpec& spec_;
  std::int64_t every_ = 0;   // steps between samples
  std::size_t depth_ = 0;    // samples per window
  std::vector<std::uint32_t> id_;       // who each slot's filter belongs to
  std::vector<std::uint64_t> filled_;   // samples taken of them
  std::vector<Vec2> history_;           // per slot, a ring of depth_ + 1 velocities
  std::vector<double> above_s_;         // per slot, time above the load threshold
  std::vector<double> load_;
  // Tripping: per slot, the impulse of contacts with fallen people (N s), and
  // a ring of the velocities they would have had without it.
  std::vector<Vec2> fallen_impulse_;
  std::vector<Vec2> unheld_;

  // Adds this step's impulse of every contact between a walking and a
  // fallen person to the walking one's account.
  void AddImpulseOfTheFallen(const engine::Simulation& sim) {
    const engine::BodyState& b = sim.bodies();
    const double dt = sim.last_step_s();
    for (const engine::Contact& c : sim.contacts()) {
      if (c.wall) continue;
      const engine::PersonState sa = b.state[c.a], sb = b.state[c.b];
      if (sa == engine::PersonState::kWalking && sb == engine::PersonState::kFallen) fallen_impulse_[c.a] += c.Force() * dt;
      if (sb == engine::PersonState::kWalking && sa == engine::PersonState::kFallen) fallen_impulse_[c.b] -= c.Force() * dt;
    }
  }
};

// ---------------------------------------------------------------------------


// ---------------------------------------------------------------------------

// Avalanches as they happen: the analysis's detector (analysis/regime.hpp,
// FindAvalanches with the default RegimeOptions) on each direction's mean
// speed along its desired direction (a group: the people walking to one
// target) and the crowd's, frame by frame, run again every second on the
// series so far; each avalanche is written once, when it is first seen
// (the burst reached), as an event `avalanche` at its start time.
class AvalancheSystem : public RunSystem {
 public:
  explicit AvalancheSystem(TimelineState& s) : s_(s), series_(s.spec.groups.size() + 1), reported_(series_.size(), 0.0) {
    std::fill(reported_.begin(), reported_.end(), -1.0);
  }
  std::string_view name() const override { return "avalanches"; }
  void AtFrame(FrameContext& c) override {
    const engine::BodyState& b = c.sim.bodies();
    const std::size_t groups = s_.spec.groups.size();
    std::vector<double> sum(groups + 1, 0.0);
    std::vector<std::size_t> count(groups + 1, 0);
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b.state[i] != engine::PersonState::kWalking || b.group[i] >= groups) continue;
      const double along = Dot(b.velocity_m_per_s[i], c.sim.definition().targets[b.target[i]].Direction(b.position_m[i]));
      sum[b.group[i]] += along;
      ++count[b.group[i]];
      sum[groups] += along;
      ++count[groups];
    }
    time_.push_back(c.sim.time_s());
    // Nobody of a direction walking: no speed (a gap, not a stop: issue 65,
    // the counter-flow's first arrivals were read as an avalanche).
    for (std::size_t g = 0; g <= groups; ++g)
      series_[g].push_back(count[g] > 0 ? sum[g] / static_cast<double>(count[g]) : std::nan(""));
    if (c.sim.time_s() + 1e-9 < next_check_s_) return;
    next_check_s_ = c.sim.time_s() + 1.0;
    const analysis::RegimeOptions options = analysis::IncidentAvalancheOptions();
    for (std::size_t g = 0; g <= groups; ++g) {
      for (const analysis::Avalanche& a : analysis::FindAvalanchesBetweenGaps(time_, series_[g], options)) {
        if (a.start_time_s <= reported_[g]) continue;
        reported_[g] = a.start_time_s;
        const std::string who = g < groups ? "direction " + s_.spec.groups[g] : "crowd";
        s_.Event(a.start_time_s, "avalanche", -1,
                 who + ": released after a stop of " + FormatFixed(a.stopped_before_s, 1) + " s, rise time " +
                     FormatFixed(a.rise_time_s, 2) + " s, peak " + FormatFixed(a.peak_speed_m_per_s, 2) + " m/s so far");
      }
    }
  }
  std::string SaveState() const override {
    StateWriter w;
    w.Put(next_check_s_);
    w.PutVector(time_);
    for (const std::vector<double>& s : series_) w.PutVector(s);
    w.PutVector(reported_);
    return w.out;
  }
  void LoadState(const std::string& state) override {
    StateReader r(state, "the timeline's avalanche detector");
    next_check_s_ = r.Get<double>();
    time_ = r.GetVector<double>();
    for (std::vector<double>& s : series_) s = r.GetVector<double>(time_.size());
    reported_ = r.GetVector<double>(series_.size());
    if (!r.AtEnd()) r.Fail();
  }

 private:
  TimelineState& s_;
  std::vector<double> time_;
  std::vector<std::vector<double>> series_;  // per group, then the crowd
  std::vector<double> reported_;             // start of the last avalanche written, per series
  double next_check_s_ = 0.0;
};

// Ends an evacuation once the stated share of the people who entered has
// left (timeline.stop_when_left_fraction).
class LeftSystem : public RunSystem {
 public:
  explicit LeftSystem(TimelineState& s) : s_(s) {}
  std::string_view name() const override { return "left"; }
  void AtFrame(FrameContext& c) override {
    const double fraction = s_.spec.stop_when_left_fraction;
    const std::uint64_t entered = s_.Entered();
    if (!(fraction > 0.0) || entered == 0 || static_cast<double>(s_.removed) < fraction * static_cast<double>(entered))
      return;
    c.finish = true;
    c.finish_reason = FormatNumber(100.0 * fraction) + " % of the people who entered have left (" +
                      std::to_string(s_.removed) + " of " + std::to_string(entered) + ") at t = " +
                      FormatNumber(c.sim.time_s()) + " s";
    s_.Event(c.sim.time_s(), "left", -1, c.finish_reason);
  }

 private:
  TimelineState& s_;
};

}  // namespace

// ---------------------------------------------------------------------------

TimelineState::TimelineState(const Scenario& sc, const BuiltWorld& world)
    : scenario(sc), spec(sc.timeline), built(world.timeline), target_names(world.target_names) {
  const std::size_t inflows = spec.inflows.size();
  inflow_on.assign(inflows, 0);
  inflow_before.assign(inflows, 0.0);
  inflow_since.assign(inflows, 0.0);
  placed.assign(inflows, 0);
  next_try_s.assign(inflows, 0.0);
  for (std::size_t f = 0; f < inflows; ++f) {
    inflow_on[f] = spec.inflows[f].on_at_start ? 1 : 0;
    // Placement draws: a stream per inflow, apart from the bodies' (world_builder.cpp).
    rng.emplace_back(sc.population.seed ^ (0xd1b54a32d192ed03ull * (f + 1)));
    entry_area.push_back(geometry::AreaTriangulation::OfEntryZone(sc.venue, spec.inflows[f].entry_index));
  }
  exit_open.assign(sc.venue.exits.size(), 1);
  for (const std::string& id : spec.closed_exits) exit_open[ExitIndex(sc.venue, id)] = 0;
  exit_count.assign(sc.venue.exits.size(), 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  group_target.assign(spec.groups.size(), -1);
  group_speed.assign(spec.groups.size(), nan);
  group_gamma.assign(spec.groups.size(), nan);
  group_lambda.assign(spec.groups.size(), nan);
}

std::uint64_t TimelineState::Due(std::size_t f, double t) const {
  const RateSchedule& rate = spec.inflows[f].rate;
  const double integral = inflow_before[f] + (inflow_on[f] ? rate.Integral(std::max(0.0, inflow_since[f]), t) : 0.0);
  const auto due = static_cast<std::uint64_t>(std::floor(integral + 1e-9));
  return std::min<std::uint64_t>(due, built.arrivals[f].size());
}

std::uint64_t TimelineState::Queued(double t) const {
  std::uint64_t q = 0;
  for (std::size_t f = 0; f < spec.inflows.size(); ++f) {
    const std::uint64_t due = Due(f, t);
    q += due - std::min(due, placed[f]);
  }
  return q;
}

runfile::Census TimelineState::Count(const engine::Simulation& sim) const {
  const engine::BodyState& b = sim.bodies();
  runfile::Census census;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.state[i] == engine::PersonState::kWalking) ++census.walking;
    if (b.state[i] == engine::PersonState::kFallen) ++census.fallen;
  }
  census.removed = static_cast<std::int64_t>(removed);
  census.queued = static_cast<std::int64_t>(Queued(sim.time_s()));
  census.entered = static_cast<std::int64_t>(Entered());
  if (census.entered != census.walking + census.fallen + census.removed)
    throw std::logic_error("internal error: the timeline lost track of people at t = " + FormatNumber(sim.time_s()) +
                           " s: entered " + std::to_string(census.entered) + ", walking " +
                           std::to_string(census.walking) + ", fallen " + std::to_string(census.fallen) +
                           ", removed " + std::to_string(census.removed));
  return census;
}

std::uint64_t TimelineState::Entered() const {
  std::uint64_t n = built.initial_people;
  for (std::uint64_t p : placed) n += p;
  return n;
}

void TimelineState::Fall(engine::Simulation& sim, std::uint32_t slot, const std::string& cause) {
  const std::int64_t person = sim.bodies().id[slot];
  sim.SetPersonState(slot, engine::PersonState::kFallen);
  ++fallen;
  Event(sim.time_s(), "fall", person, cause);
}

void TimelineState::Event(double time_s, const std::string& kind, std::int64_t person, const std::string& detail) {
  runfile::Event e;
  e.time_s = time_s;
  e.kind = kind;
  e.person = person;
  e.detail = detail;
  events.push_back(std::move(e));
}

std::string TimelineState::SaveState() const {
  StateWriter w;
  w.out.append(kStateMagic, sizeof kStateMagic);
  w.Put<std::uint64_t>(next_event);
  w.PutVector(inflow_on);
  w.PutVector(inflow_before);
  w.PutVector(inflow_since);
  w.PutVector(placed);
  w.PutVector(next_try_s);
  for (const std::mt19937_64& r : rng) {
    std::ostringstream text;
    text << r;
    w.PutString(text.str());
  }
  w.PutVector(exit_open);
  w.PutVector(exit_count);
  w.PutVector(group_target);
  w.PutVector(group_speed);
  w.PutVector(group_gamma);
  w.PutVector(group_lambda);
  w.Put(removed);
  w.Put(fallen);
  return w.out;
}

void TimelineState::LoadState(const std::string& state) {
  StateReader r(state, "the run's timeline");
  r.Need(sizeof kStateMagic);
  if (state.compare(0, sizeof kStateMagic, std::string(kStateMagicInflowByInflow, sizeof kStateMagic)) == 0)
    throw InputError("the timeline's state was written by an earlier build of crowdrecon, which numbered the arrivals "
                     "inflow by inflow (this one numbers them by the time they are due): the run cannot be resumed "
                     "by this build; run it again without --resume, or resume it with the build that began it");
  if (state.compare(0, sizeof kStateMagic, std::string(kStateMagic, sizeof kStateMagic)) != 0) r.Fail();
  for (std::size_t i = 0; i < sizeof kStateMagic; ++i) r.Get<char>();
  const std::size_t inflows = spec.inflows.size(), exits = scenario.venue.exits.size(), groups = spec.groups.size();
  next_event = r.Get<std::uint64_t>();
  inflow_on = r.GetVector<std::uint8_t>(inflows);
  inflow_before = r.GetVector<double>(inflows);
  inflow_since = r.GetVector<double>(inflows);
  placed = r.GetVector<std::uint64_t>(inflows);
  next_try_s = r.GetVector<double>(inflows);
  for (std::mt19937_64& g : rng) {
    std::istringstream text(r.GetString());
    text >> g;
    if (!text) r.Fail();
  }
  exit_open = r.GetVector<std::uint8_t>(exits);
  exit_count = r.GetVector<std::uint64_t>(exits);
  group_target = r.GetVector<std::int64_t>(groups);
  group_speed = r.GetVector<double>(groups);
  group_gamma = r.GetVector<double>(groups);
  group_lambda = r.GetVector<double>(groups);
  removed = r.Get<std::uint64_t>();
  fallen = r.Get<std::uint64_t>();
  if (!r.AtEnd() || next_event > spec.events.size()) r.Fail();
  for (std::size_t f = 0; f < inflows; ++f)
    if (placed[f] > built.arrivals[f].size()) r.Fail();
}

void ApplyEventToModel(const TimelineEvent& e, engine::ModelParameters* p) {
  if (e.kind != TimelineEvent::Kind::kSetParameters || !e.group.empty()) return;
  bool wall_given = false;
  for (const auto& [name, value] : e.parameters) wall_given = wall_given || name == "wall_restitution";
  for (const auto& [name, value] : e.parameters)
    if (const engine::ParameterInfo* info = engine::FindModelParameter(name)) {
      p->*(info->number) = value;
      if (name == "restitution" && !wall_given) p->wall_restitution = value;
    }
}

std::unique_ptr<RunSystem> MakeTimelineEventSystem(TimelineState& s) { return std::make_unique<TimelineEventSystem>(s); }
void SlotHolders(const engine::BodyState& bodies, std::vector<std::uint32_t>* holders) {
  *holders = bodies.id;
  for (std::size_t i = 0; i < holders->size(); ++i)
    if (bodies.state[i] == engine::PersonState::kRemoved) (*holders)[i] = kNoOne;
}

std::unique_ptr<RunSystem> MakeInflowSystem(TimelineState& s) { return std::make_unique<InflowSystem>(s); }
std::unique_ptr<RunSystem> MakeExitSystem(TimelineState& s) { return std::make_unique<ExitSystem>(s); }
std::unique_ptr<RunSystem> MakeFallSystem(TimelineState& s) { return std::make_unique<FallSystem>(s); }
std::unique_ptr<RunSystem> MakeAvalancheSystem(TimelineState& s) { return std::make_unique<AvalancheSystem>(s); }
std::unique_ptr<RunSystem> MakeLeftSystem(TimelineState& s) { return std::make_unique<LeftSystem>(s); }

void OpenDoorsAtStart(engine::Simulation& sim, const TimelineState& s) {
  for (std::size_t x = 0; x < s.exit_open.size(); ++x)
    sim.SetWallEnabled(s.built.exit_wall[x], s.exit_open[x] == 0);
}

}  // namespace crowdrecon::scenario::detail
