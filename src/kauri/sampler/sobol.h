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
/// m_i = 2 m_{i-1} xor m_{i-1}, v_i = m_i << (32 - i), folded into byte tables so
/// the generator-matrix product is 4 lookups instead of a 32-step loop.
struct Dim1Tables {
  uint32_t t[4][256];
  constexpr Dim1Tables() : t{} {
    uint32_t v[32] = {};
    uint32_t m = 1;
    for (int i = 1; i <= 32; ++i) {
      if (i > 1) m = (m << 1) ^ m;
      v[i - 1] = m << (32 - i);
    }
    for (int byte = 0; byte < 4; ++byte)
      for (int x = 0; x < 256; ++x) {
        uint32_t r = 0;
        for (int bit = 0; bit < 8; ++bit)
          if (x & (1 << bit)) r ^= v[8 * byte + bit];
        t[byte][x] = r;
      }
  }
};
inline constexpr Dim1Tables kDim1{};

constexpr uint32_t reverse_bits32_constexpr(uint32_t v) {
  uint32_t r = 0;
  for (int i = 0; i < 32; ++i) r |= ((v >> i) & 1u) << (31 - i);
  return r;
}

/// Byte tables of M = R ∘ S1 ∘ R (R: bit reversal, S1: the dimension-1 generator
/// matrix). M is linear over GF(2), so it maps the bit-reversed scrambled index straight
/// to the bit-reversed Sobol' value the Owen scramble works on, saving two reversals.
struct ReversedDim1Tables {
  uint32_t t[4][256];
  constexpr ReversedDim1Tables() : t{} {
    Dim1Tables d;
    for (int byte = 0; byte < 4; ++byte)
      for (int x = 0; x < 256; ++x) {
        // Bit b of the input (b = 8·byte + k) is bit 31 − b of the unreversed index.
        uint32_t r = 0;
        for (int k = 0; k < 8; ++k)
          if (x & (1 << k)) {
            uint32_t idx = 1u << (31 - (8 * byte + k));
            uint32_t s1 = d.t[0][idx & 0xff] ^ d.t[1][(idx >> 8) & 0xff] ^ d.t[2][(idx >> 16) & 0xff] ^
                          d.t[3][idx >> 24];
            r ^= reverse_bits32_constexpr(s1);
          }
        t[byte][x] = r;
      }
  }
};
inline constexpr ReversedDim1Tables kDim1Reversed{};
}  // namespace sobol_detail

KAURI_HOST_DEVICE inline uint32_t reverse_bits32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return __brev(v);
#elif defined(__GNUC__)
  // Byte swap in one instruction, then reverse the bits within each byte.
  v = __builtin_bswap32(v);
  v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  return ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
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
  const auto& t = sobol_detail::kDim1.t;
  return t[0][index & 0xff] ^ t[1][(index >> 8) & 0xff] ^ t[2][(index >> 16) & 0xff] ^ t[3][index >> 24];
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

/// 32-bit integer hash with low bias (C. Wellons' "lowbias32" constants).
KAURI_HOST_DEVICE inline uint32_t hash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

/// Scramble seeds of dimension pair `pair`: index shuffle, x and y Owen scrambles.
struct SobolPairSeeds {
  uint32_t shuffle, x, y;
  SobolPairSeeds() = default;
  KAURI_HOST_DEVICE SobolPairSeeds(uint32_t pair, uint32_t pixel_seed)
      : shuffle(hash_u32(pixel_seed ^ (pair * 0x9e3779b9u))),
        x(hash_u32(pixel_seed ^ (pair * 0x85ebca6bu + 1u))),
        y(hash_u32(pixel_seed ^ (pair * 0xc2b2ae35u + 2u))) {}
};

