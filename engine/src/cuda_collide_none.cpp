// The CUDA force computation where the build has none (no CUDA compiler was
// found, or CROWDRECON_CUDA=OFF): asking for it is an input error that says so.
#include "cuda_collide.hpp"

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::engine::cuda {

namespace {
constexpr const char* kNoCuda =
    "this build of crowdrecon has no CUDA force computation (it was built without a CUDA compiler); "
    "use device \"cpu\", or rebuild with CUDA (see README.md, \"CUDA\")";
}

bool Available(std::string* why) {
  if (why) *why = kNoCuda;
  return false;
}

struct Collider::Impl {};

Collider::Collider(const std::vector<ShapeGeometry>&, const std::vector<std::uint32_t>&, const std::vector<double>&,
                   const PeriodicBox&) {
  throw InputError(std::string("device: \"cuda\": ") + kNoCuda);
}
Collider::~Collider() = default;

bool Collider::Collide(const CollideInput&, std::vector<Contact>&, std::vector<detail::BodySums>&) { return false; }

Collider::Timing Collider::last_timing() const { return {}; }

}  // namespace crowdrecon::engine::cuda
