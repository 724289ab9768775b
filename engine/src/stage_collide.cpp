// Stage collide: narrow phase and contact forces of every pair in the lists (eqs. 7-14, 19).
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "crowdrecon/common/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

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

}  // namespace

namespace detail {

// Everything the narrow phase and the contact law need for one evaluation,
// and the work on one chunk of the pair lists (kChunk pairs: person pairs
// first, then person-wall pairs). Chunks are independent: any thread may take
// any chunk; their contacts are concatenated in chunk order.
class PairCollider {
 public:
  PairCollider(const BodyState& bodies, Simulation::Internals& in, const PeriodicBox& box, const ContactLaw& law,
               const ContactLaw& wall_law)
      : bodies_(bodies), in_(in), box_(box), law_(law), wall_law_(wall_law),
        person_chunks_((in.pairs.size() + kChunk - 1) / kChunk),
        chunks_(person_chunks_ + (in.wall_pairs.size() + kChunk - 1) / kChunk) {}

  std::size_t person_chunks() const { return person_chunks_; }
  const ContactLaw& law() const { return law_; }
  std::size_t chunks() const { return chunks_; }

  // One chunk: its contacts appended to `out`, in pair order. Returns true if
  // one of them overlaps beyond the sum of the radii (see AddContacts).
  // `measured` counts the pairs given to the narrow phase (Profile::pairs_measured).
  bool Chunk(std::size_t chunk, std::vector<Contact>& out, std::vector<ContactPoint>& points,
             std::uint64_t& measured) const {
    return chunk < person_chunks_ ? PersonChunk(chunk, out, points, measured)
                                  : WallChunk(chunk - person_chunks_, out, points, measured);
  }

 private:
  PlacedShape Placed(std::uint32_t i, Vec2 position) const {
    return in_.ShapeAt(bodies_.shape[i], position, in_.cos_angle[i], in_.sin_angle[i]);
  }
  Vec2 VelocityAt(std::uint32_t i, Vec2 arm) const {
    if (bodies_.state[i] != PersonState::kWalking) return Vec2{};
    return bodies_.velocity_m_per_s[i] + Perp(arm) * bodies_.angular_velocity_rad_per_s[i];
  }
  // m_ij of eq. (14); against a fallen person, the walking one's mass.
  double EffectiveMass(std::uint32_t a, std::uint32_t b) const {
    const bool fa = bodies_.state[a] != PersonState::kWalking, fb = bodies_.state[b] != PersonState::kWalking;
    if (fa && fb) return 0.5 * (bodies_.mass_kg[a] + bodies_.mass_kg[b]);  // no dynamics; any positive value
    if (fa) return bodies_.mass_kg[b];
    if (fb) return bodies_.mass_kg[a];
    return bodies_.mass_kg[a] * bodies_.mass_kg[b] / (bodies_.mass_kg[a] + bodies_.mass_kg[b]);  // eq. (14)
  }

  // The contacts of one pair (persons a and b, or person a and wall b) at its
  // narrow-phase points, with the forces of `pair_law`; `relative_velocity(x)`
  // is a's velocity less b's at the point x. Returns true if a point overlaps
  // beyond `radii`, the sum of the two sphero-radii, or, for a wall, if a
  // vertex went through it (WentThroughWall): the cores interpenetrate, which
  // the check stage reports (and looks for only then).
  template <typename RelativeVelocity>
  bool AddContacts(const std::vector<ContactPoint>& points, std::uint32_t a, std::uint32_t b, bool wall,
                   const ContactLaw& pair_law, double mass, double radii, PreviousContacts& previous,
                   std::vector<Contact>& out, const RelativeVelocity& relative_velocity,
                   double wall_radius_m = 0.0) const {
    const auto minimum_image = [this](Vec2 x, Vec2 y) { return detail::Separation(box_, x, y); };
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
  }

