// Vector lanes on the CPU, declared once: GCC/Clang vector types (every operator works lane
// by lane, so word and float code can be written once for a scalar and for 8 lanes) and the
// AVX2 steps across lanes that the compiler does not find by itself. Users: the Sobol'
// sampler's batches, the ray origins' offset (x, y, z in one vector), the light tree's
// 8-wide nodes, the render loop's sample groups and their splat. Host CPU code only; a
// CUDA build runs one lane per thread without these.
#pragma once

#include <cstddef>
#include <cstdint>

#if !defined(__CUDACC__) && (defined(__GNUC__) || defined(__clang__))
#define KAURI_LANE_VECTORS 1
namespace kauri::lanes {
typedef uint32_t U32x4 __attribute__((vector_size(16)));
typedef int32_t I32x4 __attribute__((vector_size(16)));
typedef float F32x4 __attribute__((vector_size(16)));
typedef uint32_t U32x8 __attribute__((vector_size(32)));
typedef int32_t I32x8 __attribute__((vector_size(32)));
typedef float F32x8 __attribute__((vector_size(32)));
typedef uint32_t U32x16 __attribute__((vector_size(64)));
typedef int32_t I32x16 __attribute__((vector_size(64)));
typedef float F32x16 __attribute__((vector_size(64)));
}  // namespace kauri::lanes
#else
#define KAURI_LANE_VECTORS 0
#endif

#if KAURI_LANE_VECTORS && defined(__AVX2__)
#define KAURI_LANES_AVX2 1
#include <immintrin.h>
namespace kauri::lanes {
/// Σ of the 8 lanes, in every lane (GCC 12 leaves such reductions scalar).
inline __m256 lane_sum(__m256 v) {
  v = _mm256_add_ps(v, _mm256_permute2f128_ps(v, v, 1));
  v = _mm256_add_ps(v, _mm256_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
  return _mm256_add_ps(v, _mm256_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
}

/// In-place transpose of an 8 × 8 matrix of floats held as 8 rows (r[i] lane j = a_ij):
/// unpack pairs, then quadruples, then swap 128-bit halves (24 shuffles).
inline void transpose8x8(__m256 r[8]) {
  __m256 t[8], q[8];
  for (int i = 0; i < 8; i += 2) {
    t[i] = _mm256_unpacklo_ps(r[i], r[i + 1]);
    t[i + 1] = _mm256_unpackhi_ps(r[i], r[i + 1]);
  }
  for (int i = 0; i < 8; i += 4) {
    q[i] = _mm256_shuffle_ps(t[i], t[i + 2], _MM_SHUFFLE(1, 0, 1, 0));
    q[i + 1] = _mm256_shuffle_ps(t[i], t[i + 2], _MM_SHUFFLE(3, 2, 3, 2));
    q[i + 2] = _mm256_shuffle_ps(t[i + 1], t[i + 3], _MM_SHUFFLE(1, 0, 1, 0));
    q[i + 3] = _mm256_shuffle_ps(t[i + 1], t[i + 3], _MM_SHUFFLE(3, 2, 3, 2));
  }
  for (int i = 0; i < 4; ++i) {
    r[i] = _mm256_permute2f128_ps(q[i], q[i + 4], 0x20);
    r[i + 4] = _mm256_permute2f128_ps(q[i], q[i + 4], 0x31);
  }
}

/// Columns 8c … 8c + 7 of the 8 rows index[0 … 7] of a table of 32-byte aligned rows of
/// `stride` floats (a multiple of 8): column[j] lane k = table[index[k] · stride + 8c + j].
/// What 8 gathers would give, as 8 row loads and a transpose: AVX2 gathers are
/// microcoded, ~2.5x slower than this on a Zen 4 (eight columns of 8 lanes: 38 ns against
/// 15 ns). Words move as their bits, so integer columns come out as floats to bit-cast.
inline void load_columns8(const float* table, int stride, I32x8 index, int c, __m256 column[8]) {
  alignas(32) int32_t row[8];
  __builtin_memcpy(row, &index, sizeof row);
  for (int k = 0; k < 8; ++k) column[k] = _mm256_load_ps(table + size_t(row[k]) * size_t(stride) + 8 * c);
  transpose8x8(column);
}
/// The 4 floats of the 8 rows index[0 … 7] of a table of 16-byte rows (unaligned) as 4
/// columns: column[j] lane k = table[4 · index[k] + j]. 8 loads and an 8 × 4 transpose in
/// place of 4 gathers.
inline void load_rows4(const float* table, I32x8 index, __m256 column[4]) {
  alignas(32) int32_t row[8];
  __builtin_memcpy(row, &index, sizeof row);
  auto rows = [&](int a) {  // rows a and a + 4 in the two 128-bit halves
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(table + 4 * size_t(row[a]))),
                                _mm_loadu_ps(table + 4 * size_t(row[a + 4])), 1);
  };
  const __m256 t0 = rows(0), t1 = rows(1), t2 = rows(2), t3 = rows(3);
  const __m256 u0 = _mm256_unpacklo_ps(t0, t1), u1 = _mm256_unpackhi_ps(t0, t1);
  const __m256 u2 = _mm256_unpacklo_ps(t2, t3), u3 = _mm256_unpackhi_ps(t2, t3);
  column[0] = _mm256_shuffle_ps(u0, u2, 0x44), column[1] = _mm256_shuffle_ps(u0, u2, 0xEE);
  column[2] = _mm256_shuffle_ps(u1, u3, 0x44), column[3] = _mm256_shuffle_ps(u1, u3, 0xEE);
}

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#define KAURI_LANES_AVX512 1
/// Lanes 0–7 and 8–15 of a 16-lane vector, and the two halves joined.
inline I32x8 low_half(I32x16 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3, 4, 5, 6, 7); }
inline I32x8 high_half(I32x16 v) { return __builtin_shufflevector(v, v, 8, 9, 10, 11, 12, 13, 14, 15); }
inline F32x16 join(F32x8 lo, F32x8 hi) {
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
}
/// load_columns8 for 16 rows: each half's 8 × 8 transpose, joined (AVX-512 has no cheaper
/// 16 × 8 transpose of 32-byte rows).
inline void load_columns16(const float* table, int stride, I32x16 index, int c, F32x16 column[8]) {
  __m256 lo[8], hi[8];
  load_columns8(table, stride, low_half(index), c, lo);
  load_columns8(table, stride, high_half(index), c, hi);
  for (int j = 0; j < 8; ++j) column[j] = join(F32x8(lo[j]), F32x8(hi[j]));
}
/// load_rows4 for 16 rows.
inline void load_rows4(const float* table, I32x16 index, F32x16 column[4]) {
  __m256 lo[4], hi[4];
  load_rows4(table, low_half(index), lo);
  load_rows4(table, high_half(index), hi);
  for (int j = 0; j < 4; ++j) column[j] = join(F32x8(lo[j]), F32x8(hi[j]));
}
#else
#define KAURI_LANES_AVX512 0
#endif
}  // namespace kauri::lanes
#else
#define KAURI_LANES_AVX2 0
#define KAURI_LANES_AVX512 0
#endif
