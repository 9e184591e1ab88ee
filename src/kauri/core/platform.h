// Portability layer shared by host and (later) CUDA device code.
//
// Every function that render-time code can reach is marked KAURI_HOST_DEVICE
// (pbrt-v4's PBRT_CPU_GPU, Cycles' ccl_device). Without nvcc it expands to
// nothing, so the CPU build sees plain inline functions.
#pragma once

#include <cstdint>

#if defined(__CUDACC__)
#define KAURI_HOST_DEVICE __host__ __device__
#define KAURI_DEVICE_CODE 1
#else
#define KAURI_HOST_DEVICE
#endif

#define KAURI_INLINE inline
/// Inlined whatever the compiler's size budget says: small fast paths in front of large
/// general functions (a lone Lambert lobe in BSDF::eval_pdf and sample, triangle lights
/// in sample_light, RGB reflectances in Spectrum::sample), which the budget would
/// otherwise leave out of line with the general code's prologue (docs/developing.md).
#if defined(__CUDACC__)
#define KAURI_FORCE_INLINE __forceinline__
#elif defined(__GNUC__)
#define KAURI_FORCE_INLINE inline __attribute__((always_inline))
#else
#define KAURI_FORCE_INLINE inline
#endif

namespace kauri {

/// Precision of render-time arithmetic. -Wdouble-promotion keeps it deliberate.
using Float = float;

inline constexpr Float kPi = 3.14159265358979323846f;
inline constexpr Float kInvPi = 0.31830988618379067154f;
inline constexpr Float kInv2Pi = 0.15915494309189533577f;
inline constexpr Float kInv4Pi = 0.07957747154594766788f;
inline constexpr Float kPiOver2 = 1.57079632679489661923f;
inline constexpr Float kPiOver4 = 0.78539816339744830961f;
inline constexpr Float kOneMinusEpsilon = 0x1.fffffep-1f;
inline constexpr Float kInfinity = __builtin_huge_valf();

}  // namespace kauri
