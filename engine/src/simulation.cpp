// Simulation: construction and validation of a world, the step as a
// sequence of stages (each stage in engine/src/stage_*.cpp, listed in
// engine/include/crowdrecon/engine/stages.hpp), person events and
// diagnostics. Checkpoints are in checkpoint.cpp.
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

// ---------------------------------------------------------------------------
// Construction and validation

bool CudaAvailable(std::string* why) { return cuda::Available(why); }

void Simulation::SetThreads(int threads) {
  if (threads < 1 || threads > 1024)
    throw InputError("threads = " + std::to_string(threads) + ", expected 1..1024");
  def_.threads = threads;
}

namespace {

// The world is usable: parameters in their ranges, every index in range,
// finite positions, walls of distinct points, a box with extent. Fills each
// shape's core radius.
void ValidateWorld(WorldDef& def) {
  std::string error;
  if (!def.parameters.IsValid(&error)) throw InputError("model parameters: " + error);
  if (def.threads < 1 || def.threads > 1024)
    throw InputError("threads = " + std::to_string(def.threads) + ", expected 1..1024");
  for (std::size_t s = 0; s < def.shapes.size(); ++s) {
    BodyShape& shape = def.shapes[s];
    if (shape.vertices.empty() || shape.vertices.size() >= 32768 || !(shape.radius_m > 0))
      throw InputError("shape " + std::to_string(s) + ": needs 1..32767 vertices and a radius > 0");
    shape.core_radius_m = 0.0;
    for (const Vec2& v : shape.vertices) shape.core_radius_m = std::max(shape.core_radius_m, Length(v));
  }
  const std::size_t n = def.people.size();
  if (n >= (std::size_t{1} << 31)) throw InputError("too many people");
  for (std::size_t i = 0; i < n; ++i) {
    const PersonDef& p = def.people[i];
    const std::string who = "person " + std::to_string(i + 1);
    if (p.shape >= def.shapes.size()) throw InputError(who + ": shape index out of range");
    if (p.target >= def.targets.size()) throw InputError(who + ": target index out of range");
    if (!(p.mass_kg > 0) || !(p.inertia_kg_m2 > 0))
      throw InputError(who + ": mass and moment of inertia must be > 0");
    if (!std::isfinite(p.position_m.x) || !std::isfinite(p.position_m.y) || !std::isfinite(p.angle_rad))
      throw InputError(who + ": position and angle must be finite");
  }
  for (std::size_t w = 0; w < def.walls.size(); ++w) {
    const Wall& wall = def.walls[w];
    if (wall.points.size() < 2 || (wall.closed && wall.points.size() < 3) || !(wall.radius_m >= 0.0))
      throw InputError("wall " + std::to_string(w) + ": needs at least 2 points (3 if closed) and a radius >= 0");
    for (std::size_t k = 0; k + 1 < wall.points.size(); ++k)
      if (Length(wall.points[k + 1] - wall.points[k]) <= 0.0)
        throw InputError("wall " + std::to_string(w) + ": points " + std::to_string(k) + " and " +
                         std::to_string(k + 1) + " coincide");
  }
  const PeriodicBox& box = def.periodic;
  if ((box.x && !(box.max_m.x > box.min_m.x)) || (box.y && !(box.max_m.y > box.min_m.y)))
    throw InputError("periodic box: max must exceed min along periodic axes");
}

}  // namespace

