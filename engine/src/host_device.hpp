// CROWDRECON_HOST_DEVICE: marks the engine's functions that are compiled for
// both the processor and the CUDA device (the contact law, parts of the
// narrow phase), so that both run the same source. Empty outside nvcc.
#pragma once

#if defined(__CUDACC__)
#define CROWDRECON_HOST_DEVICE __host__ __device__
#else
#define CROWDRECON_HOST_DEVICE
#endif
