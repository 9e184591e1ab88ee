// Wavelength importance sampling for an RGB output.
//
// A path's wavelengths are drawn from a density p(λ); the film estimates each RGB
// channel c as (1/N) Σ_i r̄_c(λ_i) L(λ_i) / p(λ_i), with r̄_c = the output space's
// colour-matching functions (rows of XYZ→RGB times x̄, ȳ, z̄). The colour noise of that
// estimate is the mismatch between p and r̄_c L. pbrt-v4's sech² "visible" density
// follows ȳ, so it starves the blue channel (z̄ peaks at 445 nm): for a grey sky its
// relative variance in blue is 0.34 per 4-wavelength sample. Sampling instead
//     p(λ) ∝ (Σ_c |r̄_c(λ)| I(λ) / mean)^½ + 0.02,
// the absolute matching functions of the space the film writes times that space's
// illuminant I (every RGB emitter and environment texel is lifted against I, so it is a
// factor of L on every path lit by them), flattened by the square root because the 4
// wavelengths are stratified (wavelength i at u + i/4), lowers the summed R+G+B relative
// variance of a sample 3.4-16× for grey, red, green, blue and gold reflectances (grey:
// 0.36 → 0.028; tests/cpp/test_wavelength_sampling.cpp measures it, docs/spectral.md
// has the table). The floor keeps p > 0 wherever any CMF is, so every spectrum is
// estimated without bias.
//
// The density is stored as its inverse CDF at uniform steps of u: sampling is one
// lerp, exactly stratified, and p is constant between knots.
#pragma once

#include <vector>

#include "kauri/spectral/sampled.h"

namespace kauri {

/// λ = F⁻¹(u), tabulated at u_k = k / (n − 1); knots strictly increasing from 360 to
/// 830 nm. Between knots λ is linear in u, so p = 1 / ((n − 1) (λ_{k+1} − λ_k)) there.
struct WavelengthDistribution {
  const float* knots = nullptr;
  int n = 0;

  KAURI_HOST_DEVICE Float sample(Float u, Float* pdf) const {
    Float t = u * Float(n - 1);
    int k = t >= Float(n - 2) ? n - 2 : int(t);
    Float a = knots[k], b = knots[k + 1];
    *pdf = 1 / (Float(n - 1) * (b - a));
    return a + (t - Float(k)) * (b - a);
  }
  /// Density at λ (binary search over the knots); 0 outside [360, 830] nm.
  KAURI_HOST_DEVICE Float pdf(Float lambda) const {
    if (!(lambda >= knots[0] && lambda <= knots[n - 1])) return 0;
    int lo = 0, hi = n - 1;  // knots[lo] <= lambda < knots[hi]
    while (hi - lo > 1) {
      int mid = (lo + hi) / 2;
      if (knots[mid] <= lambda) lo = mid; else hi = mid;
    }
    return 1 / (Float(n - 1) * (knots[lo + 1] - knots[lo]));
  }
};

/// N wavelengths stratified in the CDF (the hero at u, the others at u + i/N), each
/// with its density.
KAURI_HOST_DEVICE inline SampledWavelengths sample_wavelengths(const WavelengthDistribution& d, Float u) {
  return SampledWavelengths::sample_stratified(u, [&d](Float ui, Float* pdf) { return d.sample(ui, pdf); });
}

// ---- host (wavelength_sampling.cpp) ----

/// Knots of F⁻¹ for the density above, for the space with matrix `xyz_to_rgb` and
/// illuminant `illuminant` (kCieSamples values on the 1 nm CIE grid, any scale).
std::vector<float> output_wavelength_knots(const Float xyz_to_rgb[3][3], const float* illuminant, int n = 1025);

/// Knots of F⁻¹ for any density given on the 1 nm CIE grid (360…830 nm, 471 values,
/// each > 0): constant on each 1 nm interval at the mean of its two end values.
std::vector<float> inverse_cdf_knots(const float* density, int n);

}  // namespace kauri