  // Person pairs of chunk `chunk`, skipping those known to be still apart
  // (pair clearances, see Simulation::Internals).
  bool PersonChunk(std::size_t chunk, std::vector<Contact>& out, std::vector<ContactPoint>& points,
                   std::uint64_t& measured) const {
    PreviousContacts previous(in_.previous_contacts);
    bool overlap_beyond = false;
    const std::size_t end = std::min(in_.pairs.size(), (chunk + 1) * kChunk);
    for (std::size_t k = chunk * kChunk; k < end; ++k) {
      const auto [a, b] = in_.pairs[k];
      if (in_.Asleep(a) && in_.Asleep(b)) {  // two sleepers: their contacts as they were (docs/model.md, "Sleeping")
        previous.AppendPair(PairKey(false, a, b), out);
        continue;
      }
      Simulation::Internals::PairMotion& motion = in_.pair_motion[k];
      const double travel = in_.travel_m[a] + in_.travel_m[b];
      if (in_.pair_memory && motion.travel_offset + travel < in_.pair_clear.pair_m[k]) continue;  // still apart
      const Vec2 xa = bodies_.position_m[a];
      const Vec2 separation = detail::Separation(box_, xa, bodies_.position_m[b]);
      const double angle_a = bodies_.angle_rad[a], angle_b = bodies_.angle_rad[b];
      const double moved = motion.moved + Length(separation - motion.separation) +
                           in_.rotation_arm_m[a] * std::abs(angle_a - motion.angle_a) +
                           in_.rotation_arm_m[b] * std::abs(angle_b - motion.angle_b);
      if (in_.pair_memory && moved < in_.pair_clear.pair_m[k]) continue;  // still apart (see Internals)
      motion = {separation, angle_a, angle_b, moved, moved - travel};  // visited: the reference moves on
      if (bodies_.state[a] == PersonState::kRemoved || bodies_.state[b] == PersonState::kRemoved) continue;
      const Vec2 xb_image = xa - separation;
      const PlacedShape pa = Placed(a, xa), pb = Placed(b, xb_image);
      points.clear();
      ++measured;
      in_.pair_clear.Collide(k, moved, pa, pb, points, in_.pair_memory);
      if (points.empty()) continue;
      // (a and b captured by init-capture: clang 14, the fuzz build's compiler, cannot capture structured bindings)
      const auto relative_velocity = [&, a = a, b = b](Vec2 x) {
        return VelocityAt(a, x - xa) - VelocityAt(b, x - xb_image);
      };
      overlap_beyond = AddContacts(points, a, b, false, law_, EffectiveMass(a, b), pa.scale + pb.scale,  // (family radius 1)
                                   previous, out, relative_velocity) ||
                       overlap_beyond;
    }
    return overlap_beyond;
  }

  // Person-wall pairs of wall chunk `wchunk`.
  bool WallChunk(std::size_t wchunk, std::vector<Contact>& out, std::vector<ContactPoint>& points,
                 std::uint64_t& measured) const {
    PreviousContacts previous(in_.previous_contacts);
    bool overlap_beyond = false;
    const std::size_t end = std::min(in_.wall_pairs.size(), (wchunk + 1) * kChunk);
    for (std::size_t k = wchunk * kChunk; k < end; ++k) {
      const auto [a, w] = in_.wall_pairs[k];
      if (in_.Asleep(a)) {  // a sleeper against a wall: as it was
        previous.AppendPair(PairKey(true, a, w), out);
        continue;
      }
      const double moved = in_.travel_m[a];
      if (in_.pair_memory && moved < in_.wall_pair_clear.pair_m[k]) continue;  // still apart (see Internals)
      if (bodies_.state[a] == PersonState::kRemoved) continue;
      const Vec2 xa = bodies_.position_m[a];
      const PlacedShape pa = Placed(a, xa);
      PlacedShape pw;
      pw.geometry = &in_.wall_geometry[w];
      pw.position = in_.wall_origin[w];
      points.clear();
      ++measured;
      in_.wall_pair_clear.Collide(k, moved, pa, pw, points, in_.pair_memory);
      if (points.empty()) continue;
      const auto relative_velocity = [&, a = a](Vec2 x) { return VelocityAt(a, x - xa); };  // (init-capture: as above)
      overlap_beyond = AddContacts(points, a, w, true, wall_law_, bodies_.mass_kg[a], pa.scale + pw.geometry->radius_m,
                                   previous, out, relative_velocity, pw.geometry->radius_m) ||
                       overlap_beyond;
    }
    return overlap_beyond;
  }

