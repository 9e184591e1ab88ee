// Owen-scrambled Sobol' points with hash-based scrambling and padding
// (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//
// Each 2D dimension pair uses the first two Sobol' dimensions with its own
// shuffled index (a nested uniform scramble of the index) and per-dimension
// Owen scrambling, all seeded by a hash of (pixel, dimension, seed). The image
// therefore depends only on (pixel, sample index, dimension, seed): never on
// thread count or tile order.
#pragma once

#include "kauri/core/lanes.h"
#include "kauri/sampler/rng.h"

namespace kauri {

namespace sobol_detail {
/// Direction numbers of Sobol' dimension 1 (primitive polynomial x + 1, m_1 = 1):
/// m_i = 2 m_{i-1} xor m_{i-1}, v_i = m_i << (32 - i), folded into byte tables so
/// the generator-matrix product is 4 lookups instead of a 32-step loop. Only the
/// definition (sobol_u32) uses them, which the tests hold the fast paths to; render time
/// uses the table-free superset_xor below.
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

// The word operations below are templates over W = uint32_t or a GCC/Clang vector of
// uint32_t (every operator is lane-wise), so the scalar path and the batched one
// (owen_sobol_batch) share one definition.
#define KAURI_SOBOL_VECTORS KAURI_LANE_VECTORS
#if KAURI_SOBOL_VECTORS
using lanes::F32x8;
using lanes::I32x8;
using lanes::U32x4;
using lanes::U32x8;
#endif

/// Laine–Karras style hash that acts as an Owen scramble on reversed bits
/// (Burley 2020, listing 4 design; constants from Vegdahl's improved variant).
template <class W>
KAURI_HOST_DEVICE inline W laine_karras_words(W x, W seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}
/// 32-bit integer hash with low bias (C. Wellons' "lowbias32" constants).
template <class W>
KAURI_HOST_DEVICE inline W hash_words(W x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
/// Bit reversal by shifts and masks (vector lanes have no byte swap to start from).
template <class W>
KAURI_HOST_DEVICE inline W reverse_words(W v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
  v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
  return (v >> 16) | (v << 16);
}

#if KAURI_SOBOL_VECTORS && defined(__AVX2__)
/// Bit reversal of every 32-bit lane by byte shuffles (AVX2 vpshufb), the overloads the
/// batch below picks: the word's bytes in reverse order, then each byte's bits from two
/// 16-entry tables indexed by its nibbles (the reversed low nibble becomes the high one).
/// Seven operations per register against reverse_words' twenty; the same words (tests).
inline __m256i reverse_lane_bits(__m256i v) {
  const __m256i byte_order = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12,  //
                                              3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
  // rev4(n) and rev4(n) << 4 for n = 0 … 15 (rev4: the 4-bit reversal).
  const __m256i rev_lo = _mm256_setr_epi8(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15,  //
                                          0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15);
  const __m256i rev_hi = _mm256_slli_epi16(rev_lo, 4);  // no byte exceeds 0x0F: no carry between bytes
  const __m256i nibble = _mm256_set1_epi8(0x0F);
  const __m256i b = _mm256_shuffle_epi8(v, byte_order);
  const __m256i lo = _mm256_and_si256(b, nibble), hi = _mm256_and_si256(_mm256_srli_epi16(b, 4), nibble);
  return _mm256_or_si256(_mm256_shuffle_epi8(rev_hi, lo), _mm256_shuffle_epi8(rev_lo, hi));
}
inline U32x8 reverse_words(U32x8 v) {
  __m256i x;
  __builtin_memcpy(&x, &v, sizeof x);
  x = reverse_lane_bits(x);
  __builtin_memcpy(&v, &x, sizeof v);
  return v;
}
#if defined(__AVX512BW__)
/// reverse_lane_bits over 16 lanes (AVX-512BW vpshufb on 64 bytes).
inline lanes::U32x16 reverse_words(lanes::U32x16 v) {
  const __m512i byte_order = _mm512_broadcast_i32x4(_mm_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12));
  const __m512i rev_lo = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15));
  const __m512i rev_hi = _mm512_slli_epi16(rev_lo, 4);
  const __m512i nibble = _mm512_set1_epi8(0x0F);
  __m512i x;
  __builtin_memcpy(&x, &v, sizeof x);
  const __m512i b = _mm512_shuffle_epi8(x, byte_order);
  const __m512i lo = _mm512_and_si512(b, nibble), hi = _mm512_and_si512(_mm512_srli_epi16(b, 4), nibble);
  x = _mm512_or_si512(_mm512_shuffle_epi8(rev_hi, lo), _mm512_shuffle_epi8(rev_lo, hi));
  __builtin_memcpy(&v, &x, sizeof v);
  return v;
}
#endif
inline U32x4 reverse_words(U32x4 v) {
  __m128i x;
  __builtin_memcpy(&x, &v, sizeof x);
  x = _mm256_castsi256_si128(reverse_lane_bits(_mm256_castsi128_si256(x)));
  __builtin_memcpy(&v, &x, sizeof v);
  return v;
}
#endif
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
  return sobol_detail::reverse_words(v);
