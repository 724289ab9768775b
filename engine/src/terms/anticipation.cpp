// Term anticipation (ModelParameters::anticipation = time_to_collision; issue
// 64, off by default): anticipation by the time to collision (Karamouzas,
// Skinner and Guy, "Universal power law governing pedestrian interactions",
// Phys. Rev. Lett. 113:238701, 2014), a force beside the contact forces.
//
// Force phase, on each walking person i from every other person j in the
// venue (walking or fallen) within anticipation_radius_m: with x = x_i - x_j
// (minimum image), v = v_i - v_j and R = r_i + r_j the sum of the bounding
// radii, the time to collision tau is the smaller root of |x + v t| = R,
//   a t^2 + 2 b t + c = 0,  a = v.v, b = x.v, c = x.x - R^2,
// tau = c / (-b + sqrt(D)), D = b^2 - a c; there is none when the two move
// apart (b >= 0), miss each other (D <= 0) or their bounding circles
// already overlap (c <= 0: the contact forces act there). The energy
// E(tau) = k tau^-2 exp(-tau / tau0) per unit mass gives the force
//   F = -m_i dE/dtau d(tau)/dx = m_i k exp(-tau/tau0) tau^-2 (2/tau + 1/tau0) (x + v tau) / sqrt(D)
// (d(tau)/dx = (x + v tau) / sqrt(D), from differentiating the quadratic):
// along x + v tau, the direction from j to i at the moment they would touch.
// Its size is capped at m_i anticipation_max_acceleration_m_per_s2 per
// neighbour (tau -> 0 makes it diverge; the ceiling is ours, twice eq. 3's
// largest push at the venues' speeds, 1.2 m/s / 0.5 s). The neighbour radius: anticipation_radius_m (Karamouzas et al.
// looked 10 m; people closing at 2.6 m/s from 5 m meet in under 2 s, so
// half of it keeps the collisions that matter at a quarter of the cost).
// It acts on people who want to walk (desired speed > 0): the force is the
// change of a walker's chosen velocity (Karamouzas et al.'s agents choose a
// velocity toward a goal), and a person who stands by choice (desired speed
// 0: waiting for a pre-movement time, told to stand) chooses none; walkers
// avoid them all the same (their own force, with the standing person as j),
// and the contact forces act as ever (as the gait jitter, gait_jitter.cpp).
// Summed in the neighbour list's order: the same on any thread count.
//
// Each pair once (issue 66; evaluated at every step, without the clock):
// the force per unit mass of j on i is exactly minus that of i on j, bit for
// bit (x, v and x + v tau change sign exactly in IEEE arithmetic, the
// minimum image too; a, b, c, D, tau, the size and the ceiling are the same
// numbers), and the pick of collision courses is the same test from either
// side. So before the blocks, each in-venue person i visits only the
// candidates j > i of their list (a suffix: the list is in increasing
// index; a pair within the radius is on both lists) and records the
// colliding pairs with their force, by blocks of people on the threads;
// then each pair, in the blocks' order, adds its force to i and takes it
// from j (on the threads, each owning a part of the people). A person's sum
// so gets their partners k < i (each from k's visit, in increasing k)
// before their own j > i (in increasing j): in increasing partner index,
// each term the very number the whole list gave, so the run is the one that
// walked each person's whole list, bit for bit (UseHalfPairs switches back,
// for tests and benchmarks), at half the pair tests. Pairs where neither
// person is a walker who wants to walk are not recorded. Where most people
// stand (an evacuation before its pre-movement times), the walkers' whole
// lists are fewer tests: each evaluation takes the cheaper of the two
// (EachPairOnceIsCheaper), which changes no result.
//
// Its side preference (anticipation_side_preference s, 0 off): with e_i the
// direction the person wants to go and F the summed force per unit mass,
// the braking part B = -F.e_i (where positive) gives F + s B (e_y, -e_x),
// a step to the right of e_i (to the left for s < 0). Without it two
// people on one line brake straight at each other and only the jitter
// decides who steps aside (a counter-flow's fronts meet across a corridor's
// width and lock: IMO test 8); with it both step to their own right, as
// most people where traffic keeps right do (Moussaid et al., Proc. R. Soc.
// B 276:2755, 2009; Xiao et al., Transp. Res. C 2019: about 70 % to the
// right in circle-antipode experiments). On the summed force, once per
// person per step (on the clock: on the kept force plus the near one).
//
// Its clock (anticipation_interval_s, issue 66): 0, evaluated at every step
// (no state). Else the force from people beyond anticipation_near_m is
// evaluated at the first step of each interval [k h, (k+1) h) of the drive's
// time and kept, per unit mass, until the next interval, while the force
// from people within it is evaluated at every step (multiple time stepping
// with a split by distance, as molecular dynamics splits its long-range
// forces from its short-range ones: Tuckerman, Berne and Martyna, J. Chem.
// Phys. 97:1990, 1992; the force of people metres away changes over tenths
// of a second, that of people an arm's length away with every jostle). The
// split is smooth: a pair at centre distance r counts near with the share
// S(r) = 1 within anticipation_near_m - w, falling linearly to 0 at
// anticipation_near_m (w = min(kSwitch_m, anticipation_near_m)), and far
// with 1 - S(r), so that a pair crossing the boundary changes the force
// gradually. anticipation_near_m 0: every pair on the clock. The near pairs
// come from the neighbour stage's near list (within anticipation_near_m +
// its skin), so a step walks the near list only.
// The kept forces and the interval each was evaluated in are the term's
// state (its checkpoint section: a resumed run is the run made in one go);
// a person placed, stopped or quenched has none kept (evaluated at their
// next step). The blocks write each their own people's entries (no two
// threads the same person): the same on any thread count.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CROWDRECON_WIDE_FILTER 1
#endif

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

