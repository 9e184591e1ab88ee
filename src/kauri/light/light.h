// Lights as one plain struct with a type tag (device-portable dispatch).
//
// Conventions: `Le` spectra are radiance for area and environment lights,
// radiant intensity for point and spot lights, and irradiance at normal
// incidence for distant lights. Sampling densities are in solid angle as seen
// from the reference point; the light selection probability is applied by the
// caller.
#pragma once

#include "kauri/core/lanes.h"
#include "kauri/geometry/shapes.h"
#include "kauri/sampler/sampling.h"
#include "kauri/spectral/spectrum.h"

namespace kauri {

enum class LightType : uint8_t { Point, Spot, Distant, Triangle, Sphere, Disk, EnvConstant, EnvMap };

/// One environment texel's radiance as a sigmoid-polynomial illuminant (Jakob & Hanika 2019):
/// L(λ) = scale · s(c0 λ² + c1 λ + c2) · I(λ), I the working space's illuminant.
struct EnvTexel {
  Float scale, c0, c1, c2;
};

/// Which density NEE draws from an environment. `Complete` covers every direction with
/// radiance, as a light sampled on its own must. `Compensated` is for a path tracer that
/// combines NEE with BSDF sampling by MIS: BSDF sampling already covers the dim part of an
/// environment, so the light's density is max(0, L − L̄) (MIS compensation, Karlík et al.
/// 2019, sec. 4; pbrt-v4's allowIncompletePDF) and a constant environment has none at all.
enum class LightDensity : uint8_t { Complete, Compensated };
/// The density the path tracer's NEE uses; light selection (scene compile) agrees with it.
inline constexpr LightDensity kNextEventDensity = LightDensity::Compensated;

struct LightSample {
  SampledSpectrum L;   // incident radiance (or intensity/r², irradiance for delta lights)
  Vec3 wi;             // unit direction from the reference point to the light
  Point3 p_light;      // point on the light (for shadow rays); far away for infinite lights
  Normal3 n_light;     // its normal (area lights)
  Float pdf = 0;       // solid-angle density, or 1 for delta lights
  bool delta = false;
  bool infinite = false;
};

struct Light {
  LightType type = LightType::Point;
  bool two_sided = false;
  int material = -1;            // area lights of emissive materials: radiance comes from the material's EDFs
  Spectrum Le;                  // see the conventions above (for material lights: an estimate, for power)
  int emission_id = -1;         // lights with equal Le share an id (EmissionCache); -1: none
  // Le's colour in the output space, the expected value of the film's estimate over the
  // wavelengths (spectrum_to_xyz_expected): what a camera ray that meets the light adds,
  // with no colour noise (trace_path). Not for material lights and environment images.
  Vec3 Le_rgb;
  Point3 p0, p1, p2;            // triangle vertices; p0 = position/centre otherwise
  Normal3 n{0, 0, 1};           // triangle/disk normal, spot/distant direction (emission direction)
  Float radius = 0;             // sphere/disk radius
  Float bound_radius = 0;       // sphere/disk: a radius about p0 bounding the shape as placed (an
                                // instance's non-uniform scale; `radius` is then an average)
  Float area = 0;
  Float cos_inner = 1, cos_outer = 0;  // spot cone
  Float cos_max = 1;            // distant light angular radius (cos), 1 = delta
  Frame frame;                  // spot/distant/env orientation
  Point3 scene_center;
  Float scene_radius = 1;
  // Environment image (lat-long, row-major, width × height) and its sampling density.
  const EnvTexel* texels = nullptr;
  // The image's texels as output-space colours (the RGB each texel's spectrum is fitted to,
  // × intensity): what a camera ray that escapes adds, bilinear, without colour noise.
  const Vec3* texel_rgb = nullptr;
  DenselySampled illuminant{nullptr, 360, 1, 0};  // working-space white (Y = 1)
  int width = 0, height = 0;
  Distribution2D distribution;   // LightDensity::Complete
  Distribution2D compensated;    // LightDensity::Compensated (empty: NEE never samples this light)