/// Bit reversal of two 32-bit words at once, in one 64-bit register: *x ← R(*x), *y ← R(*y)
/// for the cost of one reversal (the byte swap exchanges the words, which it undoes).
KAURI_HOST_DEVICE inline void reverse_bits32_pair(uint32_t* x, uint32_t* y) {
#if defined(__CUDA_ARCH__)
  *x = __brev(*x);
  *y = __brev(*y);
#elif defined(__GNUC__)
  uint64_t v = __builtin_bswap64((uint64_t(*y) << 32) | *x);  // low word: bswap(y), high: bswap(x)
  v = ((v >> 4) & 0x0F0F0F0F0F0F0F0FULL) | ((v & 0x0F0F0F0F0F0F0F0FULL) << 4);
  v = ((v >> 2) & 0x3333333333333333ULL) | ((v & 0x3333333333333333ULL) << 2);
  v = ((v >> 1) & 0x5555555555555555ULL) | ((v & 0x5555555555555555ULL) << 1);
  *x = uint32_t(v >> 32);
  *y = uint32_t(v);
#else
  *x = reverse_bits32(*x);
  *y = reverse_bits32(*y);
#endif
}

/// One 2D point of the padded Owen-scrambled Sobol' sequence: dimensions
/// (2·pair, 2·pair + 1) form a scrambled (0,2)-sequence in [0,1)². By definition
///   shuffled = N(index, s0), x = N(S0(shuffled), s1), y = N(S1(shuffled), s2)
/// with N(v, s) = R(LK(R(v), s)) and S0 = R. Writing a = R(shuffled) = LK(R(index), s0):
///   x = R(LK(R(a), s1)),  y = R(LK(M(a), s2)),  M = R ∘ S1 ∘ R (byte tables),
/// bit-identical to the definition. `reversed_index` = R(index), which every pair of a
/// sample shares (the Sampler reverses it once per sample); the last two reversals run
/// as one (reverse_bits32_pair).
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d_reversed(uint32_t reversed_index, const SobolPairSeeds& s) {
  uint32_t a = laine_karras_permutation(reversed_index, s.shuffle);
  const auto& m = sobol_detail::kDim1Reversed.t;
  uint32_t ma = m[0][a & 0xff] ^ m[1][(a >> 8) & 0xff] ^ m[2][(a >> 16) & 0xff] ^ m[3][a >> 24];
  uint32_t x = laine_karras_permutation(reverse_bits32(a), s.x);
  uint32_t y = laine_karras_permutation(ma, s.y);
  reverse_bits32_pair(&x, &y);
  return {u32_to_unit(x), u32_to_unit(y)};
}
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d(uint32_t index, const SobolPairSeeds& s) {
  return owen_sobol_2d_reversed(reverse_bits32(index), s);
}
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d(uint32_t index, uint32_t pair, uint32_t pixel_seed) {
  return owen_sobol_2d(index, SobolPairSeeds(pair, pixel_seed));
}

/// Only coordinate `which` (0: x, 1: y) of owen_sobol_2d: what a 1D request needs.
KAURI_HOST_DEVICE inline Float owen_sobol_1d(uint32_t index, uint32_t pair, uint32_t which, uint32_t pixel_seed) {
  SobolPairSeeds s(pair, pixel_seed);
  uint32_t a = laine_karras_permutation(reverse_bits32(index), s.shuffle);
  if (which == 0) return u32_to_unit(reverse_bits32(laine_karras_permutation(reverse_bits32(a), s.x)));
  const auto& m = sobol_detail::kDim1Reversed.t;
  uint32_t ma = m[0][a & 0xff] ^ m[1][(a >> 8) & 0xff] ^ m[2][(a >> 16) & 0xff] ^ m[3][a >> 24];
  return u32_to_unit(reverse_bits32(laine_karras_permutation(ma, s.y)));
}

/// One coordinate of the padded sequence; `dimension` counts 1D dimensions.
KAURI_HOST_DEVICE inline Float owen_sobol_sample(uint32_t index, uint32_t dimension, uint32_t pixel_seed) {
  return owen_sobol_1d(index, dimension >> 1, dimension & 1, pixel_seed);
}

}  // namespace kauri