Simulation::Simulation(WorldDef def) : def_(std::move(def)), in_(std::make_unique<Internals>()) {
  ValidateWorld(def_);
  LoadBodies();
  // The behaviour terms of the drive, with the state of the people as placed.
  in_->terms = ActiveTerms::For(def_.parameters, def_, nullptr);
  for (ActiveTerms::Active& t : in_->terms.terms) t.term->Start(bodies_);
  BuildShapeFamilies();
  BuildWalls();
  // The contact law's constants, the time step, the device, the forces at t = 0.
  in_->restitution_factor = RestitutionDampingFactor(def_.parameters.restitution);
  in_->wall_restitution_factor = RestitutionDampingFactor(def_.parameters.wall_restitution);

  dt_estimate_ = EstimateTimeStep(def_);
  if (const std::string unstable = TimeStepAboveLimit(def_.parameters.time_step_s, def_.parameters.integrator, dt_estimate_);
      !unstable.empty())
    throw InputError("time_step_s: " + unstable);
  dt_s_ = dt_estimate_.chosen_s;
  tick_s_ = dt_s_;
  next_dt_s_ = dt_s_;
  SetUpAdaptiveStep();
  SetUpSleeping();

  if (def_.device == ComputeDevice::kCuda)
    in_->cuda = std::make_unique<cuda::Collider>(in_->family_geometry, in_->shape_family, in_->shape_scale,
                                                 def_.periodic);
  ComputeForces();  // forces at t = 0 (no spring increment: contacts start unloaded)
  in_->previous_contacts = contacts_;
}

// Slot i's person: their state, body and identity (LoadBodies, Spawn).
void Simulation::LoadPerson(std::size_t i, const PersonDef& p, std::uint32_t id) {
  bodies_.position_m[i] = p.position_m;
  detail::Wrap(def_.periodic, bodies_.position_m[i]);
  bodies_.angle_rad[i] = p.angle_rad;
  bodies_.velocity_m_per_s[i] = p.velocity_m_per_s;
  bodies_.angular_velocity_rad_per_s[i] = p.angular_velocity_rad_per_s;
  bodies_.mass_kg[i] = p.mass_kg;
  bodies_.inertia_kg_m2[i] = p.inertia_kg_m2;
  bodies_.shape[i] = p.shape;
  bodies_.desired_speed_m_per_s[i] = p.desired_speed_m_per_s;
  bodies_.target[i] = p.target;
  bodies_.group[i] = p.group;
  bodies_.state[i] = p.state;
  bodies_.id[i] = id;
  const BodyShape& s = def_.shapes[p.shape];
  in_->bound_m[i] = s.core_radius_m + s.radius_m;
}

// The bodies' state from the people of the world, wrapped into the periodic box.
void Simulation::LoadBodies() {
  const std::size_t n = def_.people.size();
  bodies_.position_m.resize(n);
  bodies_.angle_rad.resize(n);
  bodies_.velocity_m_per_s.resize(n);
  bodies_.angular_velocity_rad_per_s.resize(n);
  bodies_.force_n.assign(n, {});
  bodies_.torque_n_m.assign(n, 0.0);
  bodies_.contact_force_n.assign(n, {});
  bodies_.external_force_n.assign(n, {});
  bodies_.contact_torque_n_m.assign(n, 0.0);
  bodies_.mass_kg.resize(n);
  bodies_.inertia_kg_m2.resize(n);
  bodies_.shape.resize(n);
  bodies_.desired_speed_m_per_s.resize(n);
  bodies_.target.resize(n);
  bodies_.group.resize(n);
  bodies_.state.resize(n);
  bodies_.id.resize(n);
  in_->bound_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) LoadPerson(i, def_.people[i], static_cast<std::uint32_t>(i));
  in_->cos_angle.assign(n, 1.0);
  in_->sin_angle.assign(n, 0.0);
  in_->travel_m.assign(n, 0.0);
  in_->field_cache.assign(n, {});
  in_->travel_position = bodies_.position_m;
  in_->travel_angle = bodies_.angle_rad;
}