  KAURI_HOST_DEVICE bool is_infinite() const {
    return type == LightType::Distant || type == LightType::EnvConstant || type == LightType::EnvMap;
  }
  KAURI_HOST_DEVICE bool is_delta() const {
    return type == LightType::Point || type == LightType::Spot || (type == LightType::Distant && cos_max >= 1);
  }
};

// ---- Environment mapping: lat-long with +Y up, u = atan2(x, −z)/2π, v = acos(y)/π
// (the convention Mitsuba 3 uses, so scenes translate one to one).
KAURI_HOST_DEVICE inline Vec2 direction_to_latlong(Vec3 d) {
  Float u = atan2_poly(d.x, -d.z) * kInv2Pi;
  if (u < 0) u += 1;
  return {u, acos_poly(d.y) * kInvPi};
}
/// `sin_theta`: where not null, receives sin θ (the lat-long area element's factor), which
/// the direction already needs.
KAURI_HOST_DEVICE inline Vec3 latlong_to_direction(Vec2 uv, Float* sin_theta = nullptr) {
  const Vec2 phi = cos_sin_turns(uv.x), theta = cos_sin_turns(Float(0.5) * uv.y);  // φ = 2π u, θ = π v
  if (sin_theta) *sin_theta = theta.y;
  return {theta.y * phi.y, theta.x, -theta.y * phi.x};
}

namespace light_detail {
/// Texel `index`'s (row-major) radiance at the path's wavelengths, given the illuminant there (`I`).
KAURI_HOST_DEVICE inline SampledSpectrum env_texel_spectrum(const Light& l, int index, const SampledWavelengths& lambda,
                                                            const SampledSpectrum& I) {
  const EnvTexel& t = l.texels[index];
  if (t.scale == 0) return SampledSpectrum(0);
  return sample_sigmoid(SigmoidPolynomial{t.c0, t.c1, t.c2}, lambda) * t.scale * I;
}

#if KAURI_LANES_AVX2 && !defined(__CUDA_ARCH__)
/// Σ_k w_k scale_k s_k(λ) of four texels at the path's 4 wavelengths, two texels per AVX2
/// register (lanes 0-3 the first texel's wavelengths, 4-7 the second's). The same sum as
/// env_texel_spectrum's loop without the illuminant (the caller multiplies by it once),
/// up to rounding; a zero weight or scale gives a zero term (the sigmoid is finite for
/// every argument), so there is no branch per texel. Scalar, this was 16 sigmoids, each
/// a square root and a division: the environment scene's lookups were 28% of its
/// instructions.
inline SampledSpectrum env_blend_lanes(const EnvTexel* const t[4], const Float w[4], const SampledWavelengths& lambda) {
  static_assert(sizeof(EnvTexel) == 16 && kSpectrumSamples == 4, "a texel is one 128-bit load; 4 wavelengths per half");
  const __m128 lam4 = _mm_loadu_ps(lambda.lambda);
  const __m256 lam = _mm256_set_m128(lam4, lam4);
  const __m256 bound = _mm256_set1_ps(0x1p60f), half = _mm256_set1_ps(0.5f), one = _mm256_set1_ps(1.0f);
  __m256 sum = _mm256_setzero_ps();
  for (int pair = 0; pair < 2; ++pair) {
    const EnvTexel* a = t[2 * pair];
    const EnvTexel* b = t[2 * pair + 1];
    // (scale, c0, c1, c2) of texel a in the low half, of b in the high half.
    const __m256 v = _mm256_set_m128(_mm_loadu_ps(&b->scale), _mm_loadu_ps(&a->scale));
    const __m256 c0 = _mm256_permute_ps(v, 0x55), c1 = _mm256_permute_ps(v, 0xAA), c2 = _mm256_permute_ps(v, 0xFF);
    const __m256 scale = _mm256_permute_ps(v, 0x00);
    const __m256 wk = _mm256_set_m128(_mm_set1_ps(w[2 * pair + 1]), _mm_set1_ps(w[2 * pair]));
    // SigmoidPolynomial::sigmoid of the quadratic, lane by lane (the same clamp).
    __m256 x = _mm256_fmadd_ps(_mm256_fmadd_ps(c0, lam, c1), lam, c2);
    x = _mm256_min_ps(_mm256_max_ps(x, _mm256_sub_ps(_mm256_setzero_ps(), bound)), bound);
    const __m256 root = _mm256_sqrt_ps(_mm256_fmadd_ps(x, x, one));
    const __m256 sig = _mm256_add_ps(half, _mm256_div_ps(x, _mm256_add_ps(root, root)));
    sum = _mm256_fmadd_ps(sig, _mm256_mul_ps(scale, wk), sum);
  }
  const __m128 s4 = _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1));
  SampledSpectrum s;
  _mm_storeu_ps(s.v, s4);
  return s;
}
#endif
}  // namespace light_detail

