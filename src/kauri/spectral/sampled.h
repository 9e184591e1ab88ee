// SampledSpectrum and SampledWavelengths: the 4-wavelength representation that
// every path carries (hero wavelength sampling, Wilkie et al. 2014).
#pragma once

#include <cmath>

#include "kauri/core/lanes.h"
#include "kauri/core/math.h"

namespace kauri {

inline constexpr int kSpectrumSamples = 4;
inline constexpr Float kLambdaMin = 360;
inline constexpr Float kLambdaMax = 830;

/// Radiance, throughput or reflectance at the path's 4 wavelengths. 16-byte aligned (as
/// CUDA's float4): the compiler then moves and combines the four floats as one SSE
/// register (~1.3% faster renders on every peer-suite scene, A/B of alternating builds).
struct alignas(16) SampledSpectrum {
  Float v[kSpectrumSamples] = {0, 0, 0, 0};

  KAURI_HOST_DEVICE SampledSpectrum() = default;
  KAURI_HOST_DEVICE explicit SampledSpectrum(Float c) { for (Float& x : v) x = c; }
  KAURI_HOST_DEVICE Float operator[](int i) const { return v[i]; }
  KAURI_HOST_DEVICE Float& operator[](int i) { return v[i]; }

#define KAURI_SS_OP(op)                                                                  \
  KAURI_HOST_DEVICE SampledSpectrum& operator op##=(const SampledSpectrum& b) {          \
    for (int i = 0; i < kSpectrumSamples; ++i) v[i] op## = b.v[i];                       \
    return *this;                                                                        \
  }                                                                                      \
  KAURI_HOST_DEVICE SampledSpectrum operator op(const SampledSpectrum& b) const {        \
    SampledSpectrum r = *this;                                                           \
    return r op## = b;                                                                   \
  }
  KAURI_SS_OP(+)
  KAURI_SS_OP(-)
  KAURI_SS_OP(*)
#undef KAURI_SS_OP
  KAURI_HOST_DEVICE SampledSpectrum& operator*=(Float s) { for (Float& x : v) x *= s; return *this; }
  KAURI_HOST_DEVICE SampledSpectrum operator*(Float s) const { SampledSpectrum r = *this; return r *= s; }
  KAURI_HOST_DEVICE SampledSpectrum operator/(Float s) const { return *this * (1 / s); }
  /// Component-wise division that yields 0 where the divisor is 0.
  KAURI_HOST_DEVICE SampledSpectrum safe_div(const SampledSpectrum& b) const {
    SampledSpectrum r;
    for (int i = 0; i < kSpectrumSamples; ++i) r.v[i] = b.v[i] != 0 ? v[i] / b.v[i] : 0;
    return r;
  }
  // With 4 wavelengths in one SSE register on the CPU, each test is a vector compare and a
  // mask test, where a loop with an early return per wavelength was a compare and a branch
  // each (is_black: 1.1% of a Cornell box render's instructions; it runs after every
  // emission, BSDF value and light sample). The loops stay for CUDA and other widths.
  KAURI_HOST_DEVICE bool is_black() const {
#if KAURI_LANES_AVX2
    if constexpr (kSpectrumSamples == 4)
      return _mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(v), _mm_setzero_ps())) == 0;
#endif
    for (Float x : v) if (x != 0) return false;
    return true;
  }
  KAURI_HOST_DEVICE bool is_finite() const {
#if KAURI_LANES_AVX2
    if constexpr (kSpectrumSamples == 4) {
      // |x| < ∞ is false for ±∞ and NaN (an ordered compare).
      const __m128 abs = _mm_andnot_ps(_mm_set1_ps(-0.0f), _mm_loadu_ps(v));
      return _mm_movemask_ps(_mm_cmplt_ps(abs, _mm_set1_ps(INFINITY))) == 0xF;
    }
#endif
    for (Float x : v) if (!std::isfinite(x)) return false;
    return true;
  }
  KAURI_HOST_DEVICE Float max_value() const {
    Float m = v[0];
    for (Float x : v) m = fmax_(m, x);
    return m;
  }
  KAURI_HOST_DEVICE Float average() const {
    Float s = 0;
    for (Float x : v) s += x;
    return s / kSpectrumSamples;
  }
};
KAURI_HOST_DEVICE inline SampledSpectrum operator*(Float s, const SampledSpectrum& a) { return a * s; }
KAURI_HOST_DEVICE inline SampledSpectrum sqrt(const SampledSpectrum& a) {
  SampledSpectrum r;
  for (int i = 0; i < kSpectrumSamples; ++i) r.v[i] = std::sqrt(a.v[i]);
  return r;
}
KAURI_HOST_DEVICE inline SampledSpectrum exp(const SampledSpectrum& a) {
  SampledSpectrum r;
  for (int i = 0; i < kSpectrumSamples; ++i) r.v[i] = std::exp(a.v[i]);
  return r;
}