void Simulation::BuildShapeFamilies() {
  const std::size_t n = def_.people.size();
  // Shape families (see Internals), each with a grid of candidate edges for
  // the largest reach it can meet: its member's radius plus the largest
  // radius of any shape or wall, over its smallest member. A shape joins a
  // family when its vertices over its radius match the family's to 1e-9
  // relative (a scaled copy, up to round-off); it is then simulated as the
  // family's outline at its own scale, a difference of the order of 1e-10 m.
  double radius_max = 0.0;
  for (const BodyShape& shape : def_.shapes) radius_max = std::max(radius_max, shape.radius_m);
  for (const Wall& wall : def_.walls) radius_max = std::max(radius_max, wall.radius_m);
  {
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> buckets;
    std::vector<double> smallest;
    std::vector<Vec2> unit;
    for (const BodyShape& shape : def_.shapes) {
      const double r = shape.radius_m;
      unit.clear();
      double extent = 0.0;
      for (const Vec2& v : shape.vertices) {
        unit.push_back(v / r);
        extent = std::max(extent, Length(unit.back()));
      }
      std::uint64_t key = 1469598103934665603ull ^ unit.size();
      for (const Vec2& u : unit)
        for (double x : {u.x, u.y}) key = (key ^ static_cast<std::uint64_t>(std::llround(x * 1e6))) * 1099511628211ull;
      const double tolerance = 1e-9 * (1.0 + extent);
      std::uint32_t family = UINT32_MAX;
      for (std::uint32_t f : buckets[key]) {
        const std::vector<Vec2>& fv = in_->family_geometry[f].vertices;
        if (fv.size() != unit.size()) continue;
        bool same = true;
        for (std::size_t k = 0; k < unit.size() && same; ++k) same = Length(unit[k] - fv[k]) <= tolerance;
        if (same) {
          family = f;
          break;
        }
      }
      if (family == UINT32_MAX) {
        family = static_cast<std::uint32_t>(in_->family_geometry.size());
        in_->family_geometry.push_back(ShapeGeometry::Make(unit, unit.size() >= 3, 1.0));
        smallest.push_back(r);
        buckets[key].push_back(family);
      }
      smallest[family] = std::min(smallest[family], r);
      in_->shape_family.push_back(family);
      in_->shape_scale.push_back(r);
    }
    for (std::size_t f = 0; f < in_->family_geometry.size(); ++f)
      in_->family_geometry[f].BuildEdgeGrid(1.0 + radius_max / smallest[f]);
  }
  in_->rotation_arm_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t shape = bodies_.shape[i];
    // The core the narrow phase places (the family's outline at this scale),
    // rounded up so that round-off never makes the bound too small.
    in_->rotation_arm_m[i] =
        in_->family_geometry[in_->shape_family[shape]].core_radius_m * in_->shape_scale[shape] * (1.0 + 1e-12);
  }
}

