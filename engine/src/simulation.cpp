#include "crowdrecon/engine/simulation.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <type_traits>
#include <unordered_map>

#include "binary_io.hpp"
#include "contact_law.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fast_math.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "cuda_collide.hpp"
#include "gather_core.hpp"
#include "minimum_image.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

namespace {

using detail::ContactHistory;
using detail::ContactLaw;

constexpr double kPi = std::numbers::pi;
// Pairs per work chunk. Chunks are fixed by the pair list, not by the thread
// count, and their outputs are concatenated in order: determinism by construction.
constexpr std::size_t kChunk = 64;
// Below this many people the per-body stages run on one thread (the results
// are the same either way; only the overhead differs).
constexpr std::int64_t kParallelBodies = 512;

using Clock = std::chrono::steady_clock;

// Part q of `parts` contiguous, nearly equal parts of [0, count): the work a
// stage splits between threads in a fixed way (the results then do not
// depend on which thread takes which part).
struct Part {
  std::size_t begin, end;
};
Part PartOf(std::size_t count, std::size_t q, std::size_t parts) { return {count * q / parts, count * (q + 1) / parts}; }

// The clearances of one pair list (person pairs, or person-wall pairs): per
// pair, the travel sum below which it is still apart, and per vertex of its
// two shapes the same (VertexClearances), pair k's vertices at
// vertex_start[k], the first shape's then the second's. See Internals.
struct PairClearances {
  std::vector<double> pair_m;
  std::vector<std::size_t> vertex_start;
  std::vector<double> vertex_m;

  // For a new list: nothing known. `vertices(k)` = the vertex count of both shapes of pair k.
  // The vertex entries (several megabytes for 10,000 people) are filled by
  // `threads` threads.
  template <typename VertexCount>
  void Reset(std::size_t pairs, VertexCount vertices, int threads) {
    constexpr double kNever = -std::numeric_limits<double>::infinity();
    pair_m.assign(pairs, kNever);
    vertex_start.resize(pairs + 1);
    vertex_start[0] = 0;
    for (std::size_t k = 0; k < pairs; ++k) vertex_start[k + 1] = vertex_start[k] + vertices(k);
    vertex_m.resize(vertex_start.back());
    const std::int64_t count = static_cast<std::int64_t>(vertex_m.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (count >= 65536)
    for (std::int64_t v = 0; v < count; ++v) vertex_m[static_cast<std::size_t>(v)] = kNever;
  }

  // Narrow phase of pair k, whose shapes' core points have moved `moved`
  // together (travel sum): appends its contacts to `points` unless it is
  // known to be still apart, and remembers what it finds.
  void Collide(std::size_t k, double moved, const PlacedShape& a, const PlacedShape& b,
               std::vector<ContactPoint>& points, bool remember) {
    if (!remember) {
      CollideShapes(a, b, points);
      return;
    }
    double* vertex_clear = vertex_m.data() + vertex_start[k];
    const VertexClearances memory{moved, vertex_clear, vertex_clear + a.geometry->count()};
    const double clearance = CollideShapes(a, b, points, &memory);
    if (points.empty()) pair_m[k] = moved + clearance - kClearanceSlack_m;
  }
};

class ScopedTimer {
 public:
  explicit ScopedTimer(double& sink) : sink_(sink), start_(Clock::now()) {}
  ~ScopedTimer() { sink_ += std::chrono::duration<double>(Clock::now() - start_).count(); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double& sink_;
  Clock::time_point start_;
};

// People are named by id = index + 1, as in run files.
std::string PersonText(std::uint32_t i) { return "person " + std::to_string(i + 1); }

// Gear predictor for one coordinate (a Vec2 position or an angle): Pascal
// triangle on the Nordsieck vector (x, h v, r2..r5). Returns the predicted r2.
template <typename T>
T GearPredictOne(T& x, T& v, std::array<T, 4>& r, double h) {
  T r1 = v * h;
  x += r1 + r[0] + r[1] + r[2] + r[3];
  r1 += r[0] * 2.0 + r[1] * 3.0 + r[2] * 4.0 + r[3] * 5.0;
  r[0] += r[1] * 3.0 + r[2] * 6.0 + r[3] * 10.0;
  r[1] += r[2] * 4.0 + r[3] * 10.0;
  r[2] += r[3] * 5.0;
  v = r1 / h;
  return r[0];
}

// Gear corrector for one coordinate, `delta` = h^2/2 a(computed) - r2(predicted),
// with the coefficients for velocity-dependent forces (c0 = 3/16).
template <typename T>
void GearCorrectOne(T& x, T& v, std::array<T, 4>& r, T delta, double h) {
  static constexpr double c[6] = {3.0 / 16.0, 251.0 / 360.0, 1.0, 11.0 / 18.0, 1.0 / 6.0, 1.0 / 60.0};
  x += delta * c[0];
  v += delta * (c[1] / h);
  r[0] += delta * c[2];
  r[1] += delta * c[3];
  r[2] += delta * c[4];
  r[3] += delta * c[5];
}

}  // namespace

struct Simulation::Internals {
  // Geometry of every shape family and wall in its own frame (narrow_phase.hpp).
  // Shapes that are uniform scalings of one another share a family geometry
  // in units of their sphero-radius: shape k is family shape_family[k] scaled
  // by shape_scale[k].
  std::vector<ShapeGeometry> family_geometry;
  std::vector<std::uint32_t> shape_family;
  std::vector<double> shape_scale;
  std::vector<ShapeGeometry> wall_geometry;
  std::vector<Vec2> wall_origin;  // world position of each wall's frame
  std::vector<double> bound_m;  // core radius + sphero-radius per body
  double skin_m = 0.1;

  // Verlet lists.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;       // person pairs, a < b
  std::vector<std::pair<std::uint32_t, std::uint32_t>> wall_pairs;  // (person, wall)
  std::vector<Vec2> position_at_build;
  bool pairs_valid = false;

  // Pair clearances (temporal coherence, exact). Each pair has a measure of
  // motion that only grows, `moved`, and a pair found apart by the narrow
  // phase with clearance c (CollideShapes) cannot touch before its `moved`
  // has grown by c, so it is skipped while moved < pair_clear.pair_m[k]; the
  // same per vertex (VertexClearances). The skipped pairs are exactly pairs
  // without contacts: results are unchanged, bit for bit. Reset (to
  // -infinity) whenever the lists are rebuilt.
  //
  // Person-wall pairs: moved = travel_m[a], which adds at every force
  // evaluation a bound on how far any core point of body a moved since the
  // last one (|translation| + arm * |rotation|, the arm being the farthest
  // core vertex from the centre; walls do not move).
  //
  // Person pairs: only the two bodies' motion relative to each other can
  // close their gap, and neighbours in a crowd move largely together (in the
  // 10,000-person benchmark crowd this bound is 0.4 of the sum of the two
  // travels). pair_motion[k] keeps the pair's `moved` when it was last
  // visited, with the separation s = x_a - x_b (minimum image) and the two
  // angles then. Since, any core point of a has moved relative to any core
  // point of b by at most
  //   D = |s - s_then| + arm_a |theta_a - theta_a,then| + arm_b |theta_b - theta_b,then|
  // (|R(t) u - R(t0) u| = 2 |sin((t - t0)/2)| |u| <= |t - t0| |u|), so the
  // pair's moved is now moved_then + D, a sum of such bounds over a chain of
  // visits, which never decreases; the reference moves on at every visit.
  // D is at most what the two travels have grown since (travels bound paths,
  // D displacements), so moved <= travel_offset + travel_m[a] + travel_m[b]
  // with travel_offset = moved_then - the travel sum then: when that bound is
  // already below the pair's threshold, D is not needed (the round-off of
  // the two ways of summing is far below kClearanceSlack_m).
  std::vector<double> travel_m;
  std::vector<Vec2> travel_position;
  std::vector<double> travel_angle;
  std::vector<double> rotation_arm_m;
  struct PairMotion {
    Vec2 separation;
    double angle_a = 0.0, angle_b = 0.0, moved = 0.0;
    double travel_offset = 0.0;
  };
  std::vector<PairMotion> pair_motion;
  // The same per vertex of the two shapes of a pair, inside touching pairs.
  PairClearances pair_clear, wall_pair_clear;
  bool pair_memory = true;  // SetPairMemory

  // Contact-law constants.
  double restitution_factor = 0.0;       // 2 L / sqrt(pi^2 + L^2), L = -ln(eps)
  double wall_restitution_factor = 0.0;  // same for walls