#endif
}

/// Sobol' dimension 0 (van der Corput) and 1 as 32-bit fixed point.
KAURI_HOST_DEVICE inline uint32_t sobol_u32(uint32_t index, int dim) {
  if (dim == 0) return reverse_bits32(index);
  const auto& t = sobol_detail::kDim1.t;
  return t[0][index & 0xff] ^ t[1][(index >> 8) & 0xff] ^ t[2][(index >> 16) & 0xff] ^ t[3][index >> 24];
}

KAURI_HOST_DEVICE inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  return sobol_detail::laine_karras_words(x, seed);
}
KAURI_HOST_DEVICE inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits32(laine_karras_permutation(reverse_bits32(x), seed));
}
KAURI_HOST_DEVICE inline uint32_t hash_u32(uint32_t x) { return sobol_detail::hash_words(x); }

/// Scramble seeds of dimension pair `pair`: index shuffle, x and y Owen scrambles. `W`: a
/// 32-bit word, or a vector of them (the sampler's group start: 8 pairs at once).
template <class W>
struct BasicSobolPairSeeds {
  W shuffle, x, y;
  BasicSobolPairSeeds() = default;
  KAURI_HOST_DEVICE BasicSobolPairSeeds(W pair, W pixel_seed)
      : shuffle(sobol_detail::hash_words(pixel_seed ^ (pair * 0x9e3779b9u))),
        x(sobol_detail::hash_words(pixel_seed ^ (pair * 0x85ebca6bu + 1u))),
        y(sobol_detail::hash_words(pixel_seed ^ (pair * 0xc2b2ae35u + 2u))) {}
};
using SobolPairSeeds = BasicSobolPairSeeds<uint32_t>;

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

namespace sobol_detail {
/// M = R ∘ S1 ∘ R, the dimension-1 generator matrix on bit-reversed words, as word
/// operations: M(a) = Z(R(a)). S1 is the Pascal matrix mod 2 (m_i = (x + 1)^(i−1)), and by
/// Lucas' theorem C(b, t) is odd iff t ⊆ b (as bit sets), so bit t of Z(c) is the XOR of the
/// bits c_b over every position b ⊇ t: the superset XOR transform over the 5 bits of a
/// position, one shift-and-XOR per position bit. Fifteen lane-wise operations, no tables
/// (a GPU need not keep 4 KB of them in constant memory, and the batch below vectorises).
template <class W>
KAURI_HOST_DEVICE inline W superset_xor(W v) {
  v ^= (v >> 1) & 0x55555555u;
  v ^= (v >> 2) & 0x33333333u;
  v ^= (v >> 4) & 0x0F0F0F0Fu;
  v ^= (v >> 8) & 0x00FF00FFu;
  v ^= v >> 16;
  return v;
}
}  // namespace sobol_detail

