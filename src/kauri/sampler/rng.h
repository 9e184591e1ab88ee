// Hashing and a small PCG32 generator for device code.
#pragma once

#include "kauri/core/math.h"

namespace kauri {

/// 64-bit finaliser (MurmurHash3 fmix64); mixes pixel, index and seed into streams.
KAURI_HOST_DEVICE inline uint64_t mix_bits(uint64_t v) {
  v ^= v >> 33;
  v *= 0xff51afd7ed558ccdULL;
  v ^= v >> 33;
  v *= 0xc4ceb9fe1a85ec53ULL;
  v ^= v >> 33;
  return v;
}
KAURI_HOST_DEVICE inline uint64_t hash_combine(uint64_t a, uint64_t b) {
  return mix_bits(a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2)));
}
KAURI_HOST_DEVICE inline uint64_t hash4(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  return hash_combine(hash_combine(hash_combine(mix_bits(a), b), c), d);
}

/// uint32 → [0,1) with 24 significant bits, never reaching 1.
KAURI_HOST_DEVICE inline Float u32_to_unit(uint32_t v) {
  return fmin_(Float(v >> 8) * 0x1p-24f, kOneMinusEpsilon);
}

/// PCG32 (O'Neill 2014): 64-bit LCG state, xorshift + random rotation output.
struct PCG32 {
  uint64_t state = 0x853c49e6748fea9bULL;
  uint64_t inc = 0xda3e39cb94b95bdbULL;

  KAURI_HOST_DEVICE PCG32() = default;
  KAURI_HOST_DEVICE PCG32(uint64_t seq, uint64_t seed) { set_sequence(seq, seed); }
  KAURI_HOST_DEVICE void set_sequence(uint64_t seq, uint64_t seed) {
    state = 0;
    inc = (seq << 1) | 1;
    next_u32();
    state += seed;
    next_u32();
  }
  KAURI_HOST_DEVICE uint32_t next_u32() {
    uint64_t old = state;
    state = old * 0x5851f42d4c957f2dULL + inc;
    uint32_t xorshifted = uint32_t(((old >> 18) ^ old) >> 27);
    uint32_t rot = uint32_t(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1) & 31));
  }
  KAURI_HOST_DEVICE Float next_float() { return u32_to_unit(next_u32()); }
};

}  // namespace kauri