bool wide_allowed = true;
bool half_pairs_allowed = true;

// A person as the pair loops read them: position, velocity and bounding
// radius in one cache line (a copy made for each evaluation; x NaN for an
// empty slot: it then fails the wide filter's test, as the scalar loop
// skips it).
struct alignas(64) Candidate {
  double x, y, vx, vy, bound, unused[3];
};

#ifdef CROWDRECON_WIDE_FILTER
// MinimumImage, four at a time: |d| > p/2 ? d - p * nearbyint(d / p) : d.
__attribute__((target("avx2"), always_inline)) inline __m256d MinimumImageWide(__m256d d, __m256d p, __m256d half) {
  const __m256d far = _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), d), half, _CMP_GT_OQ);
  const __m256d k = _mm256_round_pd(_mm256_div_pd(d, p), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  return _mm256_blendv_pd(d, _mm256_sub_pd(d, _mm256_mul_pd(p, k)), far);
}

// Person i (at xi, moving at vi, bounding radius ri) and the box, broadcast
// to four lanes for the loops below.
struct WideFrame {
  __m256d xix, xiy, vix, viy, rib, px, hx, py, hy;
  bool periodic_x, periodic_y;
};
__attribute__((target("avx2"), always_inline)) inline WideFrame MakeWideFrame(const PeriodicBox& box, Vec2 xi,
                                                                                Vec2 vi, double ri) {
  const double period_x = box.max_m.x - box.min_m.x, period_y = box.max_m.y - box.min_m.y;
  return WideFrame{_mm256_set1_pd(xi.x),          _mm256_set1_pd(xi.y),
                   _mm256_set1_pd(vi.x),          _mm256_set1_pd(vi.y),
                   _mm256_set1_pd(ri),            _mm256_set1_pd(period_x),
                   _mm256_set1_pd(period_x / 2.0), _mm256_set1_pd(period_y),
                   _mm256_set1_pd(period_y / 2.0), box.x,
                   box.y};
}

