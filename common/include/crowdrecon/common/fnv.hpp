// FNV-1a, 64 bits: a checksum of bytes (checkpoints and world files, the
// geometry hash of run files, the benchmarks' "same work" check). Enough to
// catch a damaged or cut file or a different result; not cryptographic.
#pragma once

#include <cstddef>
#include <cstdint>

namespace crowdrecon {

inline std::uint64_t Fnv1a(const void* data, std::size_t size, std::uint64_t h = 1469598103934665603ull) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

}  // namespace crowdrecon
