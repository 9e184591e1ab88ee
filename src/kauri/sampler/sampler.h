// Per-pixel sample streams. The Sampler is plain data; a path asks it for the
// next 1D or 2D value and the sampler tracks the dimension.
#pragma once

#include "kauri/sampler/rng.h"
#include "kauri/sampler/sobol.h"

namespace kauri {

enum class SamplerType : uint32_t { Independent = 0, Sobol = 1 };

struct Sampler {
  SamplerType type = SamplerType::Sobol;
  uint32_t pixel_seed = 0;
  uint32_t index = 0;
  uint32_t dimension = 0;
  Float pending_y = 0;  // Sobol': second coordinate of the pair a 1D request opened
  PCG32 rng;

  /// Starts sample `index` of pixel (px, py). `seed` decorrelates whole renders.
  KAURI_HOST_DEVICE void start_pixel_sample(int px, int py, uint32_t sample_index, uint64_t seed) {
    uint64_t h = hash4(uint64_t(uint32_t(px)), uint64_t(uint32_t(py)), seed, 0x6b617572u);
    pixel_seed = uint32_t(h ^ (h >> 32));
    index = sample_index;
    dimension = 0;
    if (type == SamplerType::Independent) rng.set_sequence(pixel_seed, mix_bits(sample_index + 1));
  }
  KAURI_HOST_DEVICE Float get_1d() {
    if (type == SamplerType::Independent) return rng.next_float();
    // Consecutive 1D requests take the two coordinates of one stratified pair: the
    // first computes the pair (sharing its index shuffle), the second takes the rest.
    Float v;
    if (dimension & 1) {
      v = pending_y;
    } else {
      Vec2 p = owen_sobol_2d(index, dimension >> 1, pixel_seed);
      v = p.x;
      pending_y = p.y;
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
    Vec2 p = owen_sobol_2d(index, dimension >> 1, pixel_seed);
    dimension += 2;
    return p;
  }
};

}  // namespace kauri