void Simulation::BuildWalls() {
  const PeriodicBox& box = def_.periodic;
  // Walls crossing a periodic boundary are extended beyond it, so that a body
  // straddling the seam meets a straight wall and never a wall's end cap.
  double bound_max = 0.0;
  for (double b : in_->bound_m) bound_max = std::max(bound_max, b);
  const double reach = 2.0 * bound_max + 2.0 * in_->skin_m;
  const auto extend = [&](Vec2& end, Vec2 other, bool axis_x) {
    const double c = axis_x ? end.x : end.y;
    const double lo = axis_x ? box.min_m.x : box.min_m.y, hi = axis_x ? box.max_m.x : box.max_m.y;
    if (std::abs(c - lo) > 1e-9 && std::abs(c - hi) > 1e-9) return;
    const Vec2 dir = Normalized(end - other);
    const double along = std::abs(axis_x ? dir.x : dir.y);
    if (along < 1e-6) return;  // runs along the boundary
    end += dir * (reach / along);
  };
  for (Wall& wall : def_.walls) {
    if (wall.closed) continue;
    for (int axis = 0; axis < 2; ++axis) {
      if (!(axis == 0 ? box.x : box.y)) continue;
      extend(wall.points.front(), wall.points[1], axis == 0);
      extend(wall.points.back(), wall.points[wall.points.size() - 2], axis == 0);
    }
  }
  in_->wall_origin.resize(def_.walls.size());
  for (std::size_t w = 0; w < def_.walls.size(); ++w) {
    const Wall& wall = def_.walls[w];
    in_->wall_geometry.push_back(ShapeGeometry::FromWorld(wall.points, wall.closed, wall.radius_m, in_->wall_origin[w]));
  }
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

// ---------------------------------------------------------------------------
// Periodic box

Vec2 Simulation::Separation(Vec2 a, Vec2 b) const { return detail::Separation(def_.periodic, a, b); }

// ---------------------------------------------------------------------------

// The force stages, in the order of stages.hpp.
void Simulation::ComputeForces() {
  UpdatePairs();
  PlaceShapes();
  Neighbours();
  Collide();
  Gather();
  Drive();
}

void Simulation::Step() {
  in_->previous_contacts.swap(contacts_);
  advance_springs_ = true;
  const std::uint64_t step_ticks = std::uint64_t{1} << level_;
  in_->drive_time_s = static_cast<double>(tick_count_ + step_ticks) * tick_s_;  // the forces are evaluated at the step's end
  if (def_.parameters.integrator == Integrator::kVelocityVerlet) {
    VerletKickDrift();
    if (max_level_ > 0) ChooseStep(tick_count_ + step_ticks);
    ComputeForces();
    VerletKick();
  } else {
    GearPredict();
    ComputeForces();
    GearCorrect();
  }
  tick_count_ += step_ticks;
  time_s_ = static_cast<double>(tick_count_) * tick_s_;
  ++step_count_;
  ++profile_.steps_at_level[static_cast<std::size_t>(level_)];
  last_step_ticks_ = step_ticks;
  in_->drive_time_s = time_s_;
  UpdateBehaviourTerms();  // (with the step just taken)
  level_ = next_level_;
  dt_s_ = next_dt_s_;
  Check();
  Sleep();
}

void Simulation::AdvanceTo(double end_time_s) {
  while (time_s_ < end_time_s - 1e-12) Step();
}

void Simulation::Quench() {
  std::fill(bodies_.velocity_m_per_s.begin(), bodies_.velocity_m_per_s.end(), Vec2{});
  std::fill(bodies_.angular_velocity_rad_per_s.begin(), bodies_.angular_velocity_rad_per_s.end(), 0.0);
  for (BehaviourTerm* t : in_->terms.stateful) t->Quench();
  in_->gear_initialised = false;
  WakeAll();
}

void Simulation::SetExternalForce(std::uint32_t person, Vec2 force_n) {
  if (person >= bodies_.size()) throw InputError("person index " + std::to_string(person) + " out of range");
  bodies_.external_force_n[person] = force_n;
  Wake(person);
  Drive();  // the force enters the current evaluation too
}

void Simulation::SetPersonState(std::uint32_t person, PersonState state) {
  if (person >= bodies_.size()) throw InputError("person index " + std::to_string(person) + " out of range");
  const PersonState before = bodies_.state[person];
  bodies_.state[person] = state;
  Wake(person);
  if (state != PersonState::kWalking) {
    bodies_.velocity_m_per_s[person] = {};
    bodies_.angular_velocity_rad_per_s[person] = 0.0;
    for (BehaviourTerm* t : in_->terms.stateful) t->Stop(person);
  }
  if (state == PersonState::kRemoved) {
    // No forces on an empty slot (the stages skip it), and their contacts go
    // with them: the next step's springs start without them, and a frame
    // written now lists no contact with someone absent.
    bodies_.force_n[person] = {};
    bodies_.torque_n_m[person] = 0.0;
    bodies_.contact_force_n[person] = {};
    bodies_.contact_torque_n_m[person] = 0.0;
    std::erase_if(contacts_, [person](const Contact& c) { return c.a == person || (!c.wall && c.b == person); });
    in_->cuda_has_history = false;
  }
  // The neighbour lists stay valid unless an empty slot comes back: a removed
  // person's pairs are skipped by the collide stage (and dropped at the next
  // rebuild), a fallen one stays where they are, and which step rebuilds the
  // lists changes no result (their pair clearances only skip pairs that have
  // no contact). A rebuild here forgot every pair's clearance, so the step
  // after each exit measured every pair afresh: in the evacuation, whose
  // people leave about 60 times a second, one step in 31.
  if (before == PersonState::kRemoved) in_->pairs_valid = false;
  if (before == PersonState::kRemoved && state != PersonState::kRemoved) ListComebacks();
}

// ---------------------------------------------------------------------------
// The incident timeline's changes (between steps)

// The world as it is now (every slot's body, whoever holds it) with other
// parameters: for the time-step estimate of a change.
WorldDef Simulation::ProbeWorld(const ModelParameters& parameters) const {
  WorldDef probe;
  probe.parameters = parameters;
  probe.shapes = def_.shapes;
  probe.people.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    probe.people[i].shape = bodies_.shape[i];
    probe.people[i].mass_kg = bodies_.mass_kg[i];
    probe.people[i].inertia_kg_m2 = bodies_.inertia_kg_m2[i];
  }
  return probe;
}

