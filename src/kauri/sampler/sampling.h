// Warping functions from [0,1)^n to common domains, with their densities.
// Every routine here has a chi-square test in tests/cpp/test_sampling.cpp.
#pragma once

#include "kauri/core/math.h"

namespace kauri {

/// (cos φ, sin φ) for |φ| ≤ π/4 by their Taylor series to degree 10 and 9: the first
/// omitted terms, φ¹²/12! and φ¹¹/11!, are below 2e-9 there, under float's rounding. No
/// range reduction, no library call, and the same on every CPU and on CUDA.
KAURI_HOST_DEVICE inline Vec2 cos_sin_quarter(Float phi) {
  const Float x2 = phi * phi;
  const Float c = 1 + x2 * (-1.0f / 2 + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320 - x2 * (1.0f / 3628800)))));
  const Float s = phi * (1 + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880)))));
  return {c, s};
}

/// (cos 2πt, sin 2πt) for t in [0, 1], a fraction of a turn (a sample dimension, a
/// lat-long coordinate). The nearest quarter turn k/4 is taken out of t itself, exactly,
/// so the remainder |2π(t − k/4)| ≤ π/4 goes to cos_sin_quarter with no rounding of π in
/// the reduction; the k quarter turns are then a swap (k odd) and two sign flips, selected
/// without branches (t is often a fresh random number). libm's sincosf and sinf were ~2.5%
/// of the environment scene's render.
KAURI_HOST_DEVICE inline Vec2 cos_sin_turns(Float t) {
  const Float q = std::floor(4 * t + Float(0.5));  // the nearest quarter, 0..4
  const Vec2 cs = cos_sin_quarter(2 * kPi * (t - Float(0.25) * q));
  const uint32_t k = uint32_t(int(q)) & 3u;
  // Rotation by k quarter turns: (c, s) → (−s, c), (−c, −s), (s, −c) for k = 1, 2, 3.
  const Float odd = Float(k & 1u);
  const Float x = select_if_less(odd, Float(0.5), cs.x, cs.y), y = select_if_less(odd, Float(0.5), cs.y, cs.x);
  const uint32_t flip_x = ((k + 1u) & 2u) << 30, flip_y = (k & 2u) << 30;
  return {bits_as_float(float_as_bits(x) ^ flip_x), bits_as_float(float_as_bits(y) ^ flip_y)};
}

/// Concentric square → disk mapping (Shirley & Chiu 1997): low distortion keeps strata.
/// Each wedge's angle is π/4 · (ratio) within a quarter turn, so the cosine and sine come
/// from cos_sin_quarter (libm's sincosf was 1.8% of a Cornell box render's instructions).
/// The wedge is decided by a fresh random number, which no branch predictor learns: the
/// operands are selected (select_if_less), bit for bit the two-branch form
/// (θ = π/4 · b/a where |a| > |b|, else π/2 − π/4 · a/b).
KAURI_HOST_DEVICE inline Vec2 sample_uniform_disk(Vec2 u) {
  Float a = 2 * u.x - 1, b = 2 * u.y - 1;
  if (a == 0 && b == 0) return {0, 0};
  const Float abs_a = std::fabs(a), abs_b = std::fabs(b);  // |a| > |b|: the wedge of θ = π/4 · b/a
  const Float r = select_if_less(abs_b, abs_a, a, b), q = select_if_less(abs_b, abs_a, b, a);
  const Vec2 cs = cos_sin_quarter(kPiOver4 * (q / r));
  return {r * select_if_less(abs_b, abs_a, cs.x, cs.y), r * select_if_less(abs_b, abs_a, cs.y, cs.x)};
}

/// Malley's method: cosine-weighted hemisphere around +z, pdf = cosθ/π. The concentric
/// map's radius is r = max(|2u.x − 1|, |2u.y − 1|), so z = √((1 − r)(1 + r)) is known from
/// u alone and computed beside the disk point's division and polynomial, not after them
/// (√(1 − x² − y²) was the end of that dependency chain on every diffuse bounce).
KAURI_HOST_DEVICE inline Vec3 sample_cosine_hemisphere(Vec2 u) {
  const Float r = fmax_(std::fabs(2 * u.x - 1), std::fabs(2 * u.y - 1));
  const Vec2 d = sample_uniform_disk(u);
  return {d.x, d.y, safe_sqrt((1 - r) * (1 + r))};
}
KAURI_HOST_DEVICE inline Float cosine_hemisphere_pdf(Float cos_theta) { return fmax_(cos_theta, 0) * kInvPi; }