// Approaching's terms for four candidates j0..j3 of person i, with the same
// IEEE operations in the same order (no fused multiply-add).
struct WideTerms {
  __m256d dx, dy, wx, wy, reach, xx, bb, c, discriminant;
};
__attribute__((target("avx2"), always_inline)) inline WideTerms ApproachWide(const Candidate* q, const WideFrame& f,
                                                                               std::uint32_t j0, std::uint32_t j1,
                                                                               std::uint32_t j2, std::uint32_t j3) {
  WideTerms t;
  const __m256d r0 = _mm256_load_pd(&q[j0].x), r1 = _mm256_load_pd(&q[j1].x);
  const __m256d r2 = _mm256_load_pd(&q[j2].x), r3 = _mm256_load_pd(&q[j3].x);
  // (x, y, vx, vy) of four people transposed to x4, y4, vx4, vy4
  const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
  const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
  const __m256d x4 = _mm256_permute2f128_pd(t0, t2, 0x20), y4 = _mm256_permute2f128_pd(t1, t3, 0x20);
  const __m256d vx4 = _mm256_permute2f128_pd(t0, t2, 0x31), vy4 = _mm256_permute2f128_pd(t1, t3, 0x31);
  t.dx = _mm256_sub_pd(f.xix, x4);
  t.dy = _mm256_sub_pd(f.xiy, y4);
  if (f.periodic_x) t.dx = MinimumImageWide(t.dx, f.px, f.hx);
  if (f.periodic_y) t.dy = MinimumImageWide(t.dy, f.py, f.hy);
  t.wx = _mm256_sub_pd(f.vix, vx4);
  t.wy = _mm256_sub_pd(f.viy, vy4);
  t.reach = _mm256_add_pd(f.rib, _mm256_set_pd(q[j3].bound, q[j2].bound, q[j1].bound, q[j0].bound));
  t.xx = _mm256_add_pd(_mm256_mul_pd(t.dx, t.dx), _mm256_mul_pd(t.dy, t.dy));
  const __m256d a = _mm256_add_pd(_mm256_mul_pd(t.wx, t.wx), _mm256_mul_pd(t.wy, t.wy));
  t.bb = _mm256_add_pd(_mm256_mul_pd(t.dx, t.wx), _mm256_mul_pd(t.dy, t.wy));
  t.c = _mm256_sub_pd(t.xx, _mm256_mul_pd(t.reach, t.reach));
  t.discriminant = _mm256_sub_pd(_mm256_mul_pd(t.bb, t.bb), _mm256_mul_pd(a, t.c));
  return t;
}

// For each mask of four lanes, the bytes that move the chosen lanes' 32-bit
// values to the front (in order), and how many there are.
alignas(16) constexpr std::uint8_t kPack[16][16] = {
    {0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {4, 5, 6, 7, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 4, 5, 6, 7, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {8, 9, 10, 11, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 8, 9, 10, 11, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {4, 5, 6, 7, 8, 9, 10, 11, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0x80, 0x80, 0x80, 0x80},
    {12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {4, 5, 6, 7, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80},
    {8, 9, 10, 11, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80},
    {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0x80, 0x80, 0x80, 0x80},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15}};
constexpr std::uint32_t kPackCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// The candidates of person i (at xi, moving at vi, bounding radius ri) among
// items[m, end) that would collide, while four are left (m is advanced; the
// caller tests the last few one at a time): Approaching's test, four at a
// time (AVX2), with the same IEEE operations in the same order (no fused
// multiply-add): the same picks, bit for bit. Their indices are appended to
// hits[count..] in the list's order (four are written each time: hits has
// room for three more than the candidates); returns the new count.
__attribute__((target("avx2"))) std::uint32_t PickCollidingWide(const Candidate* q, const PeriodicBox& box,
                                                                 const std::uint32_t* items, std::uint32_t& m,
                                                                 std::uint32_t end, Vec2 xi, Vec2 vi, double ri,
                                                                 double radius, std::uint32_t* hits,
                                                                 std::uint32_t count) {
  const WideFrame f = MakeWideFrame(box, xi, vi, ri);
  const __m256d radius2 = _mm256_set1_pd(radius * radius), zero = _mm256_setzero_pd();
  for (; m + 4 <= end; m += 4) {
    const WideTerms t = ApproachWide(q, f, items[m], items[m + 1], items[m + 2], items[m + 3]);
    const __m256d xx = t.xx, c = t.c, bb = t.bb, discriminant = t.discriminant;
    __m256d collides = _mm256_cmp_pd(xx, radius2, _CMP_NGT_UQ);  // !(xx > radius^2)
    collides = _mm256_and_pd(collides, _mm256_cmp_pd(c, zero, _CMP_GT_OQ));
    collides = _mm256_and_pd(collides, _mm256_cmp_pd(bb, zero, _CMP_LT_OQ));
    collides = _mm256_and_pd(collides, _mm256_cmp_pd(discriminant, zero, _CMP_GT_OQ));
    // The picks' indices packed to the front (no branch: whether one of four
    // collides is not predictable), four stored, the count advanced.
    const auto mask = static_cast<unsigned>(_mm256_movemask_pd(collides));
    const __m128i packed = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(items + m)),
                                            _mm_load_si128(reinterpret_cast<const __m128i*>(kPack[mask])));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(hits + count), packed);
    count += kPackCount[mask];
  }
  return count;
}

