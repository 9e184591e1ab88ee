// Pixel order of the ZSobol sampler (Ahmed & Wonka 2020, "Screen-space blue-noise
// diffusion of Monte Carlo sampling error via hierarchical ordering of pixels", SIGGRAPH
// Asia; pbrt-v4's ZSobolSampler). The pixels of a 2^b × 2^b super-tile take consecutive
// blocks of one Owen-scrambled Sobol' sequence in Morton order: pixel z gets the indices
// z·2^m … z·2^m + 2^m − 1 (2^m ≥ spp). Each block is a (0,m,2)-net, as a pixel's own
// sequence is; the 4 blocks of an aligned 2×2 quad together are a (0,m+2,2)-net, of a
// 4×4 block a (0,m+4,2)-net, and so on, so the errors of neighbouring pixels cancel
// instead of adding. The per-pair nested scramble of the index (sobol.h) permutes the
// blocks hierarchically, which keeps those nets.
//
// A binary nested scramble only flips bits, so of the 4! orders of a quad's blocks it
// reaches the 8 that keep the pairs {0,1}, {2,3} of Morton digits together: the pixel
// whose block completes a pixel's (0,m+1,2)-net would always be its horizontal
// neighbour. Ahmed & Wonka permute a node's 4 children at random; here each node of the
// quadtree draws which neighbour is its partner (horizontal, vertical or diagonal, 1/3
// each) from a hash of the node and the super-tile seed, and the scramble supplies the
// rest of the permutation.
#pragma once

#include "kauri/sampler/sobol.h"

namespace kauri {

/// ⌈log2 n⌉ (0 for n ≤ 1).
KAURI_HOST_DEVICE inline uint32_t ceil_log2(uint32_t n) {
  uint32_t m = 0;
  while (m < 32 && (uint64_t(1) << m) < n) ++m;
  return m;
}

/// Pixel bits per axis of a super-tile: 2b + m ≤ 32, as the Sobol' index is 32 bits
/// (b = 12 at 256 spp: 4096² pixels share a sequence). 0 when spp leaves no room.
KAURI_HOST_DEVICE inline uint32_t zsobol_tile_bits(uint32_t log2_spp) {
  const uint32_t b = log2_spp >= 32 ? 0 : (32 - log2_spp) / 2;
  return b < 16 ? b : 16;
}

/// Position in the super-tile's pixel order of pixel (x, y), both < 2^b: a Morton code
/// whose digit at each quadtree node pairs the children by the node's random choice.
KAURI_HOST_DEVICE inline uint32_t zsobol_pixel_index(uint32_t x, uint32_t y, uint32_t b, uint32_t seed) {
  // Levels above the pixel's highest bit hold digit 0 whatever the choice: skip them.
  uint32_t top = 0;
  while (top < b && ((x | y) >> top) != 0) ++top;
  uint32_t z = 0;
  for (uint32_t l = top; l-- > 0;) {
    // The node: its digits so far under a leading 1 that marks its depth.
    const uint32_t h = hash_u32((z | (1u << (2 * (b - 1 - l)))) ^ seed);
    const uint32_t partner = uint32_t((uint64_t(h) * 3) >> 32);  // 0 horizontal, 1 vertical, 2 diagonal
    const uint32_t xb = (x >> l) & 1, yb = (y >> l) & 1;
    const uint32_t pair = partner == 0 ? yb : partner == 1 ? xb : xb ^ yb;  // which pair of the node
    const uint32_t member = partner == 1 ? yb : xb;                       // which pixel of the pair
    z = (z << 2) | (pair << 1) | member;
  }
  return z;
}

}  // namespace kauri
