// CROWDRECON_HOST_DEVICE: marks the engine's functions that are compiled for
// both the processor and the CUDA device (the contact law, parts of the
// narrow phase), so that both run the same source. Empty outside nvcc.
#pragma once

#if defined(__CUDACC__)
#define CROWDRECON_HOST_DEVICE __host__ __device__
#else
#define CROWDRECON_HOST_DEVICE
#endif

// For the small shared functions of the hot loops (the closest-point search,
// the box test): inlined where they are called, as the static functions they
// replaced were (a call costs about 5 % of the narrow phase's instructions).
#if defined(__CUDACC__)
#define CROWDRECON_INLINE __forceinline__
#else
#define CROWDRECON_INLINE [[gnu::always_inline]] inline
#endif