  // Gear predictor-corrector: scaled derivatives r2..r5 for x, y, theta.
  std::vector<std::array<Vec2, 4>> gear_xy;     // r2, r3, r4, r5
  std::vector<std::array<double, 4>> gear_theta;
  bool gear_initialised = false;

  // Parallel Collide: each thread's contacts, in the order of the chunks it
  // took (buffers apart in memory), where each chunk's contacts lie in them,
  // and where each chunk's contacts start in the contact list.
  struct alignas(64) ThreadContacts {
    std::vector<Contact> items;
    std::size_t next = 0, end = 0;  // the thread's run of chunks still to take
  };
  struct ChunkSpan {
    std::uint32_t thread = 0;
    std::size_t begin = 0, end = 0;
  };
  std::vector<ThreadContacts> thread_contacts;
  std::vector<ChunkSpan> chunk_span;
  std::vector<std::size_t> chunk_offset;
  bool overlap_beyond = false;  // set by Collide, see Check
  // The CUDA force computation of person pairs (WorldDef::device), and
  // whether it holds the previous evaluation's contacts (then they are not
  // sent again); a new list of pairs is sent at each rebuild (pair_rebuilds).
  // It also sums, per body, the forces and torques of the contacts it makes
  // (the first device_contacts of the contact list), as Gather would.
  std::unique_ptr<cuda::Collider> cuda;
  bool cuda_has_history = false;
  std::size_t device_contacts = 0;
  std::vector<detail::BodySums> device_sums;
  // Contacts of each body (indices into contacts_, in contact order): CSR.
  std::vector<std::uint32_t> body_contact_start, body_contact_items, body_contact_fill;
  std::vector<Contact> previous_contacts;  // sorted by (pair key, feature)
  std::vector<double> cos_angle, sin_angle;          // per body, set by PlaceShapes
  // Corrections of the dashpot impulse for contacts that began during the
  // last half step (trailing) or end during the next (leading); see ContactLaw.
  std::vector<Vec2> trailing_force, leading_force;
  std::vector<double> trailing_torque, leading_torque;
  // Verlet half-step velocities, or the Gear predicted r2 terms.
  std::vector<Vec2> v_half;
  std::vector<double> w_half;
};

// ---------------------------------------------------------------------------
// Construction and validation

bool CudaAvailable(std::string* why) { return cuda::Available(why); }

void Simulation::SetThreads(int threads) {
  if (threads < 1 || threads > 1024)
    throw InputError("threads = " + std::to_string(threads) + ", expected 1..1024");
  def_.threads = threads;
}

Simulation::Simulation(WorldDef def) : def_(std::move(def)), in_(std::make_unique<Internals>()) {
  std::string error;
  if (!def_.parameters.IsValid(&error)) throw InputError("model parameters: " + error);
  if (def_.threads < 1 || def_.threads > 1024)
    throw InputError("threads = " + std::to_string(def_.threads) + ", expected 1..1024");
  for (std::size_t s = 0; s < def_.shapes.size(); ++s) {
    BodyShape& shape = def_.shapes[s];
    if (shape.vertices.empty() || shape.vertices.size() >= 32768 || !(shape.radius_m > 0))
      throw InputError("shape " + std::to_string(s) + ": needs 1..32767 vertices and a radius > 0");
    shape.core_radius_m = 0.0;
    for (const Vec2& v : shape.vertices) shape.core_radius_m = std::max(shape.core_radius_m, Length(v));
  }
  const std::size_t n = def_.people.size();
  if (n >= (std::size_t{1} << 31)) throw InputError("too many people");
  for (std::size_t i = 0; i < n; ++i) {
    const PersonDef& p = def_.people[i];
    const std::string who = PersonText(static_cast<std::uint32_t>(i));
    if (p.shape >= def_.shapes.size()) throw InputError(who + ": shape index out of range");
    if (p.target >= def_.targets.size()) throw InputError(who + ": target index out of range");
    if (!(p.mass_kg > 0) || !(p.inertia_kg_m2 > 0))
      throw InputError(who + ": mass and moment of inertia must be > 0");
    if (!std::isfinite(p.position_m.x) || !std::isfinite(p.position_m.y) || !std::isfinite(p.angle_rad))
      throw InputError(who + ": position and angle must be finite");
  }
  for (std::size_t w = 0; w < def_.walls.size(); ++w) {
    const Wall& wall = def_.walls[w];
    if (wall.points.size() < 2 || (wall.closed && wall.points.size() < 3) || !(wall.radius_m >= 0.0))
      throw InputError("wall " + std::to_string(w) + ": needs at least 2 points (3 if closed) and a radius >= 0");
    for (std::size_t k = 0; k + 1 < wall.points.size(); ++k)
      if (Length(wall.points[k + 1] - wall.points[k]) <= 0.0)
        throw InputError("wall " + std::to_string(w) + ": points " + std::to_string(k) + " and " +
                         std::to_string(k + 1) + " coincide");
  }
  const PeriodicBox& box = def_.periodic;
  if ((box.x && !(box.max_m.x > box.min_m.x)) || (box.y && !(box.max_m.y > box.min_m.y)))
    throw InputError("periodic box: max must exceed min along periodic axes");

  // Bodies.
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
  in_->bound_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const PersonDef& p = def_.people[i];
    bodies_.position_m[i] = p.position_m;
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
    const BodyShape& s = def_.shapes[p.shape];
    in_->bound_m[i] = s.core_radius_m + s.radius_m;
    Wrap(bodies_.position_m[i]);
  }
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
  in_->cos_angle.assign(n, 1.0);
  in_->sin_angle.assign(n, 0.0);
  in_->travel_m.assign(n, 0.0);
  in_->travel_position = bodies_.position_m;
  in_->travel_angle = bodies_.angle_rad;
  in_->rotation_arm_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t shape = bodies_.shape[i];
    // The core the narrow phase places (the family's outline at this scale),
    // rounded up so that round-off never makes the bound too small.
    in_->rotation_arm_m[i] =
        in_->family_geometry[in_->shape_family[shape]].core_radius_m * in_->shape_scale[shape] * (1.0 + 1e-12);
  }

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

  const auto factor = [](double eps) {
    const double l = -std::log(eps);
    return 2.0 * l / std::sqrt(kPi * kPi + l * l);
  };
  in_->restitution_factor = factor(def_.parameters.restitution);
  in_->wall_restitution_factor = factor(def_.parameters.wall_restitution);

  dt_estimate_ = EstimateTimeStep(def_);
  if (def_.parameters.time_step_s > dt_estimate_.stability_limit_s)
    throw InputError("time_step_s = " + FormatNumber(def_.parameters.time_step_s) +
                     " s is above the stability limit of the " +
                     ToString(def_.parameters.integrator) + " integrator, " +
                     FormatNumber(dt_estimate_.stability_limit_s) +
                     " s, for the stiffest contact (omega_max = " +
                     FormatNumber(dt_estimate_.omega_max_rad_per_s) +
                     " rad/s); use a smaller step or 0 for automatic");
  dt_s_ = dt_estimate_.chosen_s;

