// Pre-movement times (premovement.hpp).
#include "premovement.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::scenario::detail {

namespace {

// As the timeline's events: a time reached within rounding of the clock.
constexpr double kTolerance_s = 1e-9;

class PremovementSystem : public RunSystem {
 public:
  PremovementSystem(TimelineState& s, const BuiltWorld& built, std::vector<double> times)
      : s_(s), times_(std::move(times)), order_(times_.size()) {
    for (std::size_t i = 0; i < times_.size(); ++i) own_speed_.push_back(built.world.people[i].desired_speed_m_per_s);
    std::iota(order_.begin(), order_.end(), std::size_t{0});
    std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return times_[a] < times_[b]; });
  }
  std::string_view name() const override { return "premovement"; }
  bool acts_every_step() const override { return true; }
  void BeforeStep(engine::Simulation& sim) override {
    const double t = sim.time_s();
    while (next_ < order_.size() && times_[order_[next_]] <= t + kTolerance_s) {
      const std::size_t p = order_[next_++];
      const std::string what = "pre-movement time " + FormatNumber(times_[p]) + " s";
      // A person who left or fell before their time (pushed out, felled)
      // keeps what they are; the event says so.
      if (sim.bodies().state[p] != engine::PersonState::kWalking) {
        s_.Event(t, "start", static_cast<std::int64_t>(p),
                 what + "; not walking then (" +
                     (sim.bodies().state[p] == engine::PersonState::kFallen ? "fallen" : "left the venue") + ")");
        continue;
      }
      const std::uint32_t group = sim.bodies().group[p];
      const double group_speed = group < s_.group_speed.size() ? s_.group_speed[group] : std::nan("");
      sim.SetDesiredSpeed(static_cast<std::uint32_t>(p), std::isnan(group_speed) ? own_speed_[p] : group_speed);
      s_.Event(t, "start", static_cast<std::int64_t>(p), what);
    }
  }
  std::string SaveState() const override { return std::to_string(next_); }
  void LoadState(const std::string& state) override {
    std::size_t n = 0;
    try {
      n = std::stoull(state);
    } catch (const std::exception&) {
      throw InputError("premovement state \"" + state.substr(0, 40) + "\": expected a count");
    }
    if (n > order_.size())
      throw InputError("premovement state " + state + ": more people started than the " + std::to_string(order_.size()) +
                       " of the start");
    next_ = n;
  }

 private:
  TimelineState& s_;
  std::vector<double> times_;
  std::vector<double> own_speed_;
  std::vector<std::size_t> order_;  // people by time, ties by id
  std::size_t next_ = 0;            // checkpointed: people started so far
};

}  // namespace

std::vector<double> PremovementTimes(const Scenario& scenario, std::size_t initial_people) {
  const PremovementSpec& p = scenario.timeline.premovement;
  if (!p.enabled) return {};
  if (!p.times_s.empty()) {
    if (p.times_s.size() != initial_people)
      throw InputError(scenario.file.string() + ": " + p.where + "/times_s: " + std::to_string(p.times_s.size()) +
                       " times for " + std::to_string(initial_people) +
                       " people of the start; expected one per person of the start, in id order");
    return p.times_s;
  }
  // A stream of its own, apart from the bodies', placements' and inflows'.
  std::mt19937_64 rng(scenario.population.seed ^ 0x9e3779b97f4a7c15ull);
  std::vector<double> times(initial_people);
  const bool uniform = p.distribution.kind == Distribution::Kind::kUniform;
  for (double& t : times) {
    // [0, 1), the same on every standard library; for the shapes with a tail
    // the middle of its 2^-53 interval, in (0, 1): never a time of 0.
    const double u = (double(rng() >> 11) + (uniform ? 0.0 : 0.5)) * 0x1.0p-53;
    t = std::min(p.distribution.Quantile(u), 1e6);
  }
  return times;
}

void HoldUntilPremovement(engine::Simulation& sim, const std::vector<double>& times) {
  for (std::size_t i = 0; i < times.size(); ++i)
    if (times[i] > kTolerance_s) sim.SetDesiredSpeed(static_cast<std::uint32_t>(i), 0.0);
}

std::unique_ptr<RunSystem> MakePremovementSystem(TimelineState& state, const BuiltWorld& built, std::vector<double> times) {
  return std::make_unique<PremovementSystem>(state, built, std::move(times));
}

}  // namespace crowdrecon::scenario::detail