void Simulation::Spawn(std::uint32_t slot, const PersonDef& p, std::uint32_t id) {
  if (slot >= bodies_.size()) throw InputError("slot " + std::to_string(slot) + " out of range");
  if (bodies_.state[slot] != PersonState::kRemoved)
    throw InputError("slot " + std::to_string(slot) + " is taken (" + PersonText(bodies_, slot) + " is in the venue)");
  if (p.shape >= def_.shapes.size() || p.target >= def_.targets.size() || !(p.mass_kg > 0) ||
      !(p.inertia_kg_m2 > 0) || !std::isfinite(p.position_m.x) || !std::isfinite(p.position_m.y) ||
      !std::isfinite(p.angle_rad) || p.state != PersonState::kWalking)
    throw InputError("spawn into slot " + std::to_string(slot) + ": an invalid person (shape, target, mass or pose)");
  {
    WorldDef probe;
    probe.parameters = def_.parameters;
    probe.shapes = {def_.shapes[p.shape]};
    probe.people = {p};
    probe.people[0].shape = 0;
    if (const TimeStepEstimate e = EstimateTimeStep(probe); LargestStep() > e.stability_limit_s)
      throw InputError("spawn into slot " + std::to_string(slot) + ": this person (" + FormatNumber(p.mass_kg) +
                       " kg) needs a time step below " + FormatNumber(e.stability_limit_s) + " s, the run's is " +
                       FormatNumber(LargestStep()) + " s (choose the step for every arrival)");
  }
  LoadPerson(slot, p, id);
  Wake(slot);
  bodies_.force_n[slot] = {};
  bodies_.torque_n_m[slot] = 0.0;
  bodies_.contact_force_n[slot] = {};
  bodies_.contact_torque_n_m[slot] = 0.0;
  bodies_.external_force_n[slot] = {};
  Internals& in = *in_;
  in.rotation_arm_m[slot] =
      in.family_geometry[in.shape_family[p.shape]].core_radius_m * in.shape_scale[p.shape] * (1.0 + 1e-12);
  in.cos_angle[slot] = std::cos(p.angle_rad);
  in.sin_angle[slot] = std::sin(p.angle_rad);
  in.travel_m[slot] = 0.0;
  in.travel_position[slot] = bodies_.position_m[slot];
  in.travel_angle[slot] = p.angle_rad;
  if (slot < in.leading_force.size()) in.leading_force[slot] = {};
  if (slot < in.trailing_force.size()) in.trailing_force[slot] = {};
  if (slot < in.leading_torque.size()) in.leading_torque[slot] = 0.0;
  if (slot < in.trailing_torque.size()) in.trailing_torque[slot] = 0.0;
  if (slot < in.gear_xy.size()) in.gear_xy[slot] = {};
  if (slot < in.gear_theta.size()) in.gear_theta[slot] = {};
  for (BehaviourTerm* t : in.terms.stateful) t->Place(slot, bodies_);
  in.pairs_valid = false;
  in.cuda_has_history = false;
  ListComebacks();
  Drive();  // the newcomer's own forces enter the current evaluation (the others' are unchanged)
}