  if (def_.device == ComputeDevice::kCuda)
    in_->cuda = std::make_unique<cuda::Collider>(in_->family_geometry, in_->shape_family, in_->shape_scale,
                                                 def_.periodic);
  ComputeForces();  // forces at t = 0 (no spring increment: contacts start unloaded)
  in_->previous_contacts = contacts_;
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

// ---------------------------------------------------------------------------
// Periodic box

void Simulation::Wrap(Vec2& p) const {
  const PeriodicBox& box = def_.periodic;
  // Fast path: already inside (the common case; a step moves far less than a period).
  if ((!box.x || (p.x >= box.min_m.x && p.x < box.max_m.x)) && (!box.y || (p.y >= box.min_m.y && p.y < box.max_m.y)))
    return;
  if (box.x) {
    const double l = box.max_m.x - box.min_m.x;
    p.x = box.min_m.x + (p.x - box.min_m.x) - l * std::floor((p.x - box.min_m.x) / l);
    if (p.x >= box.max_m.x) p.x -= l;
  }
  if (box.y) {
    const double l = box.max_m.y - box.min_m.y;
    p.y = box.min_m.y + (p.y - box.min_m.y) - l * std::floor((p.y - box.min_m.y) / l);
    if (p.y >= box.max_m.y) p.y -= l;
  }
}

Vec2 Simulation::Separation(Vec2 a, Vec2 b) const {
  Vec2 d = a - b;
  const PeriodicBox& box = def_.periodic;
  if (box.x) d.x = detail::MinimumImage(d.x, box.max_m.x - box.min_m.x);
  if (box.y) d.y = detail::MinimumImage(d.y, box.max_m.y - box.min_m.y);
  return d;
}

// ---------------------------------------------------------------------------
// Stage 1: neighbour pairs (cells + Verlet skin)

void Simulation::UpdatePairs() {
  ScopedTimer timer(profile_.update_pairs_s);
  Internals& in = *in_;
  const std::size_t n = bodies_.size();
  if (in.pairs_valid) {
    // Rebuild only when someone moved more than half the skin since the last
    // build (bounding circles are rotation invariant, so rotation never forces one).
    const double limit2 = in.skin_m * in.skin_m / 4.0;
    const std::int64_t count = static_cast<std::int64_t>(n);
    bool rebuild = false;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies) reduction(|| : rebuild)
    for (std::int64_t i = 0; i < count; ++i)
      rebuild = rebuild || LengthSquared(Separation(bodies_.position_m[static_cast<std::size_t>(i)],
                                                    in.position_at_build[static_cast<std::size_t>(i)])) > limit2;
    if (!rebuild) return;
  }
  ++profile_.pair_rebuilds;
  in.pairs_valid = true;
  in.position_at_build = bodies_.position_m;
  in.pairs.clear();
  in.wall_pairs.clear();

  std::vector<std::uint32_t> active;
  double bound_max = 0.0;
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (std::uint32_t i = 0; i < n; ++i) {
    if (bodies_.state[i] == PersonState::kRemoved) continue;
    active.push_back(i);
    bound_max = std::max(bound_max, in.bound_m[i]);
    const Vec2 p = bodies_.position_m[i];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  if (active.empty()) return;
  const double cutoff = 2.0 * bound_max + in.skin_m;
  const PeriodicBox& box = def_.periodic;
  if (box.x) { lo.x = box.min_m.x; hi.x = box.max_m.x; }
  if (box.y) { lo.y = box.min_m.y; hi.y = box.max_m.y; }
  if ((box.x && box.max_m.x - box.min_m.x < 2.0 * cutoff) ||
      (box.y && box.max_m.y - box.min_m.y < 2.0 * cutoff))
    throw InputError("periodic box is shorter than twice the interaction range " +
                     FormatNumber(cutoff) + " m; make it longer");
  const auto cells_along = [&](double extent, bool periodic) {
    const double count = std::floor(extent / cutoff);
    return static_cast<std::int64_t>(std::clamp(count, 1.0, periodic ? 1e6 : 1e6));
  };
  const std::int64_t ncx = cells_along(hi.x - lo.x + (box.x ? 0.0 : 1e-9), box.x);
  const std::int64_t ncy = cells_along(hi.y - lo.y + (box.y ? 0.0 : 1e-9), box.y);
  const double cell_w = box.x ? (hi.x - lo.x) / double(ncx) : std::max(cutoff, (hi.x - lo.x) / double(ncx));
  const double cell_h = box.y ? (hi.y - lo.y) / double(ncy) : std::max(cutoff, (hi.y - lo.y) / double(ncy));
  const auto cell_of = [&](Vec2 p) {
    std::int64_t cx = static_cast<std::int64_t>(std::floor((p.x - lo.x) / cell_w));
    std::int64_t cy = static_cast<std::int64_t>(std::floor((p.y - lo.y) / cell_h));
    cx = std::clamp<std::int64_t>(cx, 0, ncx - 1);
    cy = std::clamp<std::int64_t>(cy, 0, ncy - 1);
    return std::pair{cx, cy};
  };
  // Counting sort of bodies into cells.
  const std::size_t ncells = static_cast<std::size_t>(ncx * ncy);
  std::vector<std::uint32_t> cell_start(ncells + 1, 0), cell_items(active.size());
  std::vector<std::size_t> body_cell(active.size());
  for (std::size_t k = 0; k < active.size(); ++k) {
    const auto [cx, cy] = cell_of(bodies_.position_m[active[k]]);
    body_cell[k] = static_cast<std::size_t>(cy * ncx + cx);
    ++cell_start[body_cell[k] + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t k = 0; k < active.size(); ++k) cell_items[fill[body_cell[k]]++] = active[k];
  }
  // The pairs of each person with the later people of its own and the eight
  // neighbouring cells, and with the walls. People are taken in index order
  // and each one's partners in increasing order, so the lists come out sorted;
  // with many people, in as many contiguous parts as there are threads, each
  // into a list of its own, joined in order: the same lists either way.
  const std::size_t parts =
      static_cast<std::int64_t>(active.size()) >= kParallelBodies ? static_cast<std::size_t>(def_.threads) : 1;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> part_pairs(parts), part_wall_pairs(parts);
  const std::int64_t part_count = static_cast<std::int64_t>(parts);
#pragma omp parallel for schedule(static, 1) num_threads(def_.threads) if (part_count > 1)
  for (std::int64_t part = 0; part < part_count; ++part) {
    const std::size_t q = static_cast<std::size_t>(part);
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs = part_pairs[q];
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& wall_pairs = part_wall_pairs[q];
    std::vector<std::uint32_t> candidates;
    std::vector<std::size_t> neighbour_cells;
    const Part people = PartOf(active.size(), q, parts);
    for (std::size_t k = people.begin; k < people.end; ++k) {
      const std::uint32_t i = active[k];
      const Vec2 pi = bodies_.position_m[i];
      const std::int64_t cx = static_cast<std::int64_t>(body_cell[k] % static_cast<std::size_t>(ncx));
      const std::int64_t cy = static_cast<std::int64_t>(body_cell[k] / static_cast<std::size_t>(ncx));
      neighbour_cells.clear();
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          std::int64_t x = cx + dx, y = cy + dy;
          if (box.x) x = (x + ncx) % ncx;
          if (box.y) y = (y + ncy) % ncy;
          if (x < 0 || x >= ncx || y < 0 || y >= ncy) continue;
          neighbour_cells.push_back(static_cast<std::size_t>(y * ncx + x));
        }
      std::sort(neighbour_cells.begin(), neighbour_cells.end());
      neighbour_cells.erase(std::unique(neighbour_cells.begin(), neighbour_cells.end()), neighbour_cells.end());
      candidates.clear();
      for (std::size_t c : neighbour_cells)
        for (std::uint32_t s = cell_start[c]; s < cell_start[c + 1]; ++s) {
          const std::uint32_t j = cell_items[s];
          if (j <= i) continue;
          const double range = in.bound_m[i] + in.bound_m[j] + in.skin_m;
          if (LengthSquared(Separation(pi, bodies_.position_m[j])) < range * range) candidates.push_back(j);
        }
      std::sort(candidates.begin(), candidates.end());
      for (std::uint32_t j : candidates) pairs.emplace_back(i, j);
      for (std::uint32_t w = 0; w < def_.walls.size(); ++w) {
        const Wall& wall = def_.walls[w];
        const double range = in.bound_m[i] + wall.radius_m + in.skin_m;
        if (Length(pi - in.wall_origin[w]) > in.wall_geometry[w].core_radius_m + range) continue;
        const std::size_t segments = wall.closed ? wall.points.size() : wall.points.size() - 1;
        for (std::size_t seg = 0; seg < segments; ++seg)
          if (DistanceToSegment(pi, wall.points[seg], wall.points[(seg + 1) % wall.points.size()]) < range) {
            wall_pairs.emplace_back(i, w);
            break;
          }
      }
    }
  }
  for (std::size_t q = 0; q < parts; ++q) {
    in.pairs.insert(in.pairs.end(), part_pairs[q].begin(), part_pairs[q].end());
    in.wall_pairs.insert(in.wall_pairs.end(), part_wall_pairs[q].begin(), part_wall_pairs[q].end());
  }
  assert(std::is_sorted(in.pairs.begin(), in.pairs.end()));
  const auto vertices_of = [&](std::uint32_t i) {
    return std::size_t{in.family_geometry[in.shape_family[bodies_.shape[i]]].count()};
  };
  in.pair_clear.Reset(
      in.pairs.size(), [&](std::size_t k) { return vertices_of(in.pairs[k].first) + vertices_of(in.pairs[k].second); },
      def_.threads);
  in.pair_motion.assign(in.pairs.size(), Internals::PairMotion{});  // (the first visit measures every vertex)
  in.wall_pair_clear.Reset(
      in.wall_pairs.size(),
      [&](std::size_t k) { return vertices_of(in.wall_pairs[k].first) + in.wall_geometry[in.wall_pairs[k].second].count(); },
      def_.threads);
}