KAURI_HOST_DEVICE inline Vec3 sample_uniform_sphere(Vec2 u) {
  Float z = 1 - 2 * u.x;
  Float r = safe_sqrt(1 - z * z);
  const Vec2 cs = cos_sin_turns(u.y);  // φ = 2π u.y
  return {r * cs.x, r * cs.y, z};
}
KAURI_HOST_DEVICE inline Float uniform_sphere_pdf() { return kInv4Pi; }

/// Uniform direction in the cone of half-angle acos(cos_max) around +z.
KAURI_HOST_DEVICE inline Vec3 sample_uniform_cone(Vec2 u, Float cos_max) {
  Float cos_t = (1 - u.x) + u.x * cos_max;
  Float sin_t = safe_sqrt(1 - cos_t * cos_t);
  const Vec2 cs = cos_sin_turns(u.y);  // φ = 2π u.y
  return {sin_t * cs.x, sin_t * cs.y, cos_t};
}
KAURI_HOST_DEVICE inline Float uniform_cone_pdf(Float cos_max) { return 1 / (2 * kPi * (1 - cos_max)); }

/// Uniform barycentrics (b0, b1) on a triangle (Heitz 2019, "A low-distortion map
/// between triangle and square"); b2 = 1 - b0 - b1.
/// The half of the square holding u is selected, not branched on (select_if_less);
/// bit for bit the form with b0 = u.x / 2, b1 = u.y − b0 where u.x < u.y, else
/// b1 = u.y / 2, b0 = u.x − b1.
KAURI_HOST_DEVICE inline Vec2 sample_uniform_triangle(Vec2 u) {
  const Float h = select_if_less(u.x, u.y, u.x, u.y) / 2;
  return {select_if_less(u.x, u.y, h, u.x - h), select_if_less(u.x, u.y, u.y - h, h)};
}

/// Inverse error function, single precision (Giles 2010, "Approximating the erfinv function").
KAURI_HOST_DEVICE inline Float erf_inv(Float x) {
  Float w = -std::log(fmax_((1 - x) * (1 + x), 1e-30f));
  Float p;
  if (w < 5) {
    w = w - 2.5f;
    p = 2.81022636e-08f;
    p = 3.43273939e-07f + p * w;
    p = -3.5233877e-06f + p * w;
    p = -4.39150654e-06f + p * w;
    p = 0.00021858087f + p * w;
    p = -0.00125372503f + p * w;
    p = -0.00417768164f + p * w;
    p = 0.246640727f + p * w;
    p = 1.50140941f + p * w;
  } else {
    w = std::sqrt(w) - 3;
    p = -0.000200214257f;
    p = 0.000100950558f + p * w;
    p = 0.00134934322f + p * w;
    p = -0.00367342844f + p * w;
    p = 0.00573950773f + p * w;
    p = -0.0076224613f + p * w;
    p = 0.00943887047f + p * w;
    p = 1.00167406f + p * w;
    p = 2.83297682f + p * w;
  }
  return p * x;
}

/// Gaussian of std-dev `sigma` truncated to [-r, r], sampled exactly by inverting its CDF.
KAURI_HOST_DEVICE inline Float sample_truncated_gaussian(Float u, Float sigma, Float r) {
  Float k = 1 / (sigma * 1.41421356f);
  Float e = std::erf(r * k);
  Float x = erf_inv(clamp((2 * u - 1) * e, -kOneMinusEpsilon, kOneMinusEpsilon)) / k;
  return clamp(x, -r, r);
}
KAURI_HOST_DEVICE inline Float truncated_gaussian_pdf(Float x, Float sigma, Float r) {
  if (std::fabs(x) > r) return 0;
  Float norm = std::erf(r / (sigma * 1.41421356f));
  return std::exp(-x * x / (2 * sigma * sigma)) / (sigma * 2.50662827f * norm);
}

/// Index of the last cdf entry <= u among cdf[0..n) (cdf[0] = 0 <= u < cdf[n] = 1). The
/// halving steps depend on n alone and each one moves `lo` by a select, not a branch: the
/// comparisons are decided by fresh random numbers, and as branches they missed every other
/// step (light selection by power, the environment's two-level search).
KAURI_HOST_DEVICE inline int find_interval(const Float* cdf, int n, Float u) {
  int lo = 0, len = n;  // the answer lies in [lo, lo + len)
  while (len > 1) {
    const int half = len / 2;
    lo = cdf[lo + half] <= u ? lo + half : lo;
    len -= half;
  }
  return lo;
}

