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

#include <type_traits>

#include "kauri/sampler/sampler.h"

namespace kauri {

/// Samples a group holds at most: one AVX2 vector of 32-bit lanes.
inline constexpr int kSampleLanes = 8;
/// Samples start_pixel_samples_wide starts at once: one vector of 32-bit lanes, 16 in the
/// x86-64-v4 core (AVX-512), where the path lanes trace 16 samples together.
inline constexpr int kStartLanes = KAURI_LANES_AVX512 ? 16 : 8;

namespace sampler_lanes_detail {
/// start_pixel_samples_lanes over L = 8 or 16 lanes (L = 16 only with AVX-512).
template <int L>
KAURI_HOST_DEVICE inline bool start_samples(Sampler* s, int n, int px, int py, uint32_t first, uint64_t seed) {
#if KAURI_SOBOL_VECTORS
  using namespace sobol_detail;
  using U = std::conditional_t<L == 16, lanes::U32x16, U32x8>;
  using I = std::conditional_t<L == 16, lanes::I32x16, I32x8>;
  using F = std::conditional_t<L == 16, lanes::F32x16, F32x8>;
  static_assert(kSobolBatch == 8, "the transpose below writes 8 pairs per sampler");
  if (n < 1 || n > L || s[0].type == SamplerType::Independent) return false;
  const uint32_t last = first + uint32_t(n - 1);
  if (s[0].type == SamplerType::ZSobol && zsobol_tile_bits(s[0].log2_spp) > 0 && (first >> s[0].log2_spp) == 0 &&
      (last >> s[0].log2_spp) != 0)
    return false;  // the block's last samples and the per-pixel fallback's first
  s[0].start_pixel_sample(px, py, first, seed);
  const uint32_t pixel_seed = s[0].pixel_seed;
  U lane;
  for (int k = 0; k < L; ++k) lane[k] = uint32_t(k);
  const U index = lane + s[0].index;
  const U reversed = reverse_words(index);
  F coord[2 * kSobolBatch];  // x of pairs 0 … 7, then their y
  // The 8 pairs' scramble seeds: three vector hashes for 24 scalar ones, or the pixel's
  // table's (Sampler::seeds).
  SobolSeedBatch own;
  if (!s[0].seeds) sobol_seed_batch(0, pixel_seed, &own);
  const SobolSeedBatch& seeds = s[0].seeds ? s[0].seeds->seeds(0, pixel_seed) : own;
  for (uint32_t p = 0; p < kSobolBatch; ++p) {
    const U c = reverse_words(laine_karras_words(reversed, U{} + seeds.shuffle[p]));
    const U x = reverse_words(laine_karras_words(c, U{} + seeds.x[p])) >> 8;
    const U y = reverse_words(laine_karras_words(superset_xor(c), U{} + seeds.y[p])) >> 8;
    // v >> 8 < 2^24: exact as a signed integer and as a float, as in u32_to_unit.
    coord[p] = __builtin_convertvector(reinterpret_cast<const I&>(x), F) * 0x1p-24f;
    coord[kSobolBatch + p] = __builtin_convertvector(reinterpret_cast<const I&>(y), F) * 0x1p-24f;
  }
  for (int k = 1; k < n; ++k) s[k] = s[0];
#if KAURI_LANES_AVX2
  // Pair-major to sample-major, 8 samples at a time: row k of each transposed block is
  // sample k's x (y) values. Transposed where they are (__m256 may alias the vectors): a
  // copy into an __m256 array first became a 512-byte `rep movsq`, 6% of this function's
  // time (perf, environment scene).
  auto store_rows = [&](__m256* x_rows, __m256* y_rows, int k0) {
    lanes::transpose8x8(x_rows);
    lanes::transpose8x8(y_rows);
    for (int k = k0; k < n && k < k0 + 8; ++k) {
      s[k].index = index[k];
      s[k].reversed_index = reversed[k];
      s[k].batch_first = 0;
      _mm256_storeu_ps(s[k].batch, x_rows[k - k0]);
      _mm256_storeu_ps(s[k].batch + kSobolBatch, y_rows[k - k0]);
    }
  };
  if constexpr (L == 8) {
    store_rows(reinterpret_cast<__m256*>(coord), reinterpret_cast<__m256*>(coord + kSobolBatch), 0);
  } else {
    for (int h = 0; h * 8 < n; ++h) {  // lanes 8h … 8h + 7 of each pair's vector
      __m256 rows[2][8];
      for (int p = 0; p < 8; ++p)
        for (int a = 0; a < 2; ++a) rows[a][p] = _mm256_loadu_ps(reinterpret_cast<const float*>(&coord[a * 8 + p]) + 8 * h);
      store_rows(rows[0], rows[1], 8 * h);
    }
  }
#else
  for (int k = 0; k < n; ++k) {
    s[k].index = index[k];
    s[k].reversed_index = reversed[k];
    s[k].batch_first = 0;
    for (uint32_t i = 0; i < 2 * kSobolBatch; ++i) s[k].batch[i] = coord[i][k];
  }
#endif
  return true;
#else
  (void)s, (void)n, (void)px, (void)py, (void)first, (void)seed;
  return false;
#endif
}
}  // namespace sampler_lanes_detail

/// Starts s[0 … n) on samples first … first + n − 1 of pixel (px, py) (render seed
/// `seed`), as n calls of Sampler::start_pixel_sample would, and fills each one's batch of
/// pairs 0 … 7. False, with s[1 …] untouched, where the group's samples do not share a
/// pixel seed and consecutive indices (the Independent sampler; a ZSobol group straddling
/// the end of its pixel's block) or without vector types: the caller starts them one by
/// one. s[0] must carry the render's sampler type and samples per pixel. n ≤ kSampleLanes.
KAURI_HOST_DEVICE inline bool start_pixel_samples_lanes(Sampler* s, int n, int px, int py, uint32_t first,
                                                        uint64_t seed) {
  return sampler_lanes_detail::start_samples<8>(s, n, px, py, first, seed);
}
/// start_pixel_samples_lanes for n ≤ kStartLanes samples: 16 in the v4 core, whose 16-lane
/// hashes cost what the 8-lane ones do (the render loop's camera stage for the path lanes'
/// 16 samples).
KAURI_HOST_DEVICE inline bool start_pixel_samples_wide(Sampler* s, int n, int px, int py, uint32_t first,
                                                       uint64_t seed) {
  return sampler_lanes_detail::start_samples<kStartLanes>(s, n, px, py, first, seed);
}

}  // namespace kauri
