// Render session: tiled, progressive rendering over TBB with progress, time
// limit and statistics. Host code driving the device-portable path tracer.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kauri/film/film.h"
#include "kauri/integrator/path_state.h"
#include "kauri/render/light_aa.h"
#include "kauri/sampler/sampler.h"
#include "kauri/scene/scene.h"

namespace kauri {

struct RenderSettings {
  int width = 640, height = 480;
  int spp = 64;
  uint64_t seed = 0;
  int threads = 0;            // 0 = all cores
  double time_limit = 0;      // seconds; 0 = none (stops at a pass boundary)
  SamplerType sampler = SamplerType::ZSobol;
  IntegratorSettings integrator;
  PixelFilter filter;
  FilmReconstruction reconstruction = FilmReconstruction::Splat;
  int tile_size = 16;         // splatting may use smaller tiles on small images (see renderer.cpp)
  bool progress = true;       // progress bar with samples/s and ETA on stderr
  bool aovs = true;           // albedo, normal and depth; false: the beauty alone (faster)
  // Light antialiasing (render/light_aa.h): extra camera rays per sample, gathering only
  // the lights seen directly, in pixels where a probe finds their edges; 0: off.
  int light_aa = kLightAADefaultRays;
};

struct NaNReport {
  int x, y;
  uint32_t sample;
};

struct RenderStats {
  double seconds = 0;
  uint64_t samples = 0, rays = 0;
  int spp = 0;                // samples per pixel actually rendered
  uint64_t nan_samples = 0;   // non-finite samples caught (entered the film as black)
  std::vector<NaNReport> nan_pixels;  // the first few, for debugging
  size_t scene_bytes = 0;
  int materials = 0, layer_layouts = 0;  // distinct layer-program layouts (shared ones count once)
  size_t peak_rss_bytes = 0;
  double compile_seconds = 0;  // scene compile (BVH, lights) before the render; 0 when reused
  bool scene_reused = false;   // the compiled scene of an earlier render was reused (Scene::compiled)
  uint64_t light_aa_pixels = 0;  // pixels light antialiasing flagged (extra camera rays)
  bool path_lanes = false;       // the paths ran in vector lanes (integrator/path_lanes.h)
  double samples_per_second() const { return seconds > 0 ? double(samples) / seconds : 0; }
  double rays_per_second() const { return seconds > 0 ? double(rays) / seconds : 0; }
  std::string summary() const;
};

struct RenderResult {
  int width = 0, height = 0;
  std::vector<float> rgba;    // working space, premultiplied alpha, row-major top-down
  // AOVs: empty when RenderSettings::aovs is false.
  std::vector<float> albedo;  // 3 per pixel
  std::vector<float> normal;  // 3 per pixel, world-space shading normal
  std::vector<float> depth;   // camera-space depth (inf where nothing was hit)
  RenderStats stats;
};

/// Tiles of a render. A splat reaches filter.margin() pixels beyond its tile, so with
/// splatting the tiles are rendered in four phases by (tx mod 2, ty mod 2): tiles of one
/// phase are a whole tile apart and, with tiles ≥ 2 margins wide, their splats never
/// touch the same pixel. No locks, and each pixel receives its sums in the same order
/// whatever the thread count, so images stay bit-identical across thread counts.
struct TileGrid {
  int size = 16, nx = 1, ny = 1;
  std::vector<std::vector<int>> phases;  // tile indices (ty · nx + tx) per phase
};

TileGrid make_tile_grid(const RenderSettings& settings);

RenderResult render(const CompiledScene& scene, const RenderSettings& settings);

/// Peak resident memory of this process (bytes).
size_t peak_rss_bytes();

}  // namespace kauri