bool Simulation::IsFree(std::uint32_t shape, Vec2 position_m, double angle_rad, double clearance_m) const {
  if (shape >= def_.shapes.size()) throw InputError("shape index " + std::to_string(shape) + " out of range");
  const Internals& in = *in_;
  const PlacedShape me = in.ShapeAt(shape, position_m, std::cos(angle_rad), std::sin(angle_rad));
  std::vector<ContactPoint> hits;
  for (std::size_t w = 0; w < in.wall_geometry.size(); ++w) {
    if (!WallEnabled(static_cast<std::uint32_t>(w))) continue;
    PlacedShape wall;
    wall.geometry = &in.wall_geometry[w];
    wall.position = in.wall_origin[w];
    if (CollideShapes(me, wall, hits) < clearance_m || !hits.empty()) return false;
  }
  const BodyShape& mine = def_.shapes[shape];
  const double my_bound = mine.core_radius_m + mine.radius_m;
  for (std::size_t j = 0; j < bodies_.size(); ++j) {
    if (bodies_.state[j] == PersonState::kRemoved) continue;
    const Vec2 separation = Separation(position_m, bodies_.position_m[j]);
    const double reach = my_bound + in.bound_m[j] + clearance_m;
    if (LengthSquared(separation) >= reach * reach) continue;
    // The image nearest to the candidate, at the angle it has now.
    const PlacedShape other = in.ShapeAt(bodies_.shape[j], position_m - separation, std::cos(bodies_.angle_rad[j]),
                                         std::sin(bodies_.angle_rad[j]));
    if (CollideShapes(me, other, hits) < clearance_m || !hits.empty()) return false;
  }
  return true;
}

void Simulation::SetTarget(std::uint32_t person, std::uint32_t target) {
  if (person >= bodies_.size() || target >= def_.targets.size())
    throw InputError("person " + std::to_string(person) + " or target " + std::to_string(target) + " out of range");
  bodies_.target[person] = target;
  Wake(person);
  Drive();
}

void Simulation::SetDesiredSpeed(std::uint32_t person, double speed_m_per_s) {
  if (person >= bodies_.size() || !(speed_m_per_s >= 0.0) || !std::isfinite(speed_m_per_s))
    throw InputError("person " + std::to_string(person) + ": desired speed " + FormatNumber(speed_m_per_s) +
                     " m/s; expected a person in range and a finite speed >= 0");
  bodies_.desired_speed_m_per_s[person] = speed_m_per_s;
  Wake(person);
  Drive();
}

void Simulation::SetParameters(const ModelParameters& parameters) {
  std::string error;
  if (!parameters.IsValid(&error)) throw InputError("model parameters: " + error);
  ModelParameters p = parameters;
  p.time_step_s = def_.parameters.time_step_s;
  if (p.integrator != def_.parameters.integrator || p.back_force_trigger != def_.parameters.back_force_trigger ||
      p.tangential_spring != def_.parameters.tangential_spring || p.time_step_mode != def_.parameters.time_step_mode ||
      p.time_step_safety != def_.parameters.time_step_safety ||
      p.adaptive_max_safety != def_.parameters.adaptive_max_safety ||
      p.adaptive_reference_speed_m_per_s != def_.parameters.adaptive_reference_speed_m_per_s)
    throw InputError("model parameters: the integrator, the back force's trigger, the tangential spring and the "
                     "time step's settings are fixed for a run; only the model's numbers may change during it");
  const TimeStepEstimate estimate = EstimateTimeStep(ProbeWorld(p));
  if (LargestStep() > estimate.stability_limit_s)
    throw InputError("model parameters: the run's time step " + FormatNumber(LargestStep()) +
                     " s is above the stability limit " + FormatNumber(estimate.stability_limit_s) +
                     " s of the new parameters (limited by " + estimate.limited_by + ")");
  ActiveTerms terms = ActiveTerms::For(p, def_, &in_->terms);  // (refuses a term with state switched on or off)
  in_->terms = std::move(terms);
  def_.parameters = p;
  in_->restitution_factor = RestitutionDampingFactor(p.restitution);
  in_->wall_restitution_factor = RestitutionDampingFactor(p.wall_restitution);
  if (max_level_ > 0)  // the restitution errors at each level for the new parameters (the levels stay)
    level_speed_ = AdaptiveLevelSpeeds(def_, tick_s_, max_level_, reference_speed_m_per_s_);
  SetUpSleeping();  // (everyone awake: everyone's drive is another now)
  Drive();
}