/// One 2D point of the padded Owen-scrambled Sobol' sequence: dimensions
/// (2·pair, 2·pair + 1) form a scrambled (0,2)-sequence in [0,1)². By definition
///   shuffled = N(index, s0), x = N(S0(shuffled), s1), y = N(S1(shuffled), s2)
/// with N(v, s) = R(LK(R(v), s)) and S0 = R. Writing a = R(shuffled) = LK(R(index), s0)
/// and c = R(a):
///   x = R(LK(c, s1)),  y = R(LK(Z(c), s2))   (Z: sobol_detail::superset_xor),
/// bit-identical to the definition. `reversed_index` = R(index), which every pair of a
/// sample shares (the Sampler reverses it once per sample); the last two reversals run
/// as one (reverse_bits32_pair).
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d_reversed(uint32_t reversed_index, const SobolPairSeeds& s) {
  const uint32_t c = reverse_bits32(laine_karras_permutation(reversed_index, s.shuffle));
  uint32_t x = laine_karras_permutation(c, s.x);
  uint32_t y = laine_karras_permutation(sobol_detail::superset_xor(c), s.y);
  reverse_bits32_pair(&x, &y);
  return {u32_to_unit(x), u32_to_unit(y)};
}
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d(uint32_t index, const SobolPairSeeds& s) {
  return owen_sobol_2d_reversed(reverse_bits32(index), s);
}
KAURI_HOST_DEVICE inline Vec2 owen_sobol_2d(uint32_t index, uint32_t pair, uint32_t pixel_seed) {
  return owen_sobol_2d(index, SobolPairSeeds(pair, pixel_seed));
}

/// One coordinate of the padded sequence; `dimension` counts 1D dimensions.
KAURI_HOST_DEVICE inline Float owen_sobol_sample(uint32_t index, uint32_t dimension, uint32_t pixel_seed) {
  Vec2 p = owen_sobol_2d(index, dimension >> 1, pixel_seed);
  return dimension & 1 ? p.y : p.x;
}

/// Dimension pairs the Sampler computes at once (a bounce reads three: light, lobe choice
/// and roulette, BSDF direction; the camera three). Eight, one AVX2 register of 32-bit
/// lanes: the camera stage computes pairs 0-7 of a pixel's samples together
/// (sampler_lanes.h), which covers the camera and the first bounce, and a longer path
/// computes one batch every 2⅔ bounces instead of every 1⅓. Against batches of 4: Cornell
/// box 7% less time (one-thread A/B, 140-144 -> 130-133 ms), 2% fewer instructions; the
/// batch boundary's branch was one of the path loop's most mispredicted.
inline constexpr uint32_t kSobolBatch = 8;

/// The scramble seeds (BasicSobolPairSeeds) of dimension pairs first … first + 7.
struct SobolSeedBatch {
  uint32_t shuffle[kSobolBatch], x[kSobolBatch], y[kSobolBatch];
};

/// Seeds of pairs first … first + 7 (first a multiple of kSobolBatch) of `pixel_seed`.
KAURI_HOST_DEVICE inline void sobol_seed_batch(uint32_t first, uint32_t pixel_seed, SobolSeedBatch* b) {
#if KAURI_SOBOL_VECTORS
  using namespace sobol_detail;
  static_assert(kSobolBatch == 8, "one U32x8 of pairs");
  const BasicSobolPairSeeds<U32x8> s(U32x8{0, 1, 2, 3, 4, 5, 6, 7} + first, U32x8{} + pixel_seed);
  __builtin_memcpy(b->shuffle, &s.shuffle, sizeof s.shuffle);
  __builtin_memcpy(b->x, &s.x, sizeof s.x);
  __builtin_memcpy(b->y, &s.y, sizeof s.y);
#else
  for (uint32_t i = 0; i < kSobolBatch; ++i) {
    const SobolPairSeeds s(first + i, pixel_seed);
    b->shuffle[i] = s.shuffle, b->x[i] = s.x, b->y[i] = s.y;
  }
#endif
}