  const BodyState& bodies_;
  Simulation::Internals& in_;
  const PeriodicBox& box_;
  const ContactLaw& law_;
  const ContactLaw& wall_law_;
  std::size_t person_chunks_, chunks_;
};

}  // namespace detail

// The contact list of this evaluation: on the CUDA device for person pairs
// when it computes (CollideOnDevice), else on one thread in chunk order, or on
// several with work stealing (CollideOnThreads); the same list in every case.
void Simulation::Collide() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kCollide)]);
  Internals& in = *in_;
  const ModelParameters& mp = def_.parameters;
  // The first evaluation (at construction) does not advance the springs.
  const ContactLaw law{mp.normal_stiffness_n_per_m, mp.tangential_stiffness_n_per_m, mp.friction_coefficient,
                       dt_s_, in.restitution_factor, mp.tangential_damping, mp.tangential_damping_rate_per_s,
                       mp.allow_tensile_normal_force, advance_springs_,
                       mp.tangential_spring != TangentialSpring::kNone,
                       mp.tangential_spring == TangentialSpring::kCreeping
                           ? std::exp(-dt_s_ / mp.tangential_spring_relaxation_time_s)
                           : 1.0,
                       next_dt_s_};
  ContactLaw wall_law = law;
  wall_law.damping_factor = in.wall_restitution_factor;
  const PairCollider collider(bodies_, in, def_.periodic, law, wall_law);
  if (in.cuda && in.asleep.empty() && CollideOnDevice(collider)) return;  // (sleeping: on the processor)
  if (def_.threads == 1 || collider.chunks() < 4) {
    // On one thread the chunks come in order: straight into the contact list,
    // which is then what the concatenation of CollideOnThreads would make.
    contacts_.clear();
    std::vector<ContactPoint> points;
    bool overlap_beyond = false;
    std::uint64_t measured = 0;
    for (std::size_t chunk = 0; chunk < collider.chunks(); ++chunk)
      overlap_beyond = collider.Chunk(chunk, contacts_, points, measured) || overlap_beyond;
    profile_.pairs_measured += measured;
    in.overlap_beyond = overlap_beyond;
    return;
  }
  CollideOnThreads(collider);
}

// Person pairs on the device, in list order; then the wall pairs here, as on
// the processor (they follow the person pairs in the contact list). False if
// the device failed: it is then dropped, and the processor computes this
// evaluation and the following ones, with the same results.
bool Simulation::CollideOnDevice(const PairCollider& collider) {
  Internals& in = *in_;
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
  input.law = collider.law();
  contacts_.clear();
  bool overlap_beyond = false;
  try {
    overlap_beyond = in.cuda->Collide(input, contacts_, in.device_sums);
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
    return false;
  }
  in.device_contacts = contacts_.size();
  in.cuda_has_history = true;
  const cuda::Collider::Timing timing = in.cuda->last_timing();
  profile_.device_copy_s += (timing.upload_ms + timing.download_ms) * 1e-3;
  profile_.device_kernels_s += timing.kernels_ms * 1e-3;
  std::vector<ContactPoint> points;
  std::uint64_t measured = in.pairs.size();  // the device measures every person pair
  for (std::size_t chunk = collider.person_chunks(); chunk < collider.chunks(); ++chunk)
    overlap_beyond = collider.Chunk(chunk, contacts_, points, measured) || overlap_beyond;
  profile_.pairs_measured += measured;
  in.overlap_beyond = overlap_beyond;
  return true;
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
void Simulation::CollideOnThreads(const PairCollider& collider) {
  Internals& in = *in_;
  const std::size_t chunks = collider.chunks();
  const std::int64_t total = static_cast<std::int64_t>(chunks);
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
        overlap_beyond = collider.Chunk(chunk, out, points, measured) || overlap_beyond;
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

}  // namespace crowdrecon::engine