void Simulation::RebuildNeighbourList() {
  in_->pairs_valid = false;
  UpdatePairs();
}

std::size_t Simulation::neighbour_pair_count() const { return in_->pairs.size(); }

void Simulation::SetPairMemory(bool enabled) {
  if (enabled && !in_->pair_memory) in_->pairs_valid = false;  // what was remembered is stale: start afresh
  in_->pair_memory = enabled;
}

// ---------------------------------------------------------------------------
// Stage 2: shapes to world frame

void Simulation::PlaceShapes() {
  ScopedTimer timer(profile_.place_shapes_s);
  Internals& in = *in_;
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    SinCos(bodies_.angle_rad[i], in.sin_angle[i], in.cos_angle[i]);  // common/fast_math.hpp
    // Travel since the last evaluation: a core point at distance r <= arm
    // from the centre moves by at most |translation| + r |rotation|.
    const Vec2 x = bodies_.position_m[i];
    const double angle = bodies_.angle_rad[i];
    in.travel_m[i] += Length(Separation(x, in.travel_position[i])) +
                      in.rotation_arm_m[i] * std::abs(angle - in.travel_angle[i]);
    in.travel_position[i] = x;
    in.travel_angle[i] = angle;
  }
}

// ---------------------------------------------------------------------------
// Stage 3: narrow phase and contact forces (eqs. 7-14, 19)

namespace {

// The contact of persons (or person and wall) a, b at a narrow-phase point,
// before the contact law fills its forces.
// Made member by member in one initialiser (not zero-filled first and then
// assigned); the others keep their defaults until the contact law sets them.
Contact ContactAt(const ContactPoint& p, std::uint32_t a, std::uint32_t b, bool wall) {
  return Contact{.a = a, .b = b, .wall = wall, .feature = p.feature, .point_m = p.point, .normal = p.normal,
                 .overlap_m = p.overlap_m};
}

// Sum of the overlaps of a pair's points and their overlap-weighted count
// k_eff = (sum delta)^2 / sum delta^2 (see ContactLaw::Apply).
std::pair<double, double> OverlapShares(const std::vector<ContactPoint>& points) {
  double sum = 0.0, sum2 = 0.0;
  for (const ContactPoint& p : points) {
    sum += p.overlap_m;
    sum2 += p.overlap_m * p.overlap_m;
  }
  return {sum, sum * sum / sum2};
}

// The previous evaluation's contact with a given (pair key, feature), for its
// tangential spring. The lookups of one work chunk come in increasing order
// (pairs sorted, features increasing within a pair), so a cursor that moves
// forward replaces a binary search per contact; a lookup out of order falls
// back to the binary search.
class PreviousContacts {
 public:
  explicit PreviousContacts(const std::vector<Contact>& previous) : previous_(previous) {}

  const Contact* Find(std::uint64_t key, std::uint32_t feature) {
    const auto before = [&](const Contact& c) {
      const std::uint64_t ck = PairKey(c);
      return ck < key || (ck == key && c.feature < feature);
    };
    if (!started_ || key < last_key_ || (key == last_key_ && feature < last_feature_)) {
      pos_ = static_cast<std::size_t>(std::partition_point(previous_.begin(), previous_.end(), before) - previous_.begin());
      started_ = true;
    } else {
      while (pos_ < previous_.size() && before(previous_[pos_])) ++pos_;
    }
    last_key_ = key;
    last_feature_ = feature;
    if (pos_ < previous_.size() && PairKey(previous_[pos_]) == key && previous_[pos_].feature == feature)
      return &previous_[pos_];
    return nullptr;
  }

 private:
  const std::vector<Contact>& previous_;
  std::size_t pos_ = 0;
  bool started_ = false;
  std::uint64_t last_key_ = 0;
  std::uint32_t last_feature_ = 0;
};

// A wall is a line (its core, an open or closed polyline with no inside), so
// the distance of a person's vertex from it never turns negative: a vertex
// pressed through it would simply be pushed on from the other side. True when
// the vertex of contact `now` (a person's vertex against a wall's core) went
// through the wall since `before`, the same vertex's contact at the last
// evaluation: it now lies behind the line it touched then (along that
// contact's normal, from the closest point then) and the wall now pushes the
// opposite way. The closest point of the core is point - n (r_w - delta/2),
// the vertex reach - delta beyond it along n (narrow_phase.cpp). Going round
// a convex corner or a wall's end does not count, unless within about one
// step's travel of it (the core then practically touches it).
// `separation(x, y)` is x - y (minimum image).
template <typename Separation>
bool WentThroughWall(const Contact& now, const Contact& before, double wall_radius_m, double reach_m,
                     const Separation& separation) {
  if ((now.feature & kVertexOfB) != 0) return false;  // a wall's vertex against the person's core
  const auto closest = [&](const Contact& c) { return c.point_m - c.normal * (wall_radius_m - c.overlap_m / 2.0); };
  const Vec2 vertex = closest(now) + now.normal * (reach_m - now.overlap_m);
  return Dot(separation(vertex, closest(before)), before.normal) < 0.0 && Dot(now.normal, before.normal) < 0.0;
}

}  // namespace

