// A pixel's group of up to 8 consecutive samples started together: the samplers' state as
// n calls of Sampler::start_pixel_sample leave it, with each one's first batch of
// dimension pairs (0 … kSobolBatch − 1: the camera's three pairs, the first bounce's three
// and the second bounce's light pair) computed in the lanes of one vector pass instead of
// one sample at a time.
//
// Why: a pixel's samples share the Sobol' scramble seeds (one pixel seed) and have
// consecutive indices, so the per-pair seeds are hashed once for the group and the index
// scrambles of owen_sobol_2d_reversed run across the 8 samples. Host CPU code (the render
// loop's camera stage); the values are owen_sobol_2d's bit for bit, which
// tests/cpp/test_sample_lanes.cpp checks against the scalar sampler.
#pragma once

#include "kauri/sampler/sampler.h"

namespace kauri {

/// Samples a group holds at most: one AVX2 vector of 32-bit lanes.
inline constexpr int kSampleLanes = 8;

/// Starts s[0 … n) on samples first … first + n − 1 of pixel (px, py) (render seed
/// `seed`), as n calls of start_pixel_sample would, and fills each one's batch of pairs
/// 0 … 7. False, with s[1 …] untouched, where the group's samples do not share a pixel
/// seed and consecutive indices (the Independent sampler; a ZSobol group straddling the
/// end of its pixel's block) or without vector types: the caller starts them one by one.
/// s[0] must carry the render's sampler type and samples per pixel.
KAURI_HOST_DEVICE inline bool start_pixel_samples_lanes(Sampler* s, int n, int px, int py, uint32_t first,
                                                        uint64_t seed) {
#if KAURI_SOBOL_VECTORS
  using namespace sobol_detail;
  static_assert(kSobolBatch == 8, "the transpose below writes 8 pairs per sampler");
  if (n < 1 || n > kSampleLanes || s[0].type == SamplerType::Independent) return false;
  const uint32_t last = first + uint32_t(n - 1);
  if (s[0].type == SamplerType::ZSobol && zsobol_tile_bits(s[0].log2_spp) > 0 && (first >> s[0].log2_spp) == 0 &&
      (last >> s[0].log2_spp) != 0)
    return false;  // the block's last samples and the per-pixel fallback's first
  s[0].start_pixel_sample(px, py, first, seed);
  const uint32_t pixel_seed = s[0].pixel_seed;
  const U32x8 index = U32x8{0, 1, 2, 3, 4, 5, 6, 7} + s[0].index;
  const U32x8 reversed = reverse_words(index);
  F32x8 coord[2 * kSobolBatch];  // x of pairs 0 … 7, then their y
  // The 8 pairs' scramble seeds: three vector hashes for 24 scalar ones, or the pixel's
  // table's (Sampler::seeds).
  SobolSeedBatch own;
  if (!s[0].seeds) sobol_seed_batch(0, pixel_seed, &own);
  const SobolSeedBatch& seeds = s[0].seeds ? s[0].seeds->seeds(0, pixel_seed) : own;
  for (uint32_t p = 0; p < kSobolBatch; ++p) {
    const U32x8 c = reverse_words(laine_karras_words(reversed, U32x8{} + seeds.shuffle[p]));
    const U32x8 x = reverse_words(laine_karras_words(c, U32x8{} + seeds.x[p])) >> 8;
    const U32x8 y = reverse_words(laine_karras_words(superset_xor(c), U32x8{} + seeds.y[p])) >> 8;
    // v >> 8 < 2^24: exact as a signed integer and as a float, as in u32_to_unit.
    coord[p] = __builtin_convertvector(reinterpret_cast<const I32x8&>(x), F32x8) * 0x1p-24f;
    coord[kSobolBatch + p] = __builtin_convertvector(reinterpret_cast<const I32x8&>(y), F32x8) * 0x1p-24f;
  }
#if KAURI_LANES_AVX2
  // Pair-major to sample-major: row k of each transposed block is sample k's x (y) values.
  // Transposed where they are (__m256 may alias the vectors): a copy into an __m256 array
  // first became a 512-byte `rep movsq`, 6% of this function's time (perf, environment scene).
  __m256* rows[2] = {reinterpret_cast<__m256*>(coord), reinterpret_cast<__m256*>(coord + kSobolBatch)};
  lanes::transpose8x8(rows[0]);
  lanes::transpose8x8(rows[1]);
#endif
  for (int k = 0; k < n; ++k) {
    if (k > 0) s[k] = s[0];
    s[k].index = index[k];
    s[k].reversed_index = reversed[k];
    s[k].batch_first = 0;
#if KAURI_LANES_AVX2
    _mm256_storeu_ps(s[k].batch, rows[0][k]);
    _mm256_storeu_ps(s[k].batch + kSobolBatch, rows[1][k]);
#else
    for (uint32_t i = 0; i < 2 * kSobolBatch; ++i) s[k].batch[i] = coord[i][k];
#endif
  }
  return true;
#else
  (void)s, (void)n, (void)px, (void)py, (void)first, (void)seed;
  return false;
#endif
}

}  // namespace kauri
