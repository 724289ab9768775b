// Term giving_way (ModelParameters::give_way = where_room; issue 39, candidate
// b, off by default): a person blocked for a while who has room to turn and
// meets mostly people heading the other way walks their way for a while.
//
// After each step, in one serial pass (the same on any thread count; its
// state is in the checkpoint), per walking person: the velocity along e_i
// averaged over 1 s (the exact update of du/dt = (e.v - u)/T), the time it
// has stayed below give_way_speed_m_per_s, and, once that time reaches
// give_way_blocked_s, whether to give way: touching at most
// give_way_max_contacts people (room to turn) whose desired directions sum
// against e_i. Then, in the direction phase, the person heads that way for
// give_way_duration_s, and starts afresh.
#include <algorithm>
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class GivingWay final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kDirection | kAfterStep; }

  void Direction(const DriveInputs&, DriveBlock& b) const override {
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k] && left_s_[b.first + k] > 0.0) b.direction[k] = direction_[b.first + k];
  }

  void AfterStep(const StepInputs& in) override {
    const ModelParameters& mp = in.def.parameters;
    const BodyState& bodies = in.bodies;
    const std::size_t n = bodies.size();
    // Each walking person's own desired direction, then, per person, the
    // people they touch and the sum of those people's directions.
    DesiredDirections(bodies, in.def, in.field_cache, desired_);
    touching_.assign(n, 0);
    their_way_.assign(n, Vec2{});
    std::uint32_t last_a = UINT32_MAX, last_b = UINT32_MAX;
    for (const Contact& c : in.contacts) {
      if (c.wall || (c.a == last_a && c.b == last_b)) continue;  // a pair once, whatever its features
      last_a = c.a;
      last_b = c.b;
      ++touching_[c.a];
      ++touching_[c.b];
      their_way_[c.a] += desired_[c.b];
      their_way_[c.b] += desired_[c.a];
    }
    const double h = in.step_s;
    const double a = -std::expm1(-h / 1.0);  // averaged over 1 s
    for (std::size_t i = 0; i < n; ++i) {
      if (bodies.state[i] != PersonState::kWalking) continue;
      const Vec2 e = desired_[i];
      along_[i] += a * (Dot(e, bodies.velocity_m_per_s[i]) - along_[i]);
      if (left_s_[i] > 0.0) {
        left_s_[i] = std::max(0.0, left_s_[i] - h);
        continue;
      }
      blocked_s_[i] = along_[i] < mp.give_way_speed_m_per_s ? blocked_s_[i] + h : 0.0;
      if (blocked_s_[i] < mp.give_way_blocked_s) continue;
      const Vec2 way = their_way_[i];
      if (touching_[i] > static_cast<int>(mp.give_way_max_contacts) || !(Dot(way, e) < 0.0)) continue;
      direction_[i] = way * (1.0 / Length(way));
      left_s_[i] = mp.give_way_duration_s;
      blocked_s_[i] = 0.0;
    }
  }

  std::uint32_t state_version() const override { return 1; }
  void Start(const BodyState& bodies) override {
    const std::size_t n = bodies.size();
    along_.assign(n, 0.0);
    blocked_s_.assign(n, 0.0);
    left_s_.assign(n, 0.0);
    direction_.assign(n, Vec2{});
  }
  void Place(std::size_t slot, const BodyState&) override {
    along_[slot] = 0.0;
    blocked_s_[slot] = 0.0;
    left_s_[slot] = 0.0;
    direction_[slot] = {};
  }
  void Save(BinaryWriter& w) const override {
    w.PutVector(along_);
    w.PutVector(blocked_s_);
    w.PutVector(left_s_);
    w.PutVector(direction_);
  }
  void Load(BinaryReader& r, std::size_t people) override {
    GetTermVector(r, along_, people, "give-way velocity");
    GetTermVector(r, blocked_s_, people, "give-way blocked time");
    GetTermVector(r, left_s_, people, "give-way time left");
    GetTermVector(r, direction_, people, "give-way direction");
  }

 private:
  // Per person: the velocity along e_i averaged over 1 s, how long it has
  // been below the threshold, how long they still give way, and the way.
  std::vector<double> along_, blocked_s_, left_s_;
  std::vector<Vec2> direction_;
  // AfterStep's scratch (derived each step, not in the checkpoint).
  std::vector<Vec2> desired_;
  std::vector<int> touching_;
  std::vector<Vec2> their_way_;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeGivingWay(const ModelParameters& p, const WorldDef&) {
  if (p.give_way != GiveWay::kWhereRoom) return nullptr;
  return std::make_unique<GivingWay>();
}

}  // namespace crowdrecon::engine::detail