void Simulation::Collide() {
  ScopedTimer timer(profile_.collide_s);
  Internals& in = *in_;
  const ModelParameters& mp = def_.parameters;
  // The first evaluation (at construction) does not advance the springs.
  const ContactLaw law{mp.normal_stiffness_n_per_m, mp.tangential_stiffness_n_per_m, mp.friction_coefficient,
                       dt_s_, in.restitution_factor, mp.tangential_damping, mp.tangential_damping_rate_per_s,
                       mp.allow_tensile_normal_force, advance_springs_};
  ContactLaw wall_law = law;
  wall_law.damping_factor = in.wall_restitution_factor;

  const std::size_t person_chunks = (in.pairs.size() + kChunk - 1) / kChunk;
  const std::size_t wall_chunks = (in.wall_pairs.size() + kChunk - 1) / kChunk;
  const std::size_t chunks = person_chunks + wall_chunks;

  const auto placed = [&](std::uint32_t i, Vec2 position) {
    PlacedShape p;
    const std::uint32_t shape = bodies_.shape[i];
    p.geometry = &in.family_geometry[in.shape_family[shape]];
    p.scale = in.shape_scale[shape];
    p.position = position;
    p.cos_angle = in.cos_angle[i];
    p.sin_angle = in.sin_angle[i];
    return p;
  };
  const auto velocity_at = [&](std::uint32_t i, Vec2 arm) {
    if (bodies_.state[i] != PersonState::kWalking) return Vec2{};
    return bodies_.velocity_m_per_s[i] + Perp(arm) * bodies_.angular_velocity_rad_per_s[i];
  };
  const auto effective_mass = [&](std::uint32_t a, std::uint32_t b) {
    const bool fa = bodies_.state[a] != PersonState::kWalking, fb = bodies_.state[b] != PersonState::kWalking;
    if (fa && fb) return 0.5 * (bodies_.mass_kg[a] + bodies_.mass_kg[b]);  // no dynamics; any positive value
    if (fa) return bodies_.mass_kg[b];
    if (fb) return bodies_.mass_kg[a];
    return bodies_.mass_kg[a] * bodies_.mass_kg[b] / (bodies_.mass_kg[a] + bodies_.mass_kg[b]);  // eq. (14)
  };

  // The contacts of one pair (persons a and b, or person a and wall b) at its
  // narrow-phase points, with the forces of `pair_law`; `relative_velocity(x)`
  // is a's velocity less b's at the point x. Returns true if a point overlaps
  // beyond `radii`, the sum of the two sphero-radii, or, for a wall, if a
  // vertex went through it (WentThroughWall): the cores interpenetrate, which
  // Check() reports (and looks for only then).
  const auto minimum_image = [this](Vec2 x, Vec2 y) { return Separation(x, y); };
  const auto add_contacts = [&minimum_image](const std::vector<ContactPoint>& points, std::uint32_t a, std::uint32_t b,
                                          bool wall, const ContactLaw& pair_law, double mass, double radii,
                                          PreviousContacts& previous, std::vector<Contact>& out,
                                          const auto& relative_velocity, double wall_radius_m = 0.0) {
    const std::uint64_t key = PairKey(wall, a, b);
    const auto [sum, k_eff] = OverlapShares(points);
    const ContactLaw::Rates rates = pair_law.PairRates(mass, k_eff);
    bool beyond = false;
    for (const ContactPoint& p : points) {
      Contact& c = out.emplace_back(ContactAt(p, a, b, wall));
      const Contact* before = previous.Find(key, p.feature);
      const ContactHistory history =
          before ? ContactHistory{true, before->tangential_spring_m, before->leading_fraction} : ContactHistory{};
      pair_law.Apply(c, relative_velocity(p.point), mass, history, p.overlap_m / sum, rates);
      beyond = beyond || !(p.overlap_m <= radii) ||
               (wall && before && WentThroughWall(c, *before, wall_radius_m, radii, minimum_image));
    }
    return beyond;
  };
  // One chunk of pairs: its contacts appended to `out`, in pair order. Returns
  // true if one of them overlaps beyond the sum of the radii (see add_contacts).
  // `measured` counts the pairs given to the narrow phase (Profile::pairs_measured).
  const auto collide_chunk = [&](std::size_t chunk, std::vector<Contact>& out, std::vector<ContactPoint>& points,
                                 std::uint64_t& measured) {
    PreviousContacts previous(in.previous_contacts);
    bool overlap_beyond = false;
    if (chunk < person_chunks) {
      const std::size_t end = std::min(in.pairs.size(), (chunk + 1) * kChunk);
      for (std::size_t k = chunk * kChunk; k < end; ++k) {
        const auto [a, b] = in.pairs[k];
        Internals::PairMotion& motion = in.pair_motion[k];
        const double travel = in.travel_m[a] + in.travel_m[b];
        if (in.pair_memory && motion.travel_offset + travel < in.pair_clear.pair_m[k]) continue;  // still apart
        const Vec2 xa = bodies_.position_m[a];
        const Vec2 separation = Separation(xa, bodies_.position_m[b]);
        const double angle_a = bodies_.angle_rad[a], angle_b = bodies_.angle_rad[b];
        const double moved = motion.moved + Length(separation - motion.separation) +
                             in.rotation_arm_m[a] * std::abs(angle_a - motion.angle_a) +
                             in.rotation_arm_m[b] * std::abs(angle_b - motion.angle_b);
        if (in.pair_memory && moved < in.pair_clear.pair_m[k]) continue;  // still apart (see Internals)
        motion = {separation, angle_a, angle_b, moved, moved - travel};  // visited: the reference moves on
        if (bodies_.state[a] == PersonState::kRemoved || bodies_.state[b] == PersonState::kRemoved) continue;
        const Vec2 xb_image = xa - separation;
        const PlacedShape pa = placed(a, xa), pb = placed(b, xb_image);
        points.clear();
        ++measured;
        in.pair_clear.Collide(k, moved, pa, pb, points, in.pair_memory);
        if (points.empty()) continue;
        // (a and b captured by init-capture: clang 14, the fuzz build's compiler, cannot capture structured bindings)
        const auto relative_velocity = [&, a = a, b = b](Vec2 x) {
          return velocity_at(a, x - xa) - velocity_at(b, x - xb_image);
        };
        overlap_beyond = add_contacts(points, a, b, false, law, effective_mass(a, b), pa.scale + pb.scale,  // (family radius 1)
                                      previous, out, relative_velocity) ||
                         overlap_beyond;
      }
    } else {
      const std::size_t wchunk = chunk - person_chunks;
      const std::size_t end = std::min(in.wall_pairs.size(), (wchunk + 1) * kChunk);
      for (std::size_t k = wchunk * kChunk; k < end; ++k) {
        const auto [a, w] = in.wall_pairs[k];
        const double moved = in.travel_m[a];
        if (in.pair_memory && moved < in.wall_pair_clear.pair_m[k]) continue;  // still apart (see Internals)
        if (bodies_.state[a] == PersonState::kRemoved) continue;
        const Vec2 xa = bodies_.position_m[a];
        const PlacedShape pa = placed(a, xa);
        PlacedShape pw;
        pw.geometry = &in.wall_geometry[w];
        pw.position = in.wall_origin[w];
        points.clear();
        ++measured;
        in.wall_pair_clear.Collide(k, moved, pa, pw, points, in.pair_memory);
        if (points.empty()) continue;
        const auto relative_velocity = [&, a = a](Vec2 x) { return velocity_at(a, x - xa); };  // (init-capture: as above)
        overlap_beyond = add_contacts(points, a, w, true, wall_law, bodies_.mass_kg[a], pa.scale + pw.geometry->radius_m,
                                      previous, out, relative_velocity, pw.geometry->radius_m) ||
                         overlap_beyond;
      }
    }
    return overlap_beyond;
  };

  if (in.cuda) {
    // Person pairs on the device, in list order; then the wall pairs here, as
    // below (they follow the person pairs in the contact list).
    cuda::CollideInput input;
    input.n = bodies_.size();
    input.position_m = bodies_.position_m.data();
    input.cos_angle = in.cos_angle.data();
    input.sin_angle = in.sin_angle.data();
    input.velocity_m_per_s = bodies_.velocity_m_per_s.data();
    input.angular_velocity_rad_per_s = bodies_.angular_velocity_rad_per_s.data();
    input.state = bodies_.state.data();
    input.mass_kg = bodies_.mass_kg.data();
    input.shape = bodies_.shape.data();
    input.pairs = in.pairs.data();
    input.pair_count = in.pairs.size();
    input.pair_generation = profile_.pair_rebuilds;
    input.previous = &in.previous_contacts;
    input.previous_is_last_output = in.cuda_has_history;
    input.law = law;
    contacts_.clear();
    bool overlap_beyond = false;
    bool computed = false;
    try {
      overlap_beyond = in.cuda->Collide(input, contacts_, in.device_sums);
      computed = true;
    } catch (const std::runtime_error& e) {
      // The device failed (a lost GPU, a driver error). The processor gives
      // the same results, so the run goes on there, from this evaluation on;
      // the reason is kept for the caller to report (device_fallback()).
      // The processor's pair clearances were never set while the device
      // computed (all "unknown"), so it simply measures every pair at first.
      device_fallback_ = std::string(e.what()) + " (at t = " + FormatNumber(time_s_) +
                         " s; the processor took over, with the same results)";
      in.cuda.reset();
      in.device_sums.clear();
      contacts_.clear();
    }
    if (computed) {
      in.device_contacts = contacts_.size();
      in.cuda_has_history = true;
      const cuda::Collider::Timing timing = in.cuda->last_timing();
      profile_.device_copy_s += (timing.upload_ms + timing.download_ms) * 1e-3;
      profile_.device_kernels_s += timing.kernels_ms * 1e-3;
      std::vector<ContactPoint> points;
      std::uint64_t measured = in.pairs.size();  // the device measures every person pair
      for (std::size_t chunk = person_chunks; chunk < chunks; ++chunk)
        overlap_beyond = collide_chunk(chunk, contacts_, points, measured) || overlap_beyond;
      profile_.pairs_measured += measured;
      in.overlap_beyond = overlap_beyond;
      return;
    }
  }
  const std::int64_t total = static_cast<std::int64_t>(chunks);
  if (def_.threads == 1 || total < 4) {
    // On one thread the chunks come in order: straight into the contact list,
    // which is then what the concatenation below would have made.
    contacts_.clear();
    std::vector<ContactPoint> points;
    bool overlap_beyond = false;
    std::uint64_t measured = 0;
    for (std::size_t chunk = 0; chunk < chunks; ++chunk)
      overlap_beyond = collide_chunk(chunk, contacts_, points, measured) || overlap_beyond;
    profile_.pairs_measured += measured;
    in.overlap_beyond = overlap_beyond;
    return;
  }
  // Each thread owns a contiguous run of chunks (thread 0 the first, and so
  // on) and takes them one at a time from its front; a thread done with its
  // own run takes what is left of the others' (their costs vary). Pairs are
  // sorted by their first person and people are numbered along the crowd, so
  // a thread works mostly on the people whose motion it integrates and whose
  // forces it sums (the stages split by body): less data crosses between
  // cores than when chunks are dealt in turn. Each thread appends its chunks'
  // contacts to a buffer of its own (apart in memory: no cache line is written
  // by two threads) and notes where each chunk's lie; the chunks are then
  // copied into the contact list in chunk order: the same list whatever the
  // thread count, and whichever thread took which chunk.
  const std::size_t team = static_cast<std::size_t>(def_.threads);
  in.thread_contacts.resize(team);
  for (std::size_t t = 0; t < team; ++t) {
    const Part run = PartOf(chunks, t, team);
    in.thread_contacts[t].next = run.begin;
    in.thread_contacts[t].end = run.end;
  }
  in.chunk_span.resize(chunks);
  bool overlap_beyond = false;
  std::uint64_t measured = 0;
#pragma omp parallel num_threads(def_.threads) reduction(|| : overlap_beyond) reduction(+ : measured)
  {
    std::uint32_t thread = 0;
#ifdef _OPENMP
    thread = static_cast<std::uint32_t>(omp_get_thread_num());
#endif
    std::vector<ContactPoint> points;
    std::vector<Contact>& out = in.thread_contacts[thread].items;
    out.clear();
    for (std::size_t turn = 0; turn < team; ++turn) {  // its own run first, then the others'
      Internals::ThreadContacts& owner = in.thread_contacts[(thread + turn) % team];
      for (;;) {
        std::size_t chunk;
#pragma omp atomic capture
        chunk = owner.next++;
        if (chunk >= owner.end) break;
        const std::size_t begin = out.size();
        overlap_beyond = collide_chunk(chunk, out, points, measured) || overlap_beyond;
        in.chunk_span[chunk] = {thread, begin, out.size()};
      }
    }
  }
  profile_.pairs_measured += measured;
  in.overlap_beyond = overlap_beyond;
  in.chunk_offset.assign(chunks + 1, 0);
  for (std::size_t k = 0; k < chunks; ++k)
    in.chunk_offset[k + 1] = in.chunk_offset[k] + (in.chunk_span[k].end - in.chunk_span[k].begin);
  contacts_.resize(in.chunk_offset[chunks]);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (total >= 64)
  for (std::int64_t ck = 0; ck < total; ++ck) {
    const Internals::ChunkSpan& span = in.chunk_span[static_cast<std::size_t>(ck)];
    const auto from = in.thread_contacts[span.thread].items.begin();
    std::copy(from + static_cast<std::ptrdiff_t>(span.begin), from + static_cast<std::ptrdiff_t>(span.end),
              contacts_.begin() + static_cast<std::ptrdiff_t>(in.chunk_offset[static_cast<std::size_t>(ck)]));
  }
}