/// The seeds of one pixel seed's first kBatches batches, hashed once for all the samples
/// that share the seed (a pixel's samples; with ZSobol a whole super-tile's) instead of
/// once per sample and batch: the three seed hashes are ~40% of a batch's word operations
/// (owen_sobol_batch), and a path's later bounces compute a batch per sample. Filled
/// lazily, batch by batch; a new pixel seed empties it. Plain data on the stack of
/// render_pixel_samples, whose samplers point to it (Sampler::seeds).
struct SobolSeedCache {
  static constexpr uint32_t kBatches = 8;  // pairs 0 … 63: the camera's and 20 bounces'
  uint32_t pixel_seed = 0;
  uint32_t filled = 0;  // bit b: batch b holds pixel_seed's seeds
  SobolSeedBatch batch[kBatches];

  /// Whether pairs first … first + 7 are in the table's range.
  KAURI_HOST_DEVICE static bool covers(uint32_t first) { return first < kBatches * kSobolBatch; }
  /// The seeds of pairs first … first + 7 of `seed` (covers(first), first a multiple of
  /// kSobolBatch).
  KAURI_HOST_DEVICE const SobolSeedBatch& seeds(uint32_t first, uint32_t seed) {
    if (seed != pixel_seed) {
      pixel_seed = seed;
      filled = 0;
    }
    const uint32_t b = first / kSobolBatch;
    if (!(filled >> b & 1u)) {
      sobol_seed_batch(first, seed, &batch[b]);
      filled |= 1u << b;
    }
    return batch[b];
  }
};

/// Pairs first … first + 7 of one sample from their seeds: out[i] = x and out[8 + i] = y
/// of pair first + i, bit for bit owen_sobol_2d. On the CPU the eight pairs run in the
/// lanes of GCC/Clang vector types (AVX2 with x86-64-v3): the same word operations as the
/// scalar path (laine_karras_permutation, superset_xor, reverse_bits32).
KAURI_HOST_DEVICE inline void owen_sobol_batch(uint32_t reversed_index, const SobolSeedBatch& seeds,
                                               Float out[2 * kSobolBatch]) {
#if KAURI_SOBOL_VECTORS
  using namespace sobol_detail;
  U32x8 shuffle, sx, sy;
  __builtin_memcpy(&shuffle, seeds.shuffle, sizeof shuffle);
  __builtin_memcpy(&sx, seeds.x, sizeof sx);
  __builtin_memcpy(&sy, seeds.y, sizeof sy);
  const U32x8 c = reverse_words(laine_karras_words(U32x8{} + reversed_index, shuffle));
  // v >> 8 < 2^24: exact as a signed integer and as a float, as in u32_to_unit.
  const U32x8 x = reverse_words(laine_karras_words(c, sx)) >> 8;
  const U32x8 y = reverse_words(laine_karras_words(superset_xor(c), sy)) >> 8;
  const F32x8 fx = __builtin_convertvector(reinterpret_cast<const I32x8&>(x), F32x8) * 0x1p-24f;
  const F32x8 fy = __builtin_convertvector(reinterpret_cast<const I32x8&>(y), F32x8) * 0x1p-24f;
  __builtin_memcpy(out, &fx, sizeof fx);
  __builtin_memcpy(out + kSobolBatch, &fy, sizeof fy);
#else
  for (uint32_t i = 0; i < kSobolBatch; ++i) {
    SobolPairSeeds s;
    s.shuffle = seeds.shuffle[i], s.x = seeds.x[i], s.y = seeds.y[i];
    const Vec2 p = owen_sobol_2d_reversed(reversed_index, s);
    out[i] = p.x;
    out[kSobolBatch + i] = p.y;
  }
#endif
}

/// Pairs first … first + 7 of one sample, their seeds hashed here.
KAURI_HOST_DEVICE inline void owen_sobol_batch(uint32_t reversed_index, uint32_t first, uint32_t pixel_seed,
                                               Float out[2 * kSobolBatch]) {
  SobolSeedBatch seeds;
  sobol_seed_batch(first, pixel_seed, &seeds);
  owen_sobol_batch(reversed_index, seeds, out);
}

}  // namespace kauri