// The forces per unit mass of the picks hits[0, count) on person i, four at
// a time while four are left (AVX2): Approaching's terms and the force of
// AnticipationTerm::ForEachCollision with the same IEEE operations in the
// same order (no fused multiply-add; the square root and the divisions are
// correctly rounded either way), exp from the library lane by lane; the
// force of hits[h] into (ax[h], ay[h]). Returns how many were done (a
// multiple of four: the caller does the rest one at a time).
__attribute__((target("avx2"))) std::uint32_t CollisionForcesWide(const Candidate* q, const PeriodicBox& box,
                                                                   const std::uint32_t* hits, std::uint32_t count,
                                                                   Vec2 xi, Vec2 vi, double ri, double k,
                                                                   double inverse_horizon, double ceiling, double* ax,
                                                                   double* ay) {
  const WideFrame f = MakeWideFrame(box, xi, vi, ri);
  const __m256d kb = _mm256_set1_pd(k), ih = _mm256_set1_pd(inverse_horizon);
  const __m256d ceilingb = _mm256_set1_pd(ceiling), two = _mm256_set1_pd(2.0);
  std::uint32_t h = 0;
  for (; h + 4 <= count; h += 4) {
    const WideTerms t = ApproachWide(q, f, hits[h], hits[h + 1], hits[h + 2], hits[h + 3]);
    const __m256d dx = t.dx, dy = t.dy, wx = t.wx, wy = t.wy, reach = t.reach, bb = t.bb, c = t.c;
    const __m256d discriminant = t.discriminant;
    const __m256d root = _mm256_sqrt_pd(discriminant);
    const __m256d tau = _mm256_div_pd(c, _mm256_sub_pd(root, bb));
    alignas(32) double exponent[4];
    _mm256_store_pd(exponent, _mm256_mul_pd(_mm256_xor_pd(tau, _mm256_set1_pd(-0.0)), ih));  // -tau * 1/tau0
    for (double& e : exponent) e = std::exp(e);
    const __m256d size = _mm256_div_pd(
        _mm256_mul_pd(_mm256_div_pd(_mm256_mul_pd(kb, _mm256_load_pd(exponent)), _mm256_mul_pd(tau, tau)),
                      _mm256_add_pd(_mm256_div_pd(two, tau), ih)),
        root);
    const __m256d acceleration = _mm256_min_pd(ceilingb, _mm256_mul_pd(size, reach));  // std::min(size reach, ceiling)
    const __m256d factor = _mm256_div_pd(acceleration, reach);
    _mm256_storeu_pd(ax + h, _mm256_mul_pd(_mm256_add_pd(dx, _mm256_mul_pd(wx, tau)), factor));
    _mm256_storeu_pd(ay + h, _mm256_mul_pd(_mm256_add_pd(dy, _mm256_mul_pd(wy, tau)), factor));
  }
  return h;
}
#endif

}  // namespace

namespace {

// The width of the switch between near and far.
constexpr double kSwitch_m = 0.5;

class AnticipationTerm final : public BehaviourTerm {
 public:
  explicit AnticipationTerm(const ModelParameters& p, const WorldDef& def) : clocked_(p.anticipation_interval_s > 0.0) {
    Retune(p);
    bound_m_.reserve(def.shapes.size());
    for (const BodyShape& s : def.shapes) bound_m_.push_back(s.core_radius_m + s.radius_m);
  }
  unsigned phases() const override { return kForce | kPrepare; }

