// Stage gather: contact forces and torques onto bodies, in a fixed order (eq. 2, eq. 18).
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::Gather() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kGather)]);
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
        detail::AddContact(sums, c, false, xa - detail::Separation(def_.periodic, xa, bodies_.position_m[c.b]));
    }
    bodies_.contact_force_n[i] = sums.force;
    bodies_.contact_torque_n_m[i] = sums.torque;
    in.trailing_force[i] = sums.trailing_force;
    in.trailing_torque[i] = sums.trailing_torque;
    in.leading_force[i] = sums.leading_force;
    in.leading_torque[i] = sums.leading_torque;
  }
}

}  // namespace crowdrecon::engine
