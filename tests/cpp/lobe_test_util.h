// Small helpers shared by the lobe tests: directions, 4-sample spectra and the
// Monte Carlo directional albedo estimator.
#pragma once

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/sampler/rng.h"

namespace kauri::test {

inline Vec2 next_2d(PCG32& rng) {
  Float a = rng.next_float();
  return {a, rng.next_float()};
}

inline SampledWavelengths test_wavelengths() { return SampledWavelengths::sample_visible(0.3f); }

/// Unit direction with the given cosθ and azimuth φ (local frame).
inline Vec3 dir(Float cos_t, Float phi) {
  Float s = safe_sqrt(1 - cos_t * cos_t);
  return {s * std::cos(phi), s * std::sin(phi), cos_t};
}

inline SampledSpectrum spectrum4(Float a, Float b, Float c, Float d) {
  SampledSpectrum s;
  s[0] = a;
  s[1] = b;
  s[2] = c;
  s[3] = d;
  return s;
}

inline std::string fmt(double v, int prec = 4) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

inline bool rel_close(double a, double b, double tol) {
  return std::fabs(a - b) <= tol * std::max(std::fabs(a), std::fabs(b));
}

struct Albedo {
  double mean[kSpectrumSamples];
  double sigma[kSpectrumSamples];
  double mean_t;  // hero wavelength, transmitted part only
};

/// Monte Carlo directional albedo ∫ f |cosθ_i| dω_i = E[f |cosθ_i| / pdf] with the lobe's
/// own sampler (failed samples count 0); `stream` selects the PCG32 sequence.
template <class L>
Albedo directional_albedo(const L& lobe, Vec3 wo, uint64_t seed, int n, TransportMode mode = TransportMode::Radiance,
                          uint64_t stream = 3) {
  PCG32 rng(seed, stream);
  const SampledWavelengths lambda0 = test_wavelengths();
  double sum[kSpectrumSamples] = {}, sum2[kSpectrumSamples] = {}, sum_t = 0;
  for (int k = 0; k < n; ++k) {
    SampledWavelengths lambda = lambda0;
    Float uc = rng.next_float();
    BSDFSample s = lobe.sample(wo, uc, next_2d(rng), lambda, mode);
    if (!s.valid()) continue;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      double w = double(s.f[i]) * std::fabs(double(s.wi.z)) / double(s.pdf);
      sum[i] += w;
      sum2[i] += w * w;
      if (i == 0 && s.wi.z * wo.z < 0) sum_t += w;
    }
  }
  Albedo a;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    a.mean[i] = sum[i] / n;
    a.sigma[i] = std::sqrt(std::max(0.0, sum2[i] / n - a.mean[i] * a.mean[i]) / n);
  }
  a.mean_t = sum_t / n;
  return a;
}

}  // namespace kauri::test