  double neighbour_radius_m() const override { return radius_m_; }
  double near_radius_m() const override { return near_m_; }
  void Retune(const ModelParameters& p) override {
    radius_m_ = p.anticipation_radius_m;
    near_m_ = clocked_ ? std::min(p.anticipation_near_m, radius_m_) : 0.0;
    switch_m_ = std::min(kSwitch_m, near_m_);
  }

  // The copy of the people the pair loops read, and whether the wide
  // filter is in use.
  void Prepare(const DriveInputs& in) const override {
    wide_ = WideInstructions();
    const std::size_t n = in.bodies.size();
    copy_.resize(n);
    acts_.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      const Vec2 x = in.bodies.position_m[j], v = in.bodies.velocity_m_per_s[j];
      const bool empty = in.bodies.state[j] == PersonState::kRemoved;
      copy_[j] = Candidate{empty ? std::numeric_limits<double>::quiet_NaN() : x.x, x.y, v.x, v.y,
                           bound_m_[in.bodies.shape[j]], {}};
      acts_[j] = in.bodies.state[j] == PersonState::kWalking && in.def.parameters.ground_reaction &&
                 WantsToWalk(in.bodies, j);
    }
    halved_ = !clocked_ && half_pairs_allowed && EachPairOnceIsCheaper(in);
    if (halved_) SumEachPairOnce(in);
  }