// ---------------------------------------------------------------------------
// Stage 4: contact forces onto bodies (eq. 2 third term, eq. 18 last term)

void Simulation::Gather() {
  ScopedTimer timer(profile_.gather_s);
  Internals& in = *in_;
  const std::size_t n = bodies_.size();
  in.trailing_force.resize(n);
  in.trailing_torque.resize(n);
  in.leading_force.resize(n);
  in.leading_torque.resize(n);
  // Each body's contacts in contact order (counting sort), so that every
  // body's sums run in a fixed order whichever thread computes them.
  // With many contacts, in as many contiguous parts of the contact list as
  // there are threads: each part counts its contacts per body, the counts
  // give each part's place within each body's run (the earlier parts first),
  // and each part files its contacts there. The same index either way.
  // With the CUDA force computation the device has summed the person pairs'
  // contacts (the list's first in.device_contacts) per body, in the same
  // order; the sums here go on from there with the wall contacts after them.
  std::vector<std::uint32_t>& start = in.body_contact_start;
  std::vector<std::uint32_t>& items = in.body_contact_items;
  const std::size_t first = in.cuda ? in.device_contacts : 0;
  const std::size_t m = contacts_.size() - first;
  const bool split = def_.threads > 1 && static_cast<std::int64_t>(n) >= kParallelBodies &&
                     static_cast<std::int64_t>(m) >= kParallelBodies;  // as the per-body sums below
  const std::size_t parts = split ? static_cast<std::size_t>(def_.threads) : 1;
  std::vector<std::uint32_t>& fill = in.body_contact_fill;  // parts x n: counts, then where each part files
  fill.resize(parts * n);
  const std::int64_t part_count = static_cast<std::int64_t>(parts);
#pragma omp parallel for schedule(static, 1) num_threads(def_.threads) if (part_count > 1)
  for (std::int64_t part = 0; part < part_count; ++part) {
    const std::size_t q = static_cast<std::size_t>(part);
    std::uint32_t* count = fill.data() + q * n;
    std::fill(count, count + n, 0u);
    const Part listed = PartOf(m, q, parts);
    for (std::size_t k = first + listed.begin; k < first + listed.end; ++k) {
      const Contact& c = contacts_[k];
      ++count[c.a];
      if (!c.wall) ++count[c.b];
    }
  }
  start.resize(n + 1);
  std::uint32_t running = 0;
  for (std::size_t i = 0; i < n; ++i) {
    start[i] = running;
    for (std::size_t q = 0; q < parts; ++q) {
      const std::uint32_t c = fill[q * n + i];
      fill[q * n + i] = running;
      running += c;
    }
  }
  start[n] = running;
  items.resize(running);
#pragma omp parallel for schedule(static, 1) num_threads(def_.threads) if (part_count > 1)
  for (std::int64_t part = 0; part < part_count; ++part) {
    const std::size_t q = static_cast<std::size_t>(part);
    std::uint32_t* place = fill.data() + q * n;
    const Part listed = PartOf(m, q, parts);
    for (std::size_t k = first + listed.begin; k < first + listed.end; ++k) {
      const Contact& c = contacts_[k];
      items[place[c.a]++] = static_cast<std::uint32_t>(k);
      if (!c.wall) items[place[c.b]++] = static_cast<std::uint32_t>(k);
    }
  }
  const detail::BodySums* device_sums = in.cuda ? in.device_sums.data() : nullptr;
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::uint32_t i = static_cast<std::uint32_t>(ii);
    detail::BodySums sums = device_sums ? device_sums[i] : detail::BodySums{};
    for (std::uint32_t s = start[i]; s < start[i + 1]; ++s) {
      const Contact& c = contacts_[items[s]];
      const Vec2 xa = bodies_.position_m[c.a];
      if (c.a == i)
        detail::AddContact(sums, c, true, xa);
      else
        detail::AddContact(sums, c, false, xa - Separation(xa, bodies_.position_m[c.b]));
    }
    bodies_.contact_force_n[i] = sums.force;
    bodies_.contact_torque_n_m[i] = sums.torque;
    in.trailing_force[i] = sums.trailing_force;
    in.trailing_torque[i] = sums.trailing_torque;
    in.leading_force[i] = sums.leading_force;
    in.leading_torque[i] = sums.leading_torque;
  }
}

// ---------------------------------------------------------------------------
// Stage 5: ground reaction forces and torques (eqs. 3, 15, 16, 17), slope

