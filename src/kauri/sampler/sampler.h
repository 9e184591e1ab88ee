// Per-pixel sample streams. The Sampler is plain data; a path asks it for the
// next 1D or 2D value and the sampler tracks the dimension.
#pragma once

#include "kauri/sampler/rng.h"
#include "kauri/sampler/sobol.h"

namespace kauri {

enum class SamplerType : uint32_t { Independent = 0, Sobol = 1 };

/// Scramble seeds of the first dimension pairs depend on the pixel alone, not on the
/// sample index: a pixel's samples (the render loop draws them in a row) compute them
/// once. Three hashes of the ~80 operations of a pair; past the cache, computed per call.
inline constexpr uint32_t kCachedSobolPairs = 24;

struct Sampler {
  SamplerType type = SamplerType::Sobol;
  uint32_t pixel_seed = 0;
  uint32_t index = 0;
  uint32_t reversed_index = 0;  // R(index): shared by every Sobol' pair of the sample
  uint32_t dimension = 0;
  // Sobol': the pair computed for an even dimension by a 1D request; its y serves the
  // next 1D request if that is dimension pending_dim (never after a skip).
  Float pending_y = 0;
  uint32_t pending_dim = ~0u;
  PCG32 rng;
  uint32_t seeds_pixel = 0;    // pixel_seed the cached pair seeds belong to
  uint32_t seeded_pairs = 0;   // pairs [0, seeded_pairs) of seeds_pixel are cached
  SobolPairSeeds seeds[kCachedSobolPairs];

  /// Starts sample `index` of pixel (px, py). `seed` decorrelates whole renders.
  KAURI_HOST_DEVICE void start_pixel_sample(int px, int py, uint32_t sample_index, uint64_t seed) {
    uint64_t h = hash4(uint64_t(uint32_t(px)), uint64_t(uint32_t(py)), seed, 0x6b617572u);
    pixel_seed = uint32_t(h ^ (h >> 32));
    if (pixel_seed != seeds_pixel) {
      seeds_pixel = pixel_seed;
      seeded_pairs = 0;
    }
    index = sample_index;
    reversed_index = reverse_bits32(sample_index);
    dimension = 0;
    pending_dim = ~0u;
    if (type == SamplerType::Independent) rng.set_sequence(pixel_seed, mix_bits(sample_index + 1));
  }
  KAURI_HOST_DEVICE Float get_1d() {
    if (type == SamplerType::Independent) return rng.next_float();
    // Consecutive 1D requests take the two coordinates of one stratified pair: the
    // first computes the pair (sharing its index shuffle), the second takes the rest.
    Float v;
    if (dimension == pending_dim) {
      v = pending_y;
    } else {
      Vec2 p = pair(dimension >> 1);
      v = dimension & 1 ? p.y : p.x;
      pending_y = p.y;
      pending_dim = dimension | 1;
    }
    ++dimension;
    return v;
  }
  /// 2D values always start on an even dimension so the pair is a stratified 2D set.
  KAURI_HOST_DEVICE Vec2 get_2d() {
    if (type == SamplerType::Independent) {
      Float a = rng.next_float();
      return {a, rng.next_float()};
    }
    dimension += dimension & 1;
    Vec2 p = pair(dimension >> 1);
    dimension += 2;
    return p;
  }
  /// Point `k` of the current sample's padded sequence (owen_sobol_2d, bit for bit).
  KAURI_HOST_DEVICE Vec2 pair(uint32_t k) {
    if (k >= kCachedSobolPairs) return owen_sobol_2d_reversed(reversed_index, SobolPairSeeds(k, pixel_seed));
    while (seeded_pairs <= k) {
      seeds[seeded_pairs] = SobolPairSeeds(seeded_pairs, pixel_seed);
      ++seeded_pairs;
    }
    return owen_sobol_2d_reversed(reversed_index, seeds[k]);
  }
  /// Advance past a value the path does not need (a pinhole's lens sample, light
  /// sampling at a specular vertex) without computing it: the dimensions of everything
  /// after it stay where they would be.
  KAURI_HOST_DEVICE void skip_1d() {
    if (type == SamplerType::Independent) {
      rng.next_u32();
      return;
    }
    ++dimension;
  }
  KAURI_HOST_DEVICE void skip_2d() {
    if (type == SamplerType::Independent) {
      rng.next_u32();
      rng.next_u32();
      return;
    }
    dimension += (dimension & 1) + 2;
  }
};

}  // namespace kauri