  // Whether visiting each pair once tests fewer candidates than the walkers'
  // whole lists: everyone in the venue visits their later candidates, while
  // the whole lists are visited by walkers who want to walk only (where
  // most people stand, waiting to set off, the whole lists are cheaper).
  // Either way the same run, bit for bit: this chooses the cost alone.
  bool EachPairOnceIsCheaper(const DriveInputs& in) const {
    const NeighbourList& list = in.neighbours;
    const BodyState& bodies = in.bodies;
    std::size_t whole = 0, once = 0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (bodies.state[i] == PersonState::kRemoved) continue;
      const std::size_t listed = list.start[i + 1] - list.start[i];
      if (acts_[i]) whole += listed;
      once += listed / 2;
    }
    return once < whole;
  }

  // A candidate j of person i (at xi, moving at vi, bounding radius ri): the
  // quadratic's terms, and whether the two would touch (within the radius,
  // not yet touching, closing in, not missing each other).
  struct Approach {
    Vec2 x, v;
    double xx, reach, bb, c, discriminant;
    bool collides;
  };
  Approach Approaching(const DriveInputs& in, Vec2 xi, Vec2 vi, double ri, std::uint32_t j) const {
    Approach p;
    const Candidate& q = copy_[j];  // (j is in the venue: its x is its own)
    p.x = Separation(in.def.periodic, xi, Vec2{q.x, q.y});  // x_i - x_j
    p.xx = Dot(p.x, p.x);
    p.v = vi - Vec2{q.vx, q.vy};
    p.reach = ri + q.bound;
    const double a = Dot(p.v, p.v);
    p.bb = Dot(p.x, p.v);
    p.c = p.xx - p.reach * p.reach;
    p.discriminant = p.bb * p.bb - a * p.c;
    p.collides = !(p.xx > radius_m_ * radius_m_) & (p.c > 0.0) & (p.bb < 0.0) & (p.discriminant > 0.0);
    return p;
  }

  // Which pairs of a sum count, and with what share.
  enum class Pairs { kAll, kNear, kFar };

  // The force per unit mass on i from its candidates items[begin, end) (the
  // pairs of `which`), in their order. In chunks of the list: step one picks
  // the candidates that would collide (most do not: they move apart, miss,
  // or are out of reach), without a branch on the geometry (which way a
  // candidate goes is not predictable: the branches cost more than the
  // arithmetic; only empty slots are skipped first); step two recomputes
  // the pair's terms and its force for each pick, in the list's order
  // (recomputing a few picks is cheaper than storing every candidate's).
  // With kAll, step one takes four candidates at a time where the processor
  // has AVX2 (PickCollidingWide: the same picks). With kAll, the same
  // arithmetic as one loop over the candidates, so the same sums.
  // Calls visit(j, a) for each of them that collides, a the force per unit
  // mass of j on i (its share, split), in the list's order.
  template <Pairs which, class Visit>
  void ForEachCollision(const DriveInputs& in, const std::vector<std::uint32_t>& items, std::uint32_t begin,
                        std::uint32_t end, Vec2 xi, Vec2 vi, double ri, Visit&& visit) const {
    const ModelParameters& mp = in.def.parameters;
    const double k = mp.anticipation_strength_m2, inverse_horizon = 1.0 / mp.anticipation_horizon_s;
    const double ceiling = mp.anticipation_max_acceleration_m_per_s2;
    const double inner = near_m_ - switch_m_;  // S = 1 within it
    for (std::uint32_t m = begin; m < end;) {
      const std::uint32_t chunk_end = std::min<std::uint32_t>(end, m + kChunk);
      std::uint32_t hits[kChunk + 3];
      std::uint32_t count = 0;
#ifdef CROWDRECON_WIDE_FILTER
      if constexpr (which == Pairs::kAll)
        if (wide_)
          count = PickCollidingWide(copy_.data(), in.def.periodic, items.data(), m, chunk_end, xi, vi, ri, radius_m_,
                                    hits, count);
#endif
      for (; m < chunk_end; ++m) {
        const std::uint32_t j = items[m];
        // (Empty slots are listed: an evening's engine holds hundreds,
        // parked together in the list's order, so this branch is predictable.)
        if (in.bodies.state[j] == PersonState::kRemoved) continue;
        const Approach p = Approaching(in, xi, vi, ri, j);
        bool counts = p.collides;
        if constexpr (which == Pairs::kNear) counts = counts & (p.xx < near_m_ * near_m_);
        if constexpr (which == Pairs::kFar) counts = counts & (p.xx > inner * inner);
        hits[count] = j;
        count += static_cast<std::uint32_t>(counts);
      }
      std::uint32_t h = 0;
#ifdef CROWDRECON_WIDE_FILTER
      if constexpr (which == Pairs::kAll)
        if (wide_) {
          double ax[kChunk + 3], ay[kChunk + 3];
          h = CollisionForcesWide(copy_.data(), in.def.periodic, hits, count, xi, vi, ri, k, inverse_horizon, ceiling,
                                  ax, ay);
          for (std::uint32_t w = 0; w < h; ++w) visit(hits[w], Vec2{ax[w], ay[w]});
        }
#endif
      for (; h < count; ++h) {
        const Approach p = Approaching(in, xi, vi, ri, hits[h]);
        const double root = std::sqrt(p.discriminant);
        const double tau = p.c / (root - p.bb);
        const double size = k * std::exp(-tau * inverse_horizon) / (tau * tau) * (2.0 / tau + inverse_horizon) / root;
        const Vec2 at_contact = p.x + p.v * tau;  // |at_contact| = reach
        double acceleration = std::min(size * p.reach, ceiling);
        if constexpr (which != Pairs::kAll) {
          const double near_share = std::clamp((near_m_ - std::sqrt(p.xx)) / switch_m_, 0.0, 1.0);
          acceleration *= which == Pairs::kNear ? near_share : 1.0 - near_share;
        }
        visit(hits[h], at_contact * (acceleration / p.reach));
      }
    }
  }
  template <Pairs which>
  Vec2 Sum(const DriveInputs& in, const std::vector<std::uint32_t>& items, std::uint32_t begin, std::uint32_t end,
           Vec2 xi, Vec2 vi, double ri) const {
    Vec2 push{};
    ForEachCollision<which>(in, items, begin, end, xi, vi, ri, [&push](std::uint32_t, Vec2 a) { push += a; });
    return push;
  }

  // Each pair once (the file's head): every person's sum of the whole
  // list's pairs into summed_.
  void SumEachPairOnce(const DriveInputs& in) const {
    const BodyState& bodies = in.bodies;
    const NeighbourList& list = in.neighbours;
    const auto n = static_cast<std::int64_t>(bodies.size());
    const std::int64_t blocks = (n + kPairBlock - 1) / kPairBlock;
    if (pairs_.size() < static_cast<std::size_t>(blocks)) {
      pairs_.resize(static_cast<std::size_t>(blocks));
      crossing_.resize(static_cast<std::size_t>(blocks));
    }
    // The parts of the people the threads sum for (below): part q is
    // [n q / parts, n (q + 1) / parts).
    const int parts = n >= kParallelBodies ? std::max(1, in.def.threads) : 1;
    const auto part_end = [n, parts](std::uint32_t i) {  // the end of i's part
      int q = static_cast<int>(static_cast<std::int64_t>(i) * parts / n);
      while (n * (q + 1) / parts <= i) ++q;  // (rounding: at most once)
      return static_cast<std::uint32_t>(n * (q + 1) / parts);
    };
#pragma omp parallel for schedule(dynamic) num_threads(in.def.threads) if (n >= kParallelBodies)
    for (std::int64_t block = 0; block < blocks; ++block) {
      std::vector<Pair>& found = pairs_[static_cast<std::size_t>(block)];
      std::vector<Pair>& crossing = crossing_[static_cast<std::size_t>(block)];
      found.clear();
      crossing.clear();
      const std::int64_t last = std::min(n, (block + 1) * kPairBlock);
      for (auto i = static_cast<std::uint32_t>(block * kPairBlock); i < last; ++i) {
        if (bodies.state[i] == PersonState::kRemoved) continue;
        const std::uint32_t own_part_end = part_end(i);
        ForEachCollision<Pairs::kAll>(in, list.items, list.later[i], list.start[i + 1], bodies.position_m[i],
                                      bodies.velocity_m_per_s[i], bound_m_[bodies.shape[i]],
                                      [&](std::uint32_t j, Vec2 a) {
                                        if (!(acts_[i] || acts_[j])) return;
                                        found.push_back(Pair{i, j, a});
                                        if (j >= own_part_end) crossing.push_back(Pair{i, j, a});
                                      });
      }
    }
    // The sums: each thread owns a part of the people and goes through the
    // pairs in their order, adding those that touch its own (each person's
    // in the order of the serial pass). A block of people wholly before the
    // part touches it only by its pairs that cross into a later part (kept
    // apart, in their order); pairs are in increasing i, so a part is done
    // at the first block past it.
    summed_.assign(bodies.size(), Vec2{});
#pragma omp parallel for schedule(static) num_threads(parts)
    for (int part = 0; part < parts; ++part) {
      const auto low = static_cast<std::uint32_t>(n * part / parts);
      const auto high = static_cast<std::uint32_t>(n * (part + 1) / parts);
      for (std::int64_t block = 0; block < blocks && block * kPairBlock < high; ++block) {
        const bool before = (block + 1) * kPairBlock <= low;
        for (const Pair& p : (before ? crossing_ : pairs_)[static_cast<std::size_t>(block)]) {
          if (p.i >= low && p.i < high) summed_[p.i] += p.a;
          if (p.j >= low && p.j < high) summed_[p.j] -= p.a;
        }
      }
    }
  }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const NeighbourList& list = in.neighbours;
    // (The interval the drive's time is in; a clocked run keeps a positive interval.)
    const double tick = clocked_ ? std::floor(in.time_s / in.def.parameters.anticipation_interval_s) : 0.0;
    const bool split = near_m_ > 0.0;
    const double side = in.def.parameters.anticipation_side_preference;
    const bool gate_slowed = in.def.parameters.anticipation_side_gate == SidePreferenceGate::kSlowed;
    for (std::size_t n = 0; n < b.count; ++n) {
      const std::size_t i = b.first + n;
      if (!b.driven[n] || !WantsToWalk(in.bodies, i)) continue;
      const Vec2 xi = in.bodies.position_m[i], vi = in.bodies.velocity_m_per_s[i];
      const double ri = bound_m_[in.bodies.shape[i]];
      Vec2 push;
      if (halved_) {
        push = summed_[i];
      } else if (!clocked_) {
        push = Sum<Pairs::kAll>(in, list.items, list.start[i], list.start[i + 1], xi, vi, ri);
      } else {
        if (evaluated_in_[i] != tick) {
          kept_[i] = split ? Sum<Pairs::kFar>(in, list.items, list.start[i], list.start[i + 1], xi, vi, ri)
                           : Sum<Pairs::kAll>(in, list.items, list.start[i], list.start[i + 1], xi, vi, ri);
          evaluated_in_[i] = tick;
        }
        push = kept_[i];
        if (split) push += Sum<Pairs::kNear>(in, list.near_items, list.near_start[i], list.near_start[i + 1], xi, vi, ri);
      }
      // The side preference: a share of the braking part turned into a step
      // to the right of e_i (nothing where e_i is zero or nothing brakes).
      if (side != 0.0) {
        const Vec2 e = b.direction[n];
        const double braking = -Dot(push, e);
        double share = side;
        if (gate_slowed && b.pace[n] > 0.0) share *= std::max(0.0, 1.0 - Dot(vi, e) / b.pace[n]);
        if (braking > 0.0) push += Vec2{e.y, -e.x} * (share * braking);
      }
      b.force[n] += push * in.bodies.mass_kg[i];
    }
  }

  std::uint32_t state_version() const override { return clocked_ ? 1 : 0; }
  void Start(const BodyState& bodies) override {
    kept_.assign(bodies.size(), Vec2{});
    evaluated_in_.assign(bodies.size(), kNever);
  }
  void Place(std::size_t slot, const BodyState&) override { Forget(slot); }
  void Stop(std::size_t person) override { Forget(person); }
  void Quench() override {
    std::fill(kept_.begin(), kept_.end(), Vec2{});
    std::fill(evaluated_in_.begin(), evaluated_in_.end(), kNever);
  }
  void Save(BinaryWriter& w) const override {
    w.PutVector(kept_);
    w.PutVector(evaluated_in_);
  }
  void Load(BinaryReader& r, std::size_t people) override {
    GetTermVector(r, kept_, people, "kept anticipation force");
    GetTermVector(r, evaluated_in_, people, "anticipation's interval");
  }

 private:
  static constexpr std::uint32_t kChunk = 128;
  static constexpr double kNever = -1.0;  // (no interval: times are >= 0)
  void Forget(std::size_t person) {
    kept_[person] = Vec2{};
    evaluated_in_[person] = kNever;
  }

  std::vector<double> bound_m_;  // per shape of the world
  bool clocked_;  // anticipation_interval_s > 0 when the run started (fixed for a run: it has state)
  double radius_m_ = 0.0, near_m_ = 0.0, switch_m_ = 0.0;  // (the current parameters': Retune)
  // Per person, when clocked: the force per unit mass of the last evaluation
  // (of the far pairs when split) and the interval it was evaluated in
  // (floor(t / h); kNever: none kept). Written by the block of the person's
  // (Force is const: the blocks share the term).
  mutable std::vector<Vec2> kept_;
  mutable std::vector<double> evaluated_in_;
  // The evaluation's copy of the people (Prepare), and whether the wide
  // filter is in use.
  mutable std::vector<Candidate> copy_;
  mutable bool wide_ = false;
  // Each pair once (SumEachPairOnce): in use for this evaluation; per person
  // whether the force acts on them (a walker who wants to walk; Prepare); per block
  // of kPairBlock people the colliding pairs (i, j > i) and the force of j
  // on i per unit mass; per person the sum.
  struct Pair {
    std::uint32_t i, j;
    Vec2 a;
  };
  static constexpr std::int64_t kPairBlock = 64;
  mutable bool halved_ = false;
  mutable std::vector<std::uint8_t> acts_;
  mutable std::vector<std::vector<Pair>> pairs_;
  mutable std::vector<std::vector<Pair>> crossing_;  // per block, its pairs whose j is in a later part
  mutable std::vector<Vec2> summed_;
};

}  // namespace

}  // namespace crowdrecon::engine::detail

namespace crowdrecon::engine {

void UseWideInstructions(bool use) { detail::wide_allowed = use; }
void UseHalfPairs(bool use) { detail::half_pairs_allowed = use; }
bool WideInstructions() {
#ifdef CROWDRECON_WIDE_FILTER
  static const bool has = __builtin_cpu_supports("avx2");
  return detail::wide_allowed && has;
#else
  return false;
#endif
}

}  // namespace crowdrecon::engine

namespace crowdrecon::engine::detail {

std::unique_ptr<BehaviourTerm> MakeAnticipation(const ModelParameters& p, const WorldDef& def) {
  if (p.anticipation != Anticipation::kTimeToCollision) return nullptr;
  return std::make_unique<AnticipationTerm>(p, def);
}

}  // namespace crowdrecon::engine::detail