void Simulation::Drive() {
  ScopedTimer timer(profile_.drive_s);
  const Internals& in = *in_;
  const ModelParameters& mp = def_.parameters;
  // Loop invariants, so that the loop below divides only where it must.
  const double inverse_tau = 1.0 / mp.relaxation_time_s;
  const double back_factor = mp.back_force_gamma * inverse_tau;                                      // eq. (15): Gamma / tau
  const double torsion_factor = mp.torsion_stiffness_lambda * inverse_tau * inverse_tau;             // eq. (16): lambda / tau^2
  const double rotation_damping = 1.0 / mp.rotation_relaxation_time_s;                               // eq. (17)
  const bool face_velocity = mp.facing_target == FacingTarget::kVelocity;
  const double slope_force_per_kg =
      def_.slope.gradient > 0.0 ? mp.gravity_m_per_s2 * def_.slope.gradient / std::sqrt(1.0 + def_.slope.gradient * def_.slope.gradient)
                                : 0.0;
  const Vec2 slope_acceleration = def_.slope.downhill * slope_force_per_kg;
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  // In blocks of bodies, in three passes: the motive torque's angle (eq. 16)
  // is a long chain of dependent operations (a division, a polynomial), so
  // the angles of a block are computed in a short loop of their own, whose
  // iterations the processor overlaps, between the passes that need them.
  constexpr std::int64_t kBlock = 64;
  const std::int64_t blocks = (n + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies)
  for (std::int64_t block = 0; block < blocks; ++block) {
    const std::size_t first = static_cast<std::size_t>(block * kBlock);
    const std::size_t last = static_cast<std::size_t>(std::min(n, (block + 1) * kBlock));
    Vec2 direction[kBlock];
    double sine[kBlock], cosine[kBlock], gain[kBlock], angle[kBlock];
    bool driven[kBlock], turning[kBlock];
    // Pass 1: desired direction, and the angle's arguments: from the body's
    // orientation (cos, sin from PlaceShapes) to the facing direction.
    for (std::size_t i = first; i < last; ++i) {
      const std::size_t k = i - first;
      driven[k] = bodies_.state[i] == PersonState::kWalking && mp.ground_reaction;
      turning[k] = false;
      sine[k] = 0.0;
      cosine[k] = 1.0;
      gain[k] = 0.0;
      if (!driven[k]) continue;
      const Vec2 v = bodies_.velocity_m_per_s[i];
      direction[k] = def_.targets[bodies_.target[i]].Direction(bodies_.position_m[i]);
      const double speed = Length(v);
      // Only the direction of `facing` matters to the angle (atan2 of two
      // products with it), so the velocity needs no normalising.
      const Vec2 facing = face_velocity ? v : direction[k];
      if (facing.x != 0.0 || facing.y != 0.0) {
        const Vec2 orientation{in.cos_angle[i], in.sin_angle[i]};
        turning[k] = true;
        sine[k] = Cross(orientation, facing);
        cosine[k] = Dot(orientation, facing);
        const double v0 = bodies_.desired_speed_m_per_s[i];
        gain[k] = v0 > 0.0 ? 1.0 - std::exp(-speed / v0) : 1.0;
      }
    }
    // Pass 2: theta_D - theta wrapped to (-pi, pi].
    for (std::size_t k = 0; k < last - first; ++k) angle[k] = Atan2(sine[k], cosine[k]);
    // Pass 3: forces and torques.
    for (std::size_t i = first; i < last; ++i) {
      const std::size_t k = i - first;
      Vec2 force = bodies_.contact_force_n[i] + bodies_.external_force_n[i];
      double torque = bodies_.contact_torque_n_m[i];
      if (driven[k]) {
        const double m = bodies_.mass_kg[i], inertia = bodies_.inertia_kg_m2[i];
        const double v0 = bodies_.desired_speed_m_per_s[i];
        const Vec2 v = bodies_.velocity_m_per_s[i];
        const Vec2 e = direction[k];
        force += (e * v0 - v) * (m * inverse_tau);  // eq. (3)
        // Back force, eq. (15): only when pushed backwards (Theta(x) = 1 for x > 0
        // only, ERRATA 9), along e plus e x k, which points to the person's right.
        if (-Dot(e, v) > 0.0) force += (e + Vec2{e.y, -e.x}) * (back_factor * m * v0);
        // Motive torque, eq. (16) with the restoring sign (ERRATA 4).
        if (turning[k]) torque += torsion_factor * inertia * gain[k] * angle[k];
        // Rotational damping, eq. (17), with its own relaxation time (ERRATA 8).
        torque -= inertia * rotation_damping * bodies_.angular_velocity_rad_per_s[i];
        force += slope_acceleration * m;
      }
      bodies_.force_n[i] = force;
      bodies_.torque_n_m[i] = torque;
    }
  }
}

void Simulation::ComputeForces() {
  UpdatePairs();
  PlaceShapes();
  Collide();
  Gather();
  Drive();
}

// ---------------------------------------------------------------------------
// Stage 6: integration

void Simulation::VerletKickDrift() {
  ScopedTimer timer(profile_.integrate_s);
  const double h = dt_s_;
  const std::size_t n = bodies_.size();
  Internals& in = *in_;
  std::vector<Vec2>& v = bodies_.velocity_m_per_s;
  std::vector<double>& w = bodies_.angular_velocity_rad_per_s;
  in.v_half.resize(n);
  in.w_half.resize(n);
  // Half kick with the forces of the last evaluation and drift. The velocity-
  // dependent forces (dashpots, eqs. 11-12; eq. 3) at the new positions see the
  // predicted velocity v + h a(t). (A second-order Adams-Bashforth predictor was
  // tried: the restitution error is dominated by the timing of contact onset and
  // end within a step, which ContactLaw corrects, not by the predictor.)
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) {
      v[i] = {};
      w[i] = 0.0;
      in.v_half[i] = {};
      in.w_half[i] = 0.0;
      continue;
    }
    const Vec2 a = bodies_.force_n[i] / bodies_.mass_kg[i];
    const double alpha = bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i];
    in.v_half[i] = v[i] + (bodies_.force_n[i] + in.leading_force[i]) / bodies_.mass_kg[i] * (h / 2.0);
    in.w_half[i] = w[i] + (bodies_.torque_n_m[i] + in.leading_torque[i]) / bodies_.inertia_kg_m2[i] * (h / 2.0);
    bodies_.position_m[i] += in.v_half[i] * h;
    bodies_.angle_rad[i] += in.w_half[i] * h;
    Wrap(bodies_.position_m[i]);
    v[i] = in.v_half[i] + a * (h / 2.0);
    w[i] = in.w_half[i] + alpha * (h / 2.0);
  }
}

void Simulation::VerletKick() {
  ScopedTimer timer(profile_.integrate_s);
  const double h = dt_s_;
  Internals& in = *in_;
  const std::int64_t count = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) continue;
    bodies_.velocity_m_per_s[i] =
        in.v_half[i] + (bodies_.force_n[i] + in.trailing_force[i]) / bodies_.mass_kg[i] * (h / 2.0);
    bodies_.angular_velocity_rad_per_s[i] =
        in.w_half[i] + (bodies_.torque_n_m[i] + in.trailing_torque[i]) / bodies_.inertia_kg_m2[i] * (h / 2.0);
  }
}

void Simulation::GearPredict() {
  ScopedTimer timer(profile_.integrate_s);
  // Fifth-order Gear predictor-corrector for second-order equations, in
  // Nordsieck form r_k = h^k/k! d^k x/dt^k (Allen & Tildesley, Appendix E),
  // with the corrector coefficients for velocity-dependent forces (c0 = 3/16).
  const double h = dt_s_;
  const std::size_t n = bodies_.size();
  Internals& in = *in_;
  if (!in.gear_initialised) {
    in.gear_xy.assign(n, {});
    in.gear_theta.assign(n, {});
    for (std::size_t i = 0; i < n; ++i) {
      if (bodies_.state[i] != PersonState::kWalking) continue;
      in.gear_xy[i][0] = bodies_.force_n[i] / bodies_.mass_kg[i] * (h * h / 2.0);
      in.gear_theta[i][0] = bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i] * (h * h / 2.0);
    }
    in.gear_initialised = true;
  }
  std::vector<Vec2>& predicted_r2 = in.v_half;
  std::vector<double>& predicted_t2 = in.w_half;
  predicted_r2.resize(n);
  predicted_t2.resize(n);
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) {
      bodies_.velocity_m_per_s[i] = {};
      bodies_.angular_velocity_rad_per_s[i] = 0.0;
      in.gear_xy[i] = {};
      in.gear_theta[i] = {};
      continue;
    }
    predicted_r2[i] = GearPredictOne(bodies_.position_m[i], bodies_.velocity_m_per_s[i], in.gear_xy[i], h);
    predicted_t2[i] = GearPredictOne(bodies_.angle_rad[i], bodies_.angular_velocity_rad_per_s[i], in.gear_theta[i], h);
    Wrap(bodies_.position_m[i]);
  }
}

void Simulation::GearCorrect() {
  ScopedTimer timer(profile_.integrate_s);
  const double h = dt_s_;
  Internals& in = *in_;
  const std::vector<Vec2>& predicted_r2 = in.v_half;
  const std::vector<double>& predicted_t2 = in.w_half;
  const std::int64_t count = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) continue;
    GearCorrectOne(bodies_.position_m[i], bodies_.velocity_m_per_s[i], in.gear_xy[i],
                   bodies_.force_n[i] / bodies_.mass_kg[i] * (h * h / 2.0) - predicted_r2[i], h);
    Wrap(bodies_.position_m[i]);
    GearCorrectOne(bodies_.angle_rad[i], bodies_.angular_velocity_rad_per_s[i], in.gear_theta[i],
                   bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i] * (h * h / 2.0) - predicted_t2[i], h);
  }
}

