// Film: per-pixel accumulation of beauty and data AOVs, and the pixel filter.
//
// Two reconstructions (FilmReconstruction):
// - Splat (default): a sample is placed uniformly in its pixel and added, weighted by
//   the filter, to every pixel whose centre lies within the filter radius; a pixel is
//   Σ w_i L_i / Σ w_i (the weighted estimator of Arnold, RenderMan and Mitsuba). Each
//   sample informs ~π(2σ)² pixels, so per-pixel noise is ~3× lower than with one pixel
//   per sample, at the price of noise correlated between neighbours.
// - FilterImportance (Ernst et al. 2006): the film position is drawn ∝ the filter around
//   the pixel centre and the sample counts for that pixel alone with weight 1; noise is
//   uncorrelated between pixels (what some denoisers and variance estimators want).
// Data AOVs (albedo, normal, depth) are always averaged over a pixel's own samples:
// a Gaussian-blurred depth or normal would mix surfaces.
#pragma once

#include <algorithm>
#include <cstddef>

#include "kauri/sampler/sampling.h"

namespace kauri {

enum class FilterType : uint8_t { Gaussian, Box };
enum class FilmReconstruction : uint8_t { Splat, FilterImportance };

/// Largest filter radius (pixels) a render accepts: bounds a splat's footprint.
inline constexpr Float kMaxFilterRadius = 8;

struct PixelFilter {
  FilterType type = FilterType::Gaussian;
  Float sigma = 0.5f;   // Gaussian standard deviation (pixels)
  Float radius = 2.0f;  // support half-width (pixels): 4σ, as Mitsuba 3's default

