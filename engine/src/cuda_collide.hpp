// The force computation of person pairs on a CUDA device (optional).
//
// Internal to the engine, and free of CUDA types: cuda_collide.cu implements
// it where the build has a CUDA compiler (CROWDRECON_CUDA), and
// cuda_collide_none.cpp elsewhere, where creating one reports that the build
// has no CUDA. A Simulation built with ComputeDevice::kCuda hands the narrow
// phase and the contact law of its person pairs, and the per-body sums of
// their forces, to it (walls stay on the processor) and keeps every other
// stage.
//
// Same results, bit for bit. The device code runs the processor's
// expressions in the same order (the contact law, the closest-point search,
// the box test and the per-body sums are shared as source: contact_law.hpp,
// narrow_phase_core.hpp, gather_core.hpp; the rest of the narrow phase
// repeats narrow_phase.cpp), is compiled without
// contraction of a*b+c (--fmad=false, as -ffp-contract=off on the processor),
// and IEEE double division and square root are correctly rounded on both. It
// measures every vertex of every pair of the list: the processor's memory of
// vertices and pairs still apart only skips work whose result is "no
// contact", so the contacts are the same. Each pair's contacts are written at
// the pair's place in the list (a count, a prefix sum, then the write), in the
// processor's order: pairs in list order, A's vertices then B's. Each body's
// contacts are then listed in that order (a stable sort by body) and summed
// on the device, so that only the sums and the contacts come back.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "contact_law.hpp"
#include "gather_core.hpp"
#include "crowdrecon/engine/contact.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "crowdrecon/engine/world.hpp"

namespace crowdrecon::engine::cuda {

// True when this build has the CUDA force computation and a device is
// present; otherwise false, with the reason in *why.
bool Available(std::string* why);

// One evaluation's input: the bodies (structure of arrays, n entries each),
// the person pairs of the neighbour list, the previous evaluation's contacts
// and the contact law.
struct CollideInput {
  std::size_t n = 0;
  const Vec2* position_m = nullptr;
  const double* cos_angle = nullptr;
  const double* sin_angle = nullptr;
  const Vec2* velocity_m_per_s = nullptr;
  const double* angular_velocity_rad_per_s = nullptr;
  const PersonState* state = nullptr;
  const double* mass_kg = nullptr;
  const std::uint32_t* shape = nullptr;

  const std::pair<std::uint32_t, std::uint32_t>* pairs = nullptr;
  std::size_t pair_count = 0;
  std::uint64_t pair_generation = 0;  // changes whenever the list does

  // Sorted by (pair key, feature). When `previous_is_last_output`, they are
  // this collider's last output followed by contacts it did not make (walls),
  // so the device keeps its own copy and this one is not sent.
  const std::vector<Contact>* previous = nullptr;
  bool previous_is_last_output = false;

  detail::ContactLaw law{};
};

class Collider {
 public:
  // The geometry of the shape families (narrow_phase.hpp), each body shape's
  // family and scale, and the periodic box. Throws InputError when no device
  // can be used (message says why).
  Collider(const std::vector<ShapeGeometry>& families, const std::vector<std::uint32_t>& shape_family,
           const std::vector<double>& shape_scale, const PeriodicBox& periodic);
  ~Collider();
  Collider(const Collider&) = delete;
  Collider& operator=(const Collider&) = delete;

  // Appends the person pairs' contacts to `out`, in list order, with their
  // forces, and sets body_sums[i] to the sums of the forces and torques of
  // body i's contacts among them, added in list order (gather_core.hpp), as
  // Simulation::Gather would. Returns true if a contact overlaps beyond the
  // sum of the sphero-radii (see Simulation::Check). Throws
  // std::runtime_error, with the CUDA runtime's message, if the device fails
  // (Simulation then goes on with the processor). For tests of that, the
  // environment variable CROWDRECON_CUDA_FAIL_AFTER=N makes every call after
  // the first N fail so.
  bool Collide(const CollideInput& input, std::vector<Contact>& out, std::vector<detail::BodySums>& body_sums);

  // Milliseconds of the last call spent in kernels, and copying to and from
  // the device (for the benchmarks).
  struct Timing {
    double upload_ms = 0.0, kernels_ms = 0.0, download_ms = 0.0;
  };
  Timing last_timing() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowdrecon::engine::cuda
