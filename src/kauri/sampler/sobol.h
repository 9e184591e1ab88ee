// Owen-scrambled Sobol' points with hash-based scrambling and padding
// (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//
// Each 2D dimension pair uses the first two Sobol' dimensions with its own
// shuffled index (a nested uniform scramble of the index) and per-dimension
// Owen scrambling, all seeded by a hash of (pixel, dimension, seed). The image
// therefore depends only on (pixel, sample index, dimension, seed): never on
// thread count or tile order.
#pragma once

#include "kauri/sampler/rng.h"

namespace kauri {

namespace sobol_detail {
/// Direction numbers of Sobol' dimension 1 (primitive polynomial x + 1, m_1 = 1):
/// m_i = 2 m_{i-1} xor m_{i-1}, v_i = m_i << (32 - i).
struct Dim1Directions {
  uint32_t v[32];
  constexpr Dim1Directions() : v{} {
    uint32_t m = 1;
    for (int i = 1; i <= 32; ++i) {
      if (i > 1) m = (m << 1) ^ m;
      v[i - 1] = m << (32 - i);
    }
  }
};
inline constexpr Dim1Directions kDim1{};
}  // namespace sobol_detail

KAURI_HOST_DEVICE inline uint32_t reverse_bits32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return __brev(v);
#else
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
  v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
  return (v >> 16) | (v << 16);
#endif
}

/// Sobol' dimension 0 (van der Corput) and 1 as 32-bit fixed point.
KAURI_HOST_DEVICE inline uint32_t sobol_u32(uint32_t index, int dim) {
  if (dim == 0) return reverse_bits32(index);
  uint32_t x = 0;
  for (int bit = 0; index; index >>= 1, ++bit)
    if (index & 1) x ^= sobol_detail::kDim1.v[bit];
  return x;
}

/// Laine–Karras style hash that acts as an Owen scramble on reversed bits
/// (Burley 2020, listing 4 design; constants from Vegdahl's improved variant).
KAURI_HOST_DEVICE inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}
KAURI_HOST_DEVICE inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits32(laine_karras_permutation(reverse_bits32(x), seed));
}

/// One coordinate of the padded Owen-scrambled Sobol' sequence.
/// `dimension` counts 1D dimensions; pairs (2k, 2k+1) form a 2D stratified set.
KAURI_HOST_DEVICE inline Float owen_sobol_sample(uint32_t index, uint32_t dimension, uint64_t pixel_seed) {
  uint32_t pair = dimension >> 1;
  uint32_t pair_seed = uint32_t(hash_combine(pixel_seed, pair));
  uint32_t shuffled = nested_uniform_scramble(index, pair_seed);
  uint32_t x = sobol_u32(shuffled, int(dimension & 1));
  uint32_t dim_seed = uint32_t(hash_combine(pixel_seed, 0x10000u + dimension));
  return u32_to_unit(nested_uniform_scramble(x, dim_seed));
}

}  // namespace kauri
