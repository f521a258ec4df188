#pragma once
/// \file
/// Host/device annotation for kernel bodies: one body serves the seq, omp and cuda policies.

#if defined(__CUDACC__)
/// Marks a function or functor call operator callable from host and device code.
#define SIMSR_HOST_DEVICE __host__ __device__
#else
#define SIMSR_HOST_DEVICE
#endif