void Simulation::SetWallEnabled(std::uint32_t wall, bool enabled) {
  if (wall >= def_.walls.size()) throw InputError("wall " + std::to_string(wall) + " out of range");
  if (WallEnabled(wall) == enabled) return;
  if (wall_enabled_.empty()) wall_enabled_.assign(def_.walls.size(), 1);
  wall_enabled_[wall] = enabled ? 1 : 0;
  WakeAll();  // (a sleeper's contacts with walls are carried)
  if (!enabled) std::erase_if(contacts_, [wall](const Contact& c) { return c.wall && c.b == wall; });
  in_->pairs_valid = false;
  if (step_count_ == 0) {  // the forces at t = 0 as the constructor computes them, with this wall as it is now
    ComputeForces();
    in_->previous_contacts = contacts_;
  }
}

void Simulation::SetGroupDrive(std::uint32_t group, double back_force_gamma, double torsion_stiffness_lambda) {
  if (group > 1023) throw InputError("group " + std::to_string(group) + " out of range (0..1023)");
  const auto bad = [](double x) { return !std::isnan(x) && !(x >= 0.0 && x <= 1e6); };
  if (bad(back_force_gamma) || bad(torsion_stiffness_lambda))
    throw InputError("group " + std::to_string(group) + ": back force or torsion stiffness out of range");
  Internals& in = *in_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (in.group_gamma.size() <= group) {
    in.group_gamma.resize(group + 1, nan);
    in.group_lambda.resize(group + 1, nan);
  }
  in.group_gamma[group] = back_force_gamma;
  in.group_lambda[group] = torsion_stiffness_lambda;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.group[i] == group) Wake(i);
  if (!std::isnan(torsion_stiffness_lambda)) {
    ModelParameters p = def_.parameters;
    p.torsion_stiffness_lambda = torsion_stiffness_lambda;
    if (LargestStep() > EstimateTimeStep(ProbeWorld(p)).stability_limit_s) {
      in.group_lambda[group] = nan;
      throw InputError("group " + std::to_string(group) + ": torsion stiffness " + FormatNumber(torsion_stiffness_lambda) +
                       " needs a shorter time step than the run's " + FormatNumber(LargestStep()) + " s");
    }
  }
  Drive();
}

Vec2 Simulation::LinearMomentum() const {
  Vec2 p;
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.state[i] == PersonState::kWalking) p += bodies_.velocity_m_per_s[i] * bodies_.mass_kg[i];
  return p;
}

double Simulation::AngularMomentum() const {
  double l = 0.0;
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.state[i] == PersonState::kWalking)
      l += bodies_.mass_kg[i] * Cross(bodies_.position_m[i], bodies_.velocity_m_per_s[i]) +
           bodies_.inertia_kg_m2[i] * bodies_.angular_velocity_rad_per_s[i];
  return l;
}

double Simulation::KineticEnergy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < bodies_.size(); ++i)
    if (bodies_.state[i] == PersonState::kWalking)
      e += 0.5 * bodies_.mass_kg[i] * LengthSquared(bodies_.velocity_m_per_s[i]) +
           0.5 * bodies_.inertia_kg_m2[i] * bodies_.angular_velocity_rad_per_s[i] * bodies_.angular_velocity_rad_per_s[i];
  return e;
}

double Simulation::ElasticEnergy() const {
  const double kn = def_.parameters.normal_stiffness_n_per_m, kt = def_.parameters.tangential_stiffness_n_per_m;
  double e = 0.0;
  for (const Contact& c : contacts_)
    e += 0.5 * kn * c.overlap_m * c.overlap_m + 0.5 * kt * c.tangential_spring_m * c.tangential_spring_m;
  return e;
}


}  // namespace crowdrecon::engine