/// The four texels lat-long `uv` blends and their weights: bilinear between texel centres
/// (u wraps around, v clamps at the poles).
struct EnvBilinear {
  int index[4];  // row-major texel numbers
  Float w[4];
};
KAURI_HOST_DEVICE inline EnvBilinear env_bilinear(const Light& l, Vec2 uv) {
  Float fx = uv.x * Float(l.width) - Float(0.5), fy = uv.y * Float(l.height) - Float(0.5);
  Float x0f = std::floor(fx), y0f = std::floor(fy);
  Float dx = fx - x0f, dy = fy - y0f;
  int x0 = int(x0f), y0 = int(y0f);
  // uv.x ∈ [0, 1] puts x0 in [−1, width − 1]: repeat_index wraps it without a division.
  auto clamp_y = [&](int y) { return y < 0 ? 0 : (y >= l.height ? l.height - 1 : y); };
  int xa = repeat_index(x0, l.width), xb = repeat_index(x0 + 1, l.width), ya = clamp_y(y0), yb = clamp_y(y0 + 1);
  return {{ya * l.width + xa, ya * l.width + xb, yb * l.width + xa, yb * l.width + xb},
          {(1 - dx) * (1 - dy), dx * (1 - dy), (1 - dx) * dy, dx * dy}};
}

/// Environment radiance at lat-long `uv` (env_bilinear), interpolating the texels' spectra.
/// The sampling density is piecewise constant over texels of a dilated image
/// (scene_compile.cpp), so it is positive wherever this is.
KAURI_HOST_DEVICE inline SampledSpectrum env_texel_radiance(const Light& l, Vec2 uv, const SampledWavelengths& lambda) {
  const EnvBilinear b = env_bilinear(l, uv);
  const SampledSpectrum I = sample_dense(l.illuminant, lambda);  // once for the four texels
#if KAURI_LANES_AVX2 && !defined(__CUDA_ARCH__)
  const EnvTexel* t[4];
  for (int k = 0; k < 4; ++k) t[k] = &l.texels[b.index[k]];
  return light_detail::env_blend_lanes(t, b.w, lambda) * I;
#else
  SampledSpectrum s(0);
  for (int k = 0; k < 4; ++k)
    if (b.w[k] > 0) s += light_detail::env_texel_spectrum(l, b.index[k], lambda, I) * b.w[k];
  return s;
#endif
}

/// The output-space colour at lat-long `uv`: the texels' colours blended as
/// env_texel_radiance blends their spectra (the same texels and weights).
KAURI_HOST_DEVICE inline Vec3 env_texel_rgb(const Light& l, Vec2 uv) {
  const EnvBilinear b = env_bilinear(l, uv);
  Vec3 rgb{0, 0, 0};
  for (int k = 0; k < 4; ++k) rgb += l.texel_rgb[b.index[k]] * b.w[k];
  return rgb;
}

/// Whether unit direction `w` lies in a distant light's cone (cos_max < 1). For small
/// cones cosθ is within a few ulps of 1, so sin²θ = |w × n|² decides instead, and the
/// cone's solid angle 2π(1 − cosθ_max) is kept to float precision (a 0.1° sun would
/// otherwise come out 8% too bright along BSDF-sampled directions).
KAURI_HOST_DEVICE inline bool distant_cone_contains(const Light& l, Vec3 w) {
  if (!(l.cos_max < 1)) return false;
  Float c = -dot(w, l.n);
  if (l.cos_max < 0.9f) return c >= l.cos_max;
  return c > 0 && length_squared(cross(w, l.n)) <= (1 - l.cos_max) * (1 + l.cos_max);
}

/// The projected solid angle π sin²θ_max of a distant light's cone: its radiance inside the
/// cone is `Le` (irradiance at normal incidence) divided by this.
KAURI_HOST_DEVICE inline Float distant_cone_projected_solid_angle(const Light& l) {
  return kPi * (1 - l.cos_max) * (1 + l.cos_max);
}

/// Radiance arriving along direction `w` (world) from an infinite light; 0 for others.
KAURI_HOST_DEVICE inline SampledSpectrum infinite_light_Le(const Light& l, Vec3 w, const SampledWavelengths& lambda) {
  switch (l.type) {
    case LightType::EnvConstant: return l.Le.sample(lambda);
    case LightType::EnvMap: return env_texel_radiance(l, direction_to_latlong(l.frame.to_local(w)), lambda);
    case LightType::Distant:
      if (distant_cone_contains(l, w)) return l.Le.sample(lambda) / distant_cone_projected_solid_angle(l);
      return SampledSpectrum(0);
    default: return SampledSpectrum(0);
  }
}

