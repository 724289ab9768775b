// The list of behaviour terms (engine/src/behaviour.hpp): one line per term,
// in the order the drive asks them within each phase. A new term is a file
// of its own in this folder (defining Make<Name>) plus its line here.
#include <algorithm>
#include <cmath>
#include <string>

#include "../behaviour.hpp"
#include "crowdrecon/common/error.hpp"

// X(name in checkpoints, Make function, one line on what it adds)
#define CROWDRECON_BEHAVIOUR_TERMS(X)                                                                                \
  X("giving_way", MakeGivingWay, "a blocked person with room to turn walks the way of those they meet (issue 39)")  \
  X("yielding", MakeYielding, "a person held up by people ahead drives toward a share of v0 (issue 39)")            \
  X("reaction_time", MakeReactionTime, "eq. (3) relaxes from a lagged, perceived velocity (issue 39)")              \
  X("desired_velocity", MakeDesiredVelocity, "the self-driven force m (v0 e - v) / tau, eq. (3)")                  \
  X("gait_jitter", MakeGaitJitter, "the desired velocity plus a random sway of the gait (issue 39)")               \
  X("back_force", MakeBackForce, "the back force Gamma m v0 / tau (e + e x k) when pushed back, eq. (15)")        \
  X("motive_torque", MakeMotiveTorque, "the motive torque lambda I / tau^2 g (theta_D - theta), eq. (16)")        \
  X("shoulder_turn", MakeShoulderTurn, "a person held up by people ahead turns a shoulder into the way (issue 39)") \
  X("rotational_damping", MakeRotationalDamping, "the rotational damping -I omega / tau_r, eq. (17)")             \
  X("floor_slope", MakeFloorSlope, "a sloping floor pulls people, or their legs hold it and their pace follows the grade (issue 43)") \
  X("headway", MakeHeadway, "keeping a distance: e turned away from near people, v0 capped by the headway (issue 64)") \
  X("social_force", MakeSocialForce, "keeping a distance: the social force's repulsion from people near (issue 64)") \
  X("centrifugal", MakeCentrifugal, "keeping a distance: the generalized centrifugal force from people ahead (issue 64)") \
  X("anticipation", MakeAnticipation, "anticipating: the time-to-collision force off collision courses (issue 64)")

namespace crowdrecon::engine::detail {

#define CROWDRECON_DECLARE_TERM(name, make, summary) std::unique_ptr<BehaviourTerm> make(const ModelParameters&, const WorldDef&);
CROWDRECON_BEHAVIOUR_TERMS(CROWDRECON_DECLARE_TERM)
#undef CROWDRECON_DECLARE_TERM

const std::vector<TermEntry>& BehaviourTermList() {
#define CROWDRECON_LIST_TERM(name, make, summary) TermEntry{name, summary, &make},
  static const std::vector<TermEntry> list{CROWDRECON_BEHAVIOUR_TERMS(CROWDRECON_LIST_TERM)};
#undef CROWDRECON_LIST_TERM
  return list;
}

ActiveTerms ActiveTerms::For(const ModelParameters& parameters, const WorldDef& def, ActiveTerms* previous) {
  const std::vector<TermEntry>& list = BehaviourTermList();
  // Every entry's term for `def`, and the one `previous` has: all checked
  // before any state is handed over (a refusal leaves `previous` as it was).
  std::vector<std::unique_ptr<BehaviourTerm>> made(list.size());
  std::vector<Active*> before(list.size(), nullptr);
  for (std::size_t t = 0; t < list.size(); ++t) {
    made[t] = list[t].make(parameters, def);
    if (previous != nullptr)
      for (Active& p : previous->terms)
        if (p.entry == &list[t]) before[t] = &p;
    const std::uint32_t state_before = before[t] != nullptr ? before[t]->term->state_version() : 0;
    const std::uint32_t state_now = made[t] != nullptr ? made[t]->state_version() : 0;
    if (previous != nullptr && state_before != state_now)
      throw InputError(std::string("model parameters: they would switch the behaviour term ") + list[t].name +
                       (state_now != 0 ? " on" : " off") +
                       ", whose per-person state starts with the run; it is fixed for a run (only the model's numbers "
                       "may change during it)");
  }
  ActiveTerms a;
  for (std::size_t t = 0; t < list.size(); ++t) {
    if (made[t] == nullptr) continue;
    // A term with state keeps it (the same object); a stateless one is the new one.
    if (made[t]->state_version() != 0 && before[t] != nullptr) {
      made[t] = std::move(before[t]->term);
      made[t]->Retune(parameters);
    }
    a.terms.push_back({&list[t], std::move(made[t])});
  }
  for (Active& t : a.terms) {
    BehaviourTerm* term = t.term.get();
    const unsigned phases = term->phases();
    if (phases & BehaviourTerm::kDirection) a.direction.push_back(term);
    if (phases & BehaviourTerm::kPrepare) a.prepare.push_back(term);
    if (phases & BehaviourTerm::kSteer) a.steer.push_back(term);
    if (phases & BehaviourTerm::kDesire) a.desire.push_back(term);
    if (phases & BehaviourTerm::kFacing) a.facing.push_back(term);
    if (phases & BehaviourTerm::kForce) a.force.push_back(term);
    if (phases & BehaviourTerm::kAfterStep) a.after_step.push_back(term);
    if (term->state_version() != 0) {
      a.stateful.push_back(term);
      a.stateful_names.push_back(t.entry->name);
    }
    a.people_ahead = a.people_ahead || term->needs_people_ahead();
    a.neighbour_radius_m = std::max(a.neighbour_radius_m, term->neighbour_radius_m());
    a.near_radius_m = std::max(a.near_radius_m, term->near_radius_m());
  }
  return a;
}

void DesiredDirections(const BodyState& bodies, const WorldDef& def,
                       std::vector<geometry::NavigationField::CellCache>& field_cache, std::vector<Vec2>& desired) {
  desired.assign(bodies.size(), Vec2{});
  for (std::size_t i = 0; i < bodies.size(); ++i)
    if (bodies.state[i] == PersonState::kWalking)
      desired[i] = def.targets[bodies.target[i]].Direction(bodies.position_m[i], field_cache[i]);
}

namespace {
bool IsFinite(double x) { return std::isfinite(x); }
bool IsFinite(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

template <typename T>
void GetChecked(BinaryReader& r, std::vector<T>& values, std::size_t people, const char* what) {
  r.GetVector(values, people);
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!IsFinite(values[i]))
      throw InputError(std::string("checkpoint: damaged state: ") + what + " of slot " + std::to_string(i) +
                       " is not a finite number");
}
}  // namespace

void GetTermVector(BinaryReader& r, std::vector<double>& values, std::size_t people, const char* what) {
  GetChecked(r, values, people, what);
}
void GetTermVector(BinaryReader& r, std::vector<Vec2>& values, std::size_t people, const char* what) {
  GetChecked(r, values, people, what);
}

}  // namespace crowdrecon::engine::detail