  /// Offset from the pixel centre, distributed ∝ the filter (filter importance sampling).
  KAURI_HOST_DEVICE Vec2 sample(Vec2 u) const {
    if (type == FilterType::Box) return {(2 * u.x - 1) * radius, (2 * u.y - 1) * radius};
    return {sample_truncated_gaussian(u.x, sigma, radius), sample_truncated_gaussian(u.y, sigma, radius)};
  }
  KAURI_HOST_DEVICE Float pdf(Vec2 p) const {
    if (type == FilterType::Box)
      return (std::fabs(p.x) <= radius && std::fabs(p.y) <= radius) ? 1 / sqr(2 * radius) : 0;
    return truncated_gaussian_pdf(p.x, sigma, radius) * truncated_gaussian_pdf(p.y, sigma, radius);
  }
  /// Unnormalised 1D weight at offset d from a pixel centre (splatting); the support is
  /// the half-open [−r, r) so a box of radius ½ gives each position exactly one pixel.
  KAURI_HOST_DEVICE Float weight_1d(Float d) const {
    if (!(d >= -radius && d < radius)) return 0;
    return type == FilterType::Box ? Float(1) : std::exp(-d * d / (2 * sigma * sigma));
  }
  /// Pixels a splat can reach beyond the one holding the sample: centres at x + ½
  /// within [p − r, p + r) for p ∈ [x, x + 1).
  KAURI_HOST_DEVICE int margin() const { return int(std::ceil(radius - 0.5f)); }
};

/// Film position of a sample of pixel (x, y) from its film pair `u`: uniform in the pixel
/// when splatting (the filter weights the splat), else ∝ the filter around the pixel
/// centre (filter importance sampling: weight 1 for this pixel).
KAURI_HOST_DEVICE inline Vec2 sample_film_position(bool splat, const PixelFilter& f, int x, int y, Vec2 u) {
  return splat ? Vec2{Float(x) + u.x, Float(y) + u.y} : Vec2{Float(x) + 0.5f, Float(y) + 0.5f} + f.sample(u);
}

/// Running beauty sums for one pixel (double sums keep long renders exact enough): the
/// 40 bytes every splat touches, apart from the data AOVs (PixelAOVAccum) so that a
/// splat's ~16 pixels span 16 small records instead of 16 cache lines and more, and rgb
/// and alpha are four neighbouring doubles (one AVX2 operation per pixel).
struct PixelAccum {
  double rgb[3] = {0, 0, 0};
  double alpha = 0;
  double weight = 0;  // Σ filter weights of the beauty (rgb, alpha) sums
};

/// Running sums of the data AOVs of one pixel (its own samples only, unfiltered).
struct PixelAOVAccum {
  // Albedo as a ratio estimator: Σ XYZ(albedo·white) / Σ XYZ(white) over the same
  // wavelengths cancels most spectral noise (exact for flat reflectances).
  double albedo_xyz[3] = {0, 0, 0};
  double white_xyz[3] = {0, 0, 0};
  double normal[3] = {0, 0, 0};
  double depth = 0;
  uint32_t depth_count = 0;
};

/// The film as the render loop writes it: w × h pixels, row-major top-down.
struct FilmView {
  PixelAccum* pixels;
  int width, height;
  PixelAccum& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

/// 1D splat weights w[i] = weight_1d(p − (i0 + i + ½)) for pixels i0..i1. Gaussian: two
/// exponentials instead of one per pixel, by the recurrence of consecutive Gaussians
/// with a = 1/(2σ²), d = p − (i + ½):  w(d − 1) = w(d) r,  r(d − 1) = r(d) q,  q = e^(−2a),
/// r(d) = e^(a(2d − 1)); a relative error of ~2e-6 over ≤ 18 steps. `q` is passed
/// in so a splat computes it once for both axes.
inline void filter_weights(const PixelFilter& f, Float q, Float p, int i0, int i1, Float* w) {
  const Float a = 1 / (2 * f.sigma * f.sigma);
  const Float d0 = p - (Float(i0) + 0.5f), d1 = p - (Float(i1) + 0.5f);
  // Box filters, and Gaussians where the recurrence would leave float's range: one
  // weight_1d per pixel.
  if (f.type != FilterType::Gaussian || a * sqr(fmax_(std::fabs(d0), std::fabs(d1)) + 1) > 80) {
    for (int i = i0; i <= i1; ++i) w[i - i0] = f.weight_1d(p - (Float(i) + 0.5f));
    return;
  }
  // |exponents| ≤ 80 here (the test above): exp_poly, no library call (the splat's four
  // expf calls were 2.4% of a Cornell box render's instructions).
  Float wi = exp_poly(-a * d0 * d0), r = exp_poly(a * (2 * d0 - 1));
  for (int i = i0; i <= i1; ++i) {
    const Float d = p - (Float(i) + 0.5f);
    w[i - i0] = (d >= -f.radius && d < f.radius) ? wi : Float(0);
    wi *= r;
    r *= q;
  }
}
/// q = e^(−2a) = e^(−1/σ²) of filter_weights: a constant of the filter, computed once per
/// render rather than per splat.
inline Float gaussian_step_ratio(const PixelFilter& f) { return std::exp(-1 / (f.sigma * f.sigma)); }
inline void filter_weights(const PixelFilter& f, Float p, int i0, int i1, Float* w) {
  filter_weights(f, gaussian_step_ratio(f), p, i0, i1, w);
}

namespace film_detail {
/// Adds w · v to a pixel's (rgb, alpha) sums and, with kAddWeight, w to its weight. On the
/// CPU the four sums are one 4-wide double operation (GCC/Clang vector type, AVX with
/// x86-64-v3).
template <bool kAddWeight = true>
inline void accumulate(PixelAccum& a, double w, const double v[4]) {
#if defined(__GNUC__) || defined(__clang__)
  typedef double F64x4 __attribute__((vector_size(32)));
  F64x4 s, vv;
  __builtin_memcpy(&s, a.rgb, sizeof s);  // rgb[3] and alpha are adjacent (PixelAccum)
  __builtin_memcpy(&vv, v, sizeof vv);
  s += w * vv;
  __builtin_memcpy(a.rgb, &s, sizeof s);
#else
  for (int k = 0; k < 3; ++k) a.rgb[k] += w * v[k];
  a.alpha += w * v[3];
#endif
  if (kAddWeight) a.weight += w;
}

/// The first of the 4 pixel centres (along one axis) within a radius-2 support
/// [p − 2, p + 2) of position p, and their weights by filter_weights' recurrence written
/// for exactly 4 pixels (through filter_weights, whose span and support test are general,
/// the splat's gain shrinks from −2.2% / −5.1% of the instructions to −1.4% / −3.3% on
/// cornell / hangar); false where the 4 are not exactly the support's (rounding at a
/// boundary) or the recurrence would leave float's range: the caller then takes the
/// general path.
inline bool gaussian_weights4(const PixelFilter& f, Float q, Float p, int* first, Float w[4]) {
  int i0 = int(std::floor(p)) - 2;
  Float d0 = p - (Float(i0) + 0.5f);
  if (!(d0 < f.radius)) d0 = p - (Float(++i0) + 0.5f);
  if (!(d0 < f.radius) || !(p - (Float(i0 + 3) + 0.5f) >= -f.radius)) return false;
  const Float a = 1 / (2 * f.sigma * f.sigma);
  if (a * 9 > 80) return false;  // |d| ≤ 2: the bound filter_weights tests
  Float r = exp_poly(a * (2 * d0 - 1));
  w[0] = exp_poly(-a * d0 * d0);
  for (int k = 1; k < 4; ++k) {
    w[k] = w[k - 1] * r;
    r *= q;
  }
  *first = i0;
  return true;
}

/// splat_sample's common case: a Gaussian of radius 2 (kauri's and Mitsuba's default),
/// whose support holds exactly 4 pixel centres per axis, wholly inside the image. Fixed
/// trip counts, so the 16 accumulations unroll, with no clipping or trimming of
/// zero-weight ends. False (nothing added) where that does not apply.
template <bool kAddWeight>
inline bool splat_gaussian_4x4(const FilmView& film, const PixelFilter& f, Float q, Vec2 p, const double v[4]) {
  if (f.type != FilterType::Gaussian || f.radius != 2) return false;
  int x0, y0;
  Float wx[4], wy[4];
  if (!gaussian_weights4(f, q, p.x, &x0, wx) || !gaussian_weights4(f, q, p.y, &y0, wy)) return false;
  if (x0 < 0 || y0 < 0 || x0 + 3 >= film.width || y0 + 3 >= film.height) return false;
  for (int j = 0; j < 4; ++j) {
    PixelAccum* row = &film.at(x0, y0 + j);
    for (int i = 0; i < 4; ++i) accumulate<kAddWeight>(row[i], double(wx[i] * wy[j]), v);
  }
  return true;
}
}  // namespace film_detail

/// Adds a beauty sample (rgb, alpha) at raster position p (pixels, y down) to every pixel
/// the filter reaches, clipped to the image. Host code: pixels touched by one call
/// lie within filter.margin() of p's pixel, which the render loop's tile phases rely on.
/// Pixels of zero weight (outside the support) inside the span are added to as well, with
/// nothing: no branch per pixel, and x + 0 = x.
/// `q`: gaussian_step_ratio(filter). kAddWeight false: the sample adds to the pixels'
/// sums but not to their weights Σ w, for a part of another sample's estimate that was
/// sampled apart (the render loop's light antialiasing, render/light_aa.h).
template <bool kAddWeight = true>
inline void splat_sample(const FilmView& film, const PixelFilter& filter, Float q, Vec2 p, Vec3 rgb, Float alpha) {
  static_assert(offsetof(PixelAccum, alpha) == 3 * sizeof(double), "rgb and alpha must be adjacent");
  constexpr int kMaxSpan = 2 * int(kMaxFilterRadius) + 2;  // render() refuses larger radii
  const double v[4] = {double(rgb.x), double(rgb.y), double(rgb.z), double(alpha)};
  if (film_detail::splat_gaussian_4x4<kAddWeight>(film, filter, q, p, v)) return;
  const int m = filter.margin(), px = int(std::floor(p.x)), py = int(std::floor(p.y));
  const int x0 = std::max(0, px - m), x1 = std::min(film.width - 1, px + m);
  const int y0 = std::max(0, py - m), y1 = std::min(film.height - 1, py + m);
  if (x1 - x0 + 1 > kMaxSpan || y1 - y0 + 1 > kMaxSpan) return;
  Float wx[kMaxSpan], wy[kMaxSpan];
  filter_weights(filter, q, p.x, x0, x1, wx);
  filter_weights(filter, q, p.y, y0, y1, wy);
  // The span is 2m + 1 pixels, the support of a radius-r filter 2r: with r = 2 one end
  // column and one end row always weigh 0 (25 pixels become 16). Dropping zero-weight ends
  // changes no sum, and only ends are dropped: no branch per pixel.
  int bx = 0, ex = x1 - x0, by = 0, ey = y1 - y0;
  if (ex > 0 && wx[0] == 0) ++bx;
  if (ex > bx && wx[ex] == 0) --ex;
  if (ey > 0 && wy[0] == 0) ++by;
  if (ey > by && wy[ey] == 0) --ey;
  for (int j = by; j <= ey; ++j) {
    PixelAccum* row = &film.at(x0, y0 + j);
    const Float wrow = wy[j];
    for (int i = bx; i <= ex; ++i) film_detail::accumulate<kAddWeight>(row[i], double(wx[i] * wrow), v);
  }
}
inline void splat_sample(const FilmView& film, const PixelFilter& filter, Vec2 p, Vec3 rgb, Float alpha) {
  splat_sample(film, filter, gaussian_step_ratio(filter), p, rgb, alpha);
}

}  // namespace kauri