/// Piecewise-constant 1D density on [0,1) over n bins; a view over host-owned arrays.
struct Distribution1D {
  const Float* func = nullptr;  // n non-negative values
  const Float* cdf = nullptr;   // n + 1 values
  int n = 0;
  Float integral = 0;           // ∫ func over [0,1)
  // discrete_pmf(i) of every bin, computed when the distribution is built (the light
  // choice reads one per next-event sample and per emitter hit: a division saved each);
  // null: computed at each call (the conditional rows of a Distribution2D).
  const Float* pmf = nullptr;

  /// Continuous sample in [0,1); returns its pdf and the bin.
  KAURI_HOST_DEVICE Float sample_continuous(Float u, Float* pdf, int* bin) const {
    int i = find_interval(cdf, n, u);
    Float width = cdf[i + 1] - cdf[i];
    Float du = width > 0 ? (u - cdf[i]) / width : Float(0.5);
    if (pdf) *pdf = integral > 0 ? func[i] / integral : 0;
    if (bin) *bin = i;
    Float x = fmin_((Float(i) + du) / Float(n), kOneMinusEpsilon);
    // Rounding of (i + du)/n can put x in a neighbouring bin (du within an ulp of 0
    // or 1); keep it in bin i so that pdf(x) agrees with the density reported here.
    while (int(x * Float(n)) < i) x = bits_as_float(float_as_bits(x) + 1);
    while (i < n - 1 && int(x * Float(n)) > i) x = bits_as_float(float_as_bits(x) - 1);
    return x;
  }
  /// Discrete sample: bin i with probability func[i]·(1/n)/integral. `u_remapped` gets
  /// u rescaled to [0,1) within the bin, so one number can drive a further choice.
  KAURI_HOST_DEVICE int sample_discrete(Float u, Float* pmf, Float* u_remapped = nullptr) const {
    int i = find_interval(cdf, n, u);
    if (pmf) *pmf = discrete_pmf(i);
    if (u_remapped) {
      Float width = cdf[i + 1] - cdf[i];
      *u_remapped = width > 0 ? fmin_((u - cdf[i]) / width, kOneMinusEpsilon) : Float(0);
    }
    return i;
  }
  KAURI_HOST_DEVICE Float discrete_pmf(int i) const {
    if (pmf) return pmf[i];
    // func[i] is read only where the integral is positive: an empty distribution (no
    // finite lights: its arrays are null) answers 0 for any light.
    return integral > 0 ? func[i] / (integral * Float(n)) : 0;
  }
  KAURI_HOST_DEVICE Float pdf(Float x) const {
    int i = int(x * Float(n));
    i = i < 0 ? 0 : (i >= n ? n - 1 : i);
    return integral > 0 ? func[i] / integral : 0;
  }
};

/// Piecewise-constant 2D density on [0,1)^2: a marginal over rows (v) and one
/// conditional per row (u). Views over host-owned arrays (Distribution2DStorage), the rows
/// one after another: conditional[v].func = conditional[0].func + v·nu and
/// conditional[v].cdf = conditional[0].cdf + v·(nu + 1), so the whole table can also be read
/// flat (the path lanes' gathers); the marginal's values are the rows' integrals.
struct Distribution2D {
  const Distribution1D* conditional = nullptr;  // nv rows
  Distribution1D marginal;
  int nu = 0, nv = 0;

  KAURI_HOST_DEVICE Vec2 sample(Vec2 u, Float* pdf) const {
    Float pdf_v, pdf_u;
    int v;
    Float y = marginal.sample_continuous(u.y, &pdf_v, &v);
    Float x = conditional[v].sample_continuous(u.x, &pdf_u, nullptr);
    *pdf = pdf_v * pdf_u;
    return {x, y};
  }
  KAURI_HOST_DEVICE Float pdf(Vec2 p) const {
    int iu = int(p.x * Float(nu)), iv = int(p.y * Float(nv));
    iu = iu < 0 ? 0 : (iu >= nu ? nu - 1 : iu);
    iv = iv < 0 ? 0 : (iv >= nv ? nv - 1 : iv);
    return marginal.integral > 0 ? conditional[iv].func[iu] / marginal.integral : 0;
  }
};

/// Power heuristic with β = 2 (Veach 1997, eq. 9.13).
KAURI_HOST_DEVICE inline Float power_heuristic(Float pdf_a, Float pdf_b) {
  Float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (!(a < kInfinity)) return 1;
  return a + b > 0 ? a / (a + b) : 0;
}

}  // namespace kauri
