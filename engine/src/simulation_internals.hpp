// Private to the engine: what the stages of Simulation::Step share — the
// Internals of a Simulation (neighbour lists, pair clearances, integrator
// history, per-thread buffers) and small helpers. Each stage lives in a file
// of its own (engine/include/crowdrecon/engine/stages.hpp lists them).
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "behaviour.hpp"
#include "contact_law.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fast_math.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "cuda_collide.hpp"
#include "gather_core.hpp"
#include "minimum_image.hpp"

namespace crowdrecon::engine {

namespace detail {


// Pairs per work chunk. Chunks are fixed by the pair list, not by the thread
// count, and their outputs are concatenated in order: determinism by construction.
constexpr std::size_t kChunk = 64;

using Clock = std::chrono::steady_clock;

// Part q of `parts` contiguous, nearly equal parts of [0, count): the work a
// stage splits between threads in a fixed way (the results then do not
// depend on which thread takes which part).
struct Part {
  std::size_t begin, end;
};
inline Part PartOf(std::size_t count, std::size_t q, std::size_t parts) { return {count * q / parts, count * (q + 1) / parts}; }

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

// People are named by their id + 1, as in run files (a timeline's slot
// index is not its person's id: arrivals take whichever slot is free).
inline std::string PersonText(const BodyState& bodies, std::uint32_t slot) {
  return "person " + std::to_string(std::uint64_t{bodies.id[slot]} + 1);
}


// The periodic box (WorldDef::periodic): a position wrapped into it, and the
// minimum-image difference a - b. Inline: the stages call them in their loops.
inline void Wrap(const PeriodicBox& box, Vec2& p) {
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

// (Separation(box, a, b), the minimum-image difference a - b: behaviour.hpp, shared with the behaviour terms.)

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

  // Every contact of the pair `key` in the previous evaluation, appended to
  // `out` in their order (a pair of sleepers: carried unchanged). The same
  // cursor as Find: lookups in increasing order move it forward.
  void AppendPair(std::uint64_t key, std::vector<Contact>& out) {
    const auto before = [&](const Contact& c) { return PairKey(c) < key; };
    if (!started_ || key < last_key_) {
      pos_ = static_cast<std::size_t>(std::partition_point(previous_.begin(), previous_.end(), before) - previous_.begin());
      started_ = true;
    } else {
      while (pos_ < previous_.size() && before(previous_[pos_])) ++pos_;
    }
    last_key_ = key;
    last_feature_ = 0;
    for (; pos_ < previous_.size() && PairKey(previous_[pos_]) == key; ++pos_) out.push_back(previous_[pos_]);
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
inline bool WentThroughWall(const Contact& now, const Contact& before, double wall_radius_m, double reach_m,
                     const Separation& separation) {
  if ((now.feature & kVertexOfB) != 0) return false;  // a wall's vertex against the person's core
  const auto closest = [&](const Contact& c) { return c.point_m - c.normal * (wall_radius_m - c.overlap_m / 2.0); };
  const Vec2 vertex = closest(now) + now.normal * (reach_m - now.overlap_m);
  return Dot(separation(vertex, closest(before)), before.normal) < 0.0 && Dot(now.normal, before.normal) < 0.0;
}

}  // namespace detail

struct Simulation::Internals {
  // Geometry of every shape family and wall in its own frame (narrow_phase.hpp).
  // Shapes that are uniform scalings of one another share a family geometry
  // in units of their sphero-radius: shape k is family shape_family[k] scaled
  // by shape_scale[k].
  std::vector<ShapeGeometry> family_geometry;
  std::vector<std::uint32_t> shape_family;
  std::vector<double> shape_scale;
  // Shape `shape` for the narrow phase, at `position` turned by (cos, sin).
  PlacedShape ShapeAt(std::uint32_t shape, Vec2 position, double c, double s) const {
    PlacedShape p;
    p.geometry = &family_geometry[shape_family[shape]];
    p.scale = shape_scale[shape];
    p.position = position;
    p.cos_angle = c;
    p.sin_angle = s;
    return p;
  }
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
  detail::PairClearances pair_clear, wall_pair_clear;
  bool pair_memory = true;  // SetPairMemory

  // Per-group back force Gamma and torsion stiffness lambda (SetGroupDrive),
  // NaN where the group uses the model's; empty when no group has its own.
  std::vector<double> group_gamma, group_lambda;

  // Contact-law constants.
  double restitution_factor = 0.0;       // 2 L / sqrt(pi^2 + L^2), L = -ln(eps)
  double wall_restitution_factor = 0.0;  // same for walls

  // Sleeping (ModelParameters::sleep_speed_m_per_s > 0; docs/model.md,
  // "Sleeping"; stage_sleep.cpp): per slot, whether the person sleeps, how
  // long their still spell has lasted (0: none), where it began, and the
  // frozen drive (the mean load of the spell turned round; while awake, its
  // running value). Empty when sleeping is off. Checkpointed.
  std::vector<std::uint8_t> asleep;
  std::vector<double> still_s;
  std::vector<Vec2> sleep_drive_force;
  std::vector<double> sleep_drive_torque;
  std::vector<Vec2> sleep_anchor;
  std::vector<double> sleep_anchor_angle;
  bool Asleep(std::size_t i) const { return !asleep.empty() && asleep[i] != 0; }

  // Gear predictor-corrector: scaled derivatives r2..r5 for x, y, theta.
  std::vector<std::array<Vec2, 4>> gear_xy;     // r2, r3, r4, r5
  std::vector<std::array<double, 4>> gear_theta;
  bool gear_initialised = false;

  // The run's behaviour terms (behaviour.hpp), each with its own per-person
  // state; made at construction, made again when the parameters change.
  detail::ActiveTerms terms;
  // For terms that need people ahead (ActiveTerms::people_ahead), derived in
  // Drive from the contacts (not in the checkpoint): per body, its desired
  // direction and the sum of the backward parts of its contact forces from
  // people ahead (<= 0).
  std::vector<Vec2> desired_direction;
  std::vector<double> held_back_n;
  // The neighbour stage's list (empty unless a term asks for neighbours),
  // with the positions at its build and the skin its candidates carry.
  // Which slots are candidates in it (those in the venue at its build and
  // those come back since: Simulation::ListComebacks).
  detail::NeighbourList neighbours;
  std::vector<Vec2> neighbours_position_at_build;
  std::vector<std::uint8_t> neighbours_listed;
  // The build's work space: per chunk of people, their candidates and near
  // candidates (stage_neighbours.cpp), kept between builds.
  std::vector<std::vector<std::uint32_t>> neighbour_chunks, near_chunks;
  double requested_neighbour_radius_m = 0.0;  // Simulation::RequestNeighbours
  // The time at which Drive evaluates the forces (s): within a step, the end
  // of the step (the integrators evaluate there), between steps time_s_.
  // Only the gait jitter (a function of time) reads it.
  double drive_time_s = 0.0;

  // Per body, the navigation field's cell it last sampled (Drive,
  // AverageBackForceTrigger): the grid is read only when someone enters a
  // new cell. A cache names its field and cell, so it is never stale (the
  // fields do not change); nothing about it is saved in checkpoints.
  std::vector<geometry::NavigationField::CellCache> field_cache;

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

}  // namespace crowdrecon::engine
