// Per-pixel sample streams. The Sampler is plain data; a path asks it for the
// next 1D or 2D value and the sampler tracks the dimension.
#pragma once

#include "kauri/sampler/rng.h"
#include "kauri/sampler/sobol.h"
#include "kauri/sampler/zsobol.h"

namespace kauri {

/// Sobol: every pixel scrambles its own sequence. ZSobol: the pixels of a 2^b × 2^b
/// super-tile share one sequence, each pixel a block of it (zsobol.h), so neighbouring
/// pixels' errors cancel (blue noise); every pixel's own points are as Sobol'.
enum class SamplerType : uint32_t { Independent = 0, Sobol = 1, ZSobol = 2 };

struct Sampler {
  SamplerType type = SamplerType::Sobol;
  uint32_t pixel_seed = 0;
  uint32_t index = 0;
  uint32_t reversed_index = 0;  // R(index): shared by every Sobol' pair of the sample
  uint32_t dimension = 0;
  uint32_t log2_spp = 0;        // ZSobol: a pixel's block holds 2^log2_spp sample indices
  // ZSobol: the last pixel's first index and super-tile seed (px = -1: none yet).
  int zsobol_px = -1, zsobol_py = -1;
  uint64_t zsobol_render_seed = 0;
  uint32_t zsobol_block = 0, zsobol_seed = 0;
  // Sobol': pairs [batch_first, batch_first + kSobolBatch) of the current sample, x then
  // y (owen_sobol_batch); batch_first = ~0u when none is computed.
  uint32_t batch_first = ~0u;
  Float batch[2 * kSobolBatch];
  /// Optional: the pair seeds of this sampler's pixel seed, shared by the samplers of a
  /// pixel's group (SobolSeedCache); null: each batch hashes its own.
  SobolSeedCache* seeds = nullptr;
  PCG32 rng;

  /// Samples per pixel the render takes (ZSobol sizes each pixel's block by it).
  KAURI_HOST_DEVICE void set_samples_per_pixel(uint32_t spp) {
    log2_spp = ceil_log2(spp);
    zsobol_px = -1;
  }

  /// Starts sample `index` of pixel (px, py). `seed` decorrelates whole renders.
  /// ZSobol: a sample index beyond the pixel's block (more samples than
  /// set_samples_per_pixel announced) falls back to the pixel's own Sobol' sequence, so
  /// no two pixels ever share a point.
  KAURI_HOST_DEVICE void start_pixel_sample(int px, int py, uint32_t sample_index, uint64_t seed) {
    uint32_t i = sample_index;
    const uint32_t b = zsobol_tile_bits(log2_spp);
    if (type == SamplerType::ZSobol && b > 0 && (sample_index >> log2_spp) == 0) {
      // A pixel's samples follow each other: its block and seed are kept, not recomputed.
      if (px != zsobol_px || py != zsobol_py || seed != zsobol_render_seed) {
        const uint32_t mask = (1u << b) - 1;
        const uint64_t tile = hash4(uint64_t(uint32_t(px) >> b), uint64_t(uint32_t(py) >> b), seed, 0x7a736f62u);
        zsobol_seed = uint32_t(tile >> 32);  // shared by the super-tile
        zsobol_block = zsobol_pixel_index(uint32_t(px) & mask, uint32_t(py) & mask, b, uint32_t(tile)) << log2_spp;
        zsobol_px = px;
        zsobol_py = py;
        zsobol_render_seed = seed;
      }
      pixel_seed = zsobol_seed;
      i |= zsobol_block;
    } else {
      uint64_t h = hash4(uint64_t(uint32_t(px)), uint64_t(uint32_t(py)), seed, 0x6b617572u);
      pixel_seed = uint32_t(h ^ (h >> 32));
    }
    index = i;
    reversed_index = reverse_bits32(i);
    dimension = 0;
    batch_first = ~0u;
    if (type == SamplerType::Independent) rng.set_sequence(pixel_seed, mix_bits(sample_index + 1));
  }
  KAURI_HOST_DEVICE Float get_1d() {
    if (type == SamplerType::Independent) return rng.next_float();
    // Consecutive 1D requests take the two coordinates of one stratified pair.
    Vec2 p = pair(dimension >> 1);
    return dimension++ & 1 ? p.y : p.x;
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
  /// The next n 2D values, as n calls of get_2d give them. The path lanes take a bounce's
  /// pairs at once: one test that they lie in the computed batch instead of a test and
  /// the dimension's bookkeeping per pair (~20 instructions each).
  KAURI_HOST_DEVICE void get_2d_n(Vec2* u, int n) {
    if (type == SamplerType::Independent) {
      for (int i = 0; i < n; ++i) u[i] = get_2d();
      return;
    }
    dimension += dimension & 1;
    const uint32_t k = dimension >> 1;
    dimension += 2 * uint32_t(n);
    if (batch_first == ~0u || k < batch_first || k + uint32_t(n) > batch_first + kSobolBatch) {
      for (int i = 0; i < n; ++i) u[i] = pair(k + uint32_t(i));  // crosses into the next batch
      return;
    }
    const Float* x = batch + (k - batch_first);
    for (int i = 0; i < n; ++i) u[i] = {x[i], x[kSobolBatch + i]};
  }
  /// Point `k` of the current sample's padded sequence (owen_sobol_2d, bit for bit),
  /// from the batch of kSobolBatch pairs holding it.
  KAURI_HOST_DEVICE Vec2 pair(uint32_t k) {
    const uint32_t first = k & ~(kSobolBatch - 1);
    if (first != batch_first) {
      if (seeds && SobolSeedCache::covers(first))
        owen_sobol_batch(reversed_index, seeds->seeds(first, pixel_seed), batch);
      else
        owen_sobol_batch(reversed_index, first, pixel_seed, batch);
      batch_first = first;
    }
    return {batch[k - first], batch[kSobolBatch + k - first]};
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