/// A path's light spectrum at its wavelengths, the last one evaluated kept for the next
/// evaluation of the same spectrum: a path's wavelengths never change, and most scenes'
/// lights share a few emission colours (each evaluation of an RGB light is a sigmoid and an
/// illuminant lookup at 4 wavelengths). Cornell box: 2.5% fewer instructions per render;
/// hangar (three colours side by side, short paths) unchanged, and a 4-entry cache by
/// emission_id did not change that (0.1% more instructions on both).
struct EmissionCache {
  int id = -1;  // Light::emission_id of `Le`
  SampledSpectrum Le;

  /// l.Le at `lambda`, from the cache when the last light evaluated had the same Le.
  KAURI_HOST_DEVICE const SampledSpectrum& emission(const Light& l, const SampledWavelengths& lambda) {
    if (l.emission_id < 0 || l.emission_id != id) {
      Le = l.Le.sample(lambda);
      id = l.emission_id;
    }
    return Le;
  }
};

/// l.Le at `lambda`, through the path's cache when there is one.
KAURI_HOST_DEVICE inline SampledSpectrum light_emission(const Light& l, const SampledWavelengths& lambda,
                                                        EmissionCache* cache) {
  return cache ? cache->emission(l, lambda) : l.Le.sample(lambda);
}

/// Radiance leaving an area light at a point with normal `n` towards `w` (`cache`: the
/// path's EmissionCache, or null).
KAURI_HOST_DEVICE inline SampledSpectrum area_light_L(const Light& l, Normal3 n, Vec3 w, const SampledWavelengths& lambda,
                                                      EmissionCache* cache = nullptr) {
  if (!l.two_sided && dot(n, w) <= 0) return SampledSpectrum(0);
  return light_emission(l, lambda, cache);
}

/// Converts an area density at a light point to solid angle from `p`.
KAURI_HOST_DEVICE inline Float area_to_solid_angle(Float pdf_area, Point3 p, Point3 pl, Normal3 nl) {
  // pdf_A r² / cos θ_l with cos θ_l = |n_l · d| / r: as pdf_A (r² / |n_l · d|) r, the
  // division and the square root are independent (a square root then a division by its
  // result was a dependency chain on every next-event sample).
  Vec3 d = pl - p;
  Float d2 = length_squared(d);
  Float nd = absdot(nl, d);
  return nd > 0 ? pdf_area * (d2 / nd) * std::sqrt(d2) : 0;
}

/// `cache`: the path's EmissionCache (null: Le evaluated afresh). Triangle lights (every
/// mesh emitter) are sampled inline; the other kinds in sample_light_other.
KAURI_HOST_DEVICE KAURI_FORCE_INLINE LightSample sample_light(const Light& l, Point3 p, Vec2 u, const SampledWavelengths& lambda,
                                           LightDensity density = LightDensity::Complete,
                                           EmissionCache* cache = nullptr);
KAURI_HOST_DEVICE Float light_pdf(const Light& l, Point3 p, Vec3 wi, Point3 p_light, Normal3 n_light,
                                  LightDensity density = LightDensity::Complete);
/// Whether NEE with `density` can sample `l` at all (light selection gives it no share otherwise).
KAURI_HOST_DEVICE inline bool has_light_density(const Light& l, LightDensity density) {
  if (density == LightDensity::Complete) return true;
  if (l.type == LightType::EnvConstant) return false;
  if (l.type == LightType::EnvMap) return l.compensated.marginal.integral > 0;
  return true;
}
/// An environment map's sampling distribution for `density`.
KAURI_HOST_DEVICE inline const Distribution2D& env_distribution(const Light& l, LightDensity density) {
  return density == LightDensity::Compensated ? l.compensated : l.distribution;
}

/// Where a world direction meets an environment map: its lat-long coordinates and sin θ
/// (the lat-long area element's factor), found once for the radiance and the density there.
struct EnvDirection {
  Vec2 uv;
  Float sin_theta;
};
KAURI_HOST_DEVICE inline EnvDirection env_direction(const Light& l, Vec3 w) {
  const Vec3 d = l.frame.to_local(w);
  // sin θ = |(x, z)| of the unit direction (+Y up): a square root, where one of θ = π v
  // would first need v's arccosine undone.
  return {direction_to_latlong(d), std::sqrt(d.x * d.x + d.z * d.z)};
}
/// Solid-angle density with which sample_light() picks the direction `e` on environment map
/// `l`: the lat-long density over its Jacobian 2π² sin θ (0 at the poles).
KAURI_HOST_DEVICE inline Float env_pdf(const Light& l, const EnvDirection& e, LightDensity density) {
  if (e.sin_theta == 0) return 0;
  return env_distribution(l, density).pdf(e.uv) / (2 * kPi * kPi * e.sin_theta);
}

}  // namespace kauri

#include "kauri/light/light_sampling.inl"
