// Light antialiasing: more camera rays where lights seen directly have edges.
//
// A small bright lamp seen by the camera covers part of a few pixels; whether a camera
// sample lands on it is a coin toss worth the lamp's whole radiance, and that coverage
// noise can dominate an image's error (the benchmark hangar: 92% of its error over 4×4
// blocks comes from its 144 lamps seen directly, bench/suite.py). A path costs ~5× a
// camera ray there, so the render loop splits the camera sample's estimate in two:
//     L(u) = Le_rgb(u) + S(u),
// Le_rgb the colour of the lights the camera ray meets (PathOutput::rgb_exact, the
// light's exact output-space colour) and S everything the path gathers after it. In a
// pixel flagged for light antialiasing, each of its camera samples keeps S(u) and replaces
// Le_rgb(u) by the mean of Le_rgb over E extra camera rays v_1 … v_E of the same pixel,
//     L̂ = S(u) + (1/E) Σ_j Le_rgb(v_j),
// with E[L̂] = E[L(u)] since each v_j is distributed as u is (uniform in the pixel, or by
// the filter); the extra rays' points come from a sequence of their own (N·E
// Owen-scrambled Sobol' points per pixel: the coverage is stratified over all of them).
// Each extra ray is splatted at its own film position into the pixels' sums, but not into
// their filter weights Σ w: the weights stay those of the N camera samples whose estimate
// the extra rays complete. With filter importance sampling (weights 1) a pixel's estimate
// is thus unbiased as before. Splatting is the ratio Σ w L / Σ w, consistent but biased by
// O(1/N) through the covariance of Σ w and the sums; the lamps' part of the sums no longer
// shares the camera samples' positions, so that O(1/N) term changes (it vanishes for the
// lamps' part), and the image converges to the same limit. Alpha and the data AOVs stay
// the camera samples' own. A pixel whose spp · E reaches 2^31 (the sampler's indices)
// renders without it.
//
// Which pixels: a probe of kLightAAProbeRays camera rays per pixel, on a sequence
// independent of the render's, before the pixel's first samples; a pixel is flagged where
// the colours of the lamps (area and distant lights) its rays meet differ by at least
// half the brightest lamp's in view (an edge). The flag is a function of the probe alone,
// independent of the samples it acts on, so whatever the probe misses changes no
// expected value (a missed sliver of lamp keeps the one-ray estimate).
//
// The split is not always a gain: it drops the negative covariance of Le_rgb(u) and S(u)
// (where the ray meets the light, the path gathers nothing beyond it, and the other way
// round), Var[Le + S] = Var[Le] + Var[S] + 2 Cov[Le, S]. Beside a lamp, S is small
// against Le and the covariance with it; at a constant sky's silhouettes the objects are
// lit by that sky and about as bright as it, and there the split was worse than none
// (a test scene with a sky of 20: +6% variance). So a constant environment never flags a
// pixel: its colour only rides along in a pixel flagged for a lamp. Pixels wholly on or
// off a lamp, and scenes without lamps seen in Le_rgb (material emitters, environment
// images), render as without it. Host render-loop code (renderer.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "kauri/sampler/rng.h"
#include "kauri/scene/scene_view.h"

namespace kauri {

/// Camera rays of a pixel's probe: one packet, on 8 stratified points.
inline constexpr int kLightAAProbeRays = 8;

/// Default and largest extra camera rays per camera sample in a flagged pixel
/// (RenderSettings::light_aa).
inline constexpr int kLightAADefaultRays = 4;
inline constexpr int kLightAAMaxRays = 64;

/// Seeds of the probe's and the extra rays' sequences, derived from the render's seed so
/// that both stay independent of the render's own points and of each other.
inline uint64_t light_aa_probe_seed(uint64_t seed) { return mix_bits(seed ^ 0x6c69676874707262ull); }
inline uint64_t light_aa_extra_seed(uint64_t seed) { return mix_bits(seed ^ 0x6c69676874657874ull); }

/// The colour a camera ray meeting light `l` sees as Le_rgb if it is a lamp that flags
/// pixels: an area light without an emissive material (path_detail::
/// add_area_seen_directly) or a distant light with a cone (add_seen_directly); black
/// for the others (constant environments: see the header; the rest are estimated
/// spectrally or never met).
inline Vec3 lamp_colour(const Light& l) {
  switch (l.type) {
    case LightType::Triangle:
    case LightType::Sphere:
    case LightType::Disk: return l.material < 0 ? l.Le_rgb : Vec3{0, 0, 0};
    case LightType::Distant:  // a cone's radiance; a delta direction is never met
      return l.cos_max < 1 ? l.Le_rgb / distant_cone_projected_solid_angle(l) : Vec3{0, 0, 0};
    default: return Vec3{0, 0, 0};
  }
}

/// Spread of the probe's colours below which a pixel is not flagged, as a share of the
/// brightest lamp's channel among those the camera can see (light_aa_candidates). The
/// extra rays pay where a lamp's edge is bright against what the path gathers beside it
/// (the covariance above); the probe sees only the lamps, so the brightest one in view
/// stands for that scale, and dim panels beside it keep the one-ray estimate.
inline constexpr Float kLightAASpreadShare = 0.5f;

/// Whether the probe's colours seen directly differ by at least `min_spread` in some
/// channel (a pixel wholly inside one light or off every light never does).
inline bool light_colours_differ(const Vec3* rgb, int n, Float min_spread) {
  Vec3 lo = rgb[0], hi = rgb[0];
  for (int k = 1; k < n; ++k) lo = vmin(lo, rgb[k]), hi = vmax(hi, rgb[k]);
  const Float spread = max_component(hi - lo);
  return spread > 0 && spread >= min_spread;
}

/// Light antialiasing's screen mask: which pixels a probe could flag, and the probe's
/// threshold.
struct LightAAMask {
  std::vector<uint8_t> pixels;  // 1: probe; 0: no lamp can reach; empty: no lamp in view
  Float min_spread = 0;         // spread_share × the brightest lamp in view
};

/// The mask from the screen-space bounds of the lamps (lamp_colour) the camera can see,
/// those bright enough to reach the threshold (any other lamps' colours, 0 included,
/// differ by less): a pixel's probe rays see only lamps whose projection covers it. A
/// pinhole or orthographic camera projects each such lamp's bounding box (its 8 corners)
/// and marks the pixels within `margin` of it (1 with splatting: rounding; 1 + the
/// filter's radius with filter importance sampling, whose camera samples land around the
/// pixel). A distant light's cone in view, a thin lens (defocus), a box across the
/// camera's plane, or boxes adding up to more than 4 images' area mark every pixel;
/// lamps off screen or wholly behind the camera are left out, of the threshold too.
/// Only marked pixels pay for a probe. Host code.
LightAAMask light_aa_candidates(const SceneView& s, int width, int height, Float spread_share, int margin);

}  // namespace kauri