// ---------------------------------------------------------------------------
// Stage 7: checks

void Simulation::Check() {
  ScopedTimer timer(profile_.check_s);
  // Look for a bad body in parallel (Collide already looked at the contacts);
  // if there is one, report the first as the serial scan below would.
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  bool bad_body = false;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies) reduction(|| : bad_body)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    const Vec2 x = bodies_.position_m[i], v = bodies_.velocity_m_per_s[i];
    bad_body = !std::isfinite(x.x + x.y + v.x + v.y + bodies_.angle_rad[i] + bodies_.angular_velocity_rad_per_s[i]) || bad_body;
  }
  if (!bad_body && !in_->overlap_beyond) return;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const Vec2 x = bodies_.position_m[i], v = bodies_.velocity_m_per_s[i];
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(v.x) || !std::isfinite(v.y) ||
        !std::isfinite(bodies_.angle_rad[i]) || !std::isfinite(bodies_.angular_velocity_rad_per_s[i]))
      throw SimulationError("non-finite state of " + PersonText(i) + " at t = " + FormatNumber(time_s_) +
                            " s (position " + FormatNumber(x.x) + ", " + FormatNumber(x.y) + "; velocity " +
                            FormatNumber(v.x) + ", " + FormatNumber(v.y) + ")",
                            i, -1, time_s_);
  }
  PreviousContacts previous(in_->previous_contacts);
  for (const Contact& c : contacts_) {
    const double ra = def_.shapes[bodies_.shape[c.a]].radius_m;
    const double rb = c.wall ? def_.walls[c.b].radius_m : def_.shapes[bodies_.shape[c.b]].radius_m;
    const Contact* before = c.wall ? previous.Find(PairKey(c), c.feature) : nullptr;
    const auto separation = [this](Vec2 x, Vec2 y) { return Separation(x, y); };
    if (before && WentThroughWall(c, *before, rb, ra + rb, separation)) {
      const Vec2 x = bodies_.position_m[c.a];
      throw SimulationError(PersonText(c.a) + " went through wall " + std::to_string(c.b) + " at t = " +
                            FormatNumber(time_s_) + " s near (" + FormatNumber(c.point_m.x) + ", " +
                            FormatNumber(c.point_m.y) + "), centre at (" + FormatNumber(x.x) + ", " +
                            FormatNumber(x.y) + "): the core crossed the wall line, a load beyond k_n (r_person + r_wall) = " +
                            FormatNumber(def_.parameters.normal_stiffness_n_per_m * (ra + rb)) +
                            " N on one point or too fast for the step (desired speed, time step)",
                            c.a, -1, time_s_);
    }
    if (!(c.overlap_m <= ra + rb)) {
      const std::string other = c.wall ? "wall " + std::to_string(c.b) : PersonText(c.b);
      throw SimulationError("overlap of " + PersonText(c.a) + " and " + other + " is " +
                            FormatNumber(c.overlap_m) + " m at t = " + FormatNumber(time_s_) +
                            " s, beyond the sum of their sphero-radii " + FormatNumber(ra + rb) +
                            " m: the cores interpenetrate (time step too large or forces too strong)",
                            c.a, c.wall ? -1 : std::int64_t{c.b}, time_s_);
    }
  }
}

// ---------------------------------------------------------------------------

void Simulation::Step() {
  in_->previous_contacts.swap(contacts_);
  advance_springs_ = true;
  if (def_.parameters.integrator == Integrator::kVelocityVerlet) {
    VerletKickDrift();
    ComputeForces();
    VerletKick();
  } else {
    GearPredict();
    ComputeForces();
    GearCorrect();
  }
  time_s_ = static_cast<double>(step_count_ + 1) * dt_s_;
  ++step_count_;
  Check();
}

void Simulation::AdvanceTo(double end_time_s) {
  while (time_s_ < end_time_s - 1e-12) Step();
}

void Simulation::Quench() {
  std::fill(bodies_.velocity_m_per_s.begin(), bodies_.velocity_m_per_s.end(), Vec2{});
  std::fill(bodies_.angular_velocity_rad_per_s.begin(), bodies_.angular_velocity_rad_per_s.end(), 0.0);
  in_->gear_initialised = false;
}

void Simulation::SetExternalForce(std::uint32_t person, Vec2 force_n) {
  if (person >= bodies_.size()) throw InputError("person index " + std::to_string(person) + " out of range");
  bodies_.external_force_n[person] = force_n;
  Drive();  // the force enters the current evaluation too
}

void Simulation::SetPersonState(std::uint32_t person, PersonState state) {
  if (person >= bodies_.size()) throw InputError("person index " + std::to_string(person) + " out of range");
  bodies_.state[person] = state;
  if (state != PersonState::kWalking) {
    bodies_.velocity_m_per_s[person] = {};
    bodies_.angular_velocity_rad_per_s[person] = 0.0;
  }
  in_->pairs_valid = false;
}

// ---------------------------------------------------------------------------
// Checkpoints

namespace {

constexpr char kStateMagic[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '1'};

// The checkpoint's writer and reader (binary_io.hpp, shared with world files).
class StateWriter : public detail::BinaryWriter {
 public:
  StateWriter() : BinaryWriter(kStateMagic) {}
};

class StateReader : public detail::BinaryReader {
 public:
  explicit StateReader(const std::string& data) : BinaryReader(data, kStateMagic, "checkpoint", "state") {}
};

}  // namespace

std::string Simulation::SaveState() const {
  StateWriter w;
  w.Put(static_cast<std::uint64_t>(bodies_.size()));
  w.Put(step_count_);
  w.Put(time_s_);
  w.Put(dt_s_);
  w.Put(advance_springs_);
  w.PutVector(bodies_.position_m);
  w.PutVector(bodies_.angle_rad);
  w.PutVector(bodies_.velocity_m_per_s);
  w.PutVector(bodies_.angular_velocity_rad_per_s);
  w.PutVector(bodies_.force_n);
  w.PutVector(bodies_.torque_n_m);
  w.PutVector(bodies_.contact_force_n);
  w.PutVector(bodies_.contact_torque_n_m);
  w.PutVector(bodies_.external_force_n);
  w.PutVector(bodies_.state);
  w.PutVector(bodies_.target);
  w.PutVector(bodies_.desired_speed_m_per_s);
  w.PutVector(contacts_);
  w.PutVector(in_->leading_force);
  w.PutVector(in_->leading_torque);
  w.Put(in_->gear_initialised);
  w.PutVector(in_->gear_xy);
  w.PutVector(in_->gear_theta);
  return w.Finish();
}

void Simulation::LoadState(const std::string& data) {
  StateReader r(data);
  const auto n = r.Get<std::uint64_t>();
  if (n != bodies_.size())
    throw InputError("checkpoint: holds " + std::to_string(n) + " people where this run has " +
                     std::to_string(bodies_.size()) + " (different scenario?)");
  step_count_ = r.Get<std::uint64_t>();
  time_s_ = r.Get<double>();
  const double dt = r.Get<double>();
  if (dt != dt_s_)
    throw InputError("checkpoint: time step " + FormatNumber(dt) + " s differs from this run's " +
                     FormatNumber(dt_s_) + " s (different scenario or parameters?)");
  advance_springs_ = r.Get<bool>();
  r.GetVector(bodies_.position_m, n);
  r.GetVector(bodies_.angle_rad, n);
  r.GetVector(bodies_.velocity_m_per_s, n);
  r.GetVector(bodies_.angular_velocity_rad_per_s, n);
  r.GetVector(bodies_.force_n, n);
  r.GetVector(bodies_.torque_n_m, n);
  r.GetVector(bodies_.contact_force_n, n);
  r.GetVector(bodies_.contact_torque_n_m, n);
  r.GetVector(bodies_.external_force_n, n);
  r.GetVector(bodies_.state, n);
  r.GetVector(bodies_.target, n);
  r.GetVector(bodies_.desired_speed_m_per_s, n);
  r.GetVector(contacts_);
  r.GetVector(in_->leading_force);
  r.GetVector(in_->leading_torque);
  in_->gear_initialised = r.Get<bool>();
  r.GetVector(in_->gear_xy);
  r.GetVector(in_->gear_theta);
  in_->pairs_valid = false;  // rebuilt on the next step; results do not depend on when
  in_->cuda_has_history = false;  // the device's last contacts are not these
  PlaceShapes();  // orientations of the restored angles (Drive reads them)
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