/// Visible-range importance density: a sech^2 lobe centred at 538 nm on
/// [360, 830] nm, which follows the CIE luminous efficiency closely enough to
/// cut colour noise against uniform sampling (pbrt-v4, "SampleVisibleWavelengths").
KAURI_HOST_DEVICE inline Float visible_wavelength_pdf(Float lambda) {
  if (lambda < kLambdaMin || lambda > kLambdaMax) return 0;
  return 0.0039398042f / sqr(std::cosh(0.0072f * (lambda - 538)));
}
KAURI_HOST_DEVICE inline Float sample_visible_wavelength(Float u) {
  return 538 - 138.888889f * std::atanh(0.85691062f - 1.82750197f * u);
}
/// Both at once, without cosh or atanh: with y = 0.85691062 − 1.82750197 u,
/// λ = 538 − 138.888889 atanh(y), and since 0.0072 · 138.888889 = 1,
/// cosh²(0.0072 (λ − 538)) = cosh²(atanh y) = 1 / (1 − y²), so pdf = 0.0039398042 (1 − y²);
/// atanh y = ½ log((1 + y) / (1 − y)). u ∈ [0, 1) keeps λ inside [360, 830] nm.
KAURI_HOST_DEVICE inline Float sample_visible_wavelength(Float u, Float* pdf) {
  Float y = 0.85691062f - 1.82750197f * u;
  Float lambda = 538 - 69.4444445f * std::log((1 + y) / (1 - y));
  if (!(lambda >= kLambdaMin && lambda <= kLambdaMax)) {  // float rounding at the ends
    lambda = clamp(lambda, kLambdaMin, kLambdaMax);
    *pdf = visible_wavelength_pdf(lambda);
    return lambda;
  }
  *pdf = 0.0039398042f * (1 - y * y);
  return lambda;
}

/// The path's wavelengths and their sampling densities. Sample 0 is the hero:
/// direction sampling that depends on wavelength uses it alone.
struct SampledWavelengths {
  Float lambda[kSpectrumSamples];
  Float pdf[kSpectrumSamples];

  /// Four wavelengths stratified in the CDF of the visible density (rotation
  /// of the hero sample by 1/4 in primary sample space).
  KAURI_HOST_DEVICE static SampledWavelengths sample_visible(Float u) {
    return sample_stratified(u, [](Float ui, Float* pdf) { return sample_visible_wavelength(ui, pdf); });
  }
  /// The N wavelengths of any inverse CDF `sample(u, &pdf)`: the hero at u, wavelength i
  /// at u + i/N (mod 1), each with its density.
  template <class Sample1D>
  KAURI_HOST_DEVICE static SampledWavelengths sample_stratified(Float u, const Sample1D& sample) {
    SampledWavelengths w;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      Float ui = u + Float(i) / kSpectrumSamples;
      if (ui >= 1) ui -= 1;
      w.lambda[i] = sample(ui, &w.pdf[i]);
    }
    return w;
  }
  KAURI_HOST_DEVICE static SampledWavelengths sample_uniform(Float u) {
    SampledWavelengths w;
    const Float width = kLambdaMax - kLambdaMin;
    w.lambda[0] = kLambdaMin + u * width;
    for (int i = 1; i < kSpectrumSamples; ++i) {
      w.lambda[i] = w.lambda[i - 1] + width / kSpectrumSamples;
      if (w.lambda[i] > kLambdaMax) w.lambda[i] -= width;
    }
    for (Float& p : w.pdf) p = 1 / width;
    return w;
  }
  KAURI_HOST_DEVICE SampledSpectrum pdf_spectrum() const {
    SampledSpectrum s;
    for (int i = 0; i < kSpectrumSamples; ++i) s.v[i] = pdf[i];
    return s;
  }
  /// A wavelength-dependent specular event (dispersion) keeps only the hero;
  /// it then stands for all four stratified samples, hence the 1/4.
  KAURI_HOST_DEVICE void terminate_secondary() {
    if (secondary_terminated()) return;
    for (int i = 1; i < kSpectrumSamples; ++i) pdf[i] = 0;
    pdf[0] /= kSpectrumSamples;
  }
  KAURI_HOST_DEVICE bool secondary_terminated() const {
    for (int i = 1; i < kSpectrumSamples; ++i) if (pdf[i] != 0) return false;
    return true;
  }
};

}  // namespace kauri
