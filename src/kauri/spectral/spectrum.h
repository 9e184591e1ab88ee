// Spectral distributions evaluated at the path's wavelengths. A tagged union with
// switch dispatch (no virtuals) so the same code can run on a GPU later.
#pragma once

#include <cmath>
#include <cstdint>

#include "kauri/core/math.h"
#include "kauri/spectral/rgb_to_spectrum.h"
#include "kauri/spectral/sampled.h"
#include "kauri/spectral/spectral_tables.h"

namespace kauri {

/// Tabulated spectrum on a uniform grid; linear interpolation, 0 outside the grid.
struct DenselySampled {
  const float* values;
  Float lambda_min;
  Float step;
  int count;

  /// Branch-free (selects, not jumps), so sample_dense's loop over the wavelengths has no
  /// unpredictable branches: each RGB light's emission and each environment lookup reads
  /// the illuminant at 4 wavelengths.
  KAURI_HOST_DEVICE Float operator()(Float lambda) const {
    const Float t = (lambda - lambda_min) / step;
    const bool inside = t >= 0 && t <= Float(count - 1);  // false for NaN
    const Float tc = inside ? t : Float(0);
    const int i = int(tc) < count - 2 ? int(tc) : count - 2;  // the last knot: the last interval's end
    const Float v = lerp(tc - Float(i), values[i], values[i + 1]);
    return inside ? v : Float(0);
  }
};

/// `d` at the path's wavelengths.
KAURI_HOST_DEVICE inline SampledSpectrum sample_dense(const DenselySampled& d, const SampledWavelengths& w) {
  SampledSpectrum s;
  for (int i = 0; i < kSpectrumSamples; ++i) s[i] = d(w.lambda[i]);
  return s;
}

/// Planck's law B(lambda, T) in W sr^-1 m^-3 (lambda in nm, T in kelvin).
KAURI_HOST_DEVICE inline Float planck(Float lambda_nm, Float temperature) {
  const Float c = 299792458.f, h = 6.62606957e-34f, kb = 1.3806488e-23f;
  Float l = lambda_nm * 1e-9f;
  Float l5 = (l * l) * (l * l) * l;
  return (2 * h * c * c) / (l5 * std::expm1((h * c) / (l * kb * temperature)));
}

/// Wien's displacement law: wavelength (nm) of the Planck peak.
KAURI_HOST_DEVICE inline Float wien_peak_nm(Float temperature) { return 2.8977721e6f / temperature; }

/// Planck's law divided by its peak value. Writing B(l)/B(l_max) with the peak
/// condition h c / (l_max k T) = 4.965114 (root of x = 5 (1 - e^-x)) cancels every
/// physical constant except the second radiation constant, so it stays well
/// scaled in float for any T.
KAURI_HOST_DEVICE inline Float blackbody_normalized(Float lambda_nm, Float temperature) {
  if (!(temperature > 0) || !(lambda_nm > 0)) return 0;
  const Float kWienX = 4.96511423f;
  const Float kC2 = 1.438777e7f;  // h c / k_B in nm K
  Float peak = wien_peak_nm(temperature);
  Float r = peak / lambda_nm;
  Float r5 = (r * r) * (r * r) * r;
  return r5 * std::expm1(kWienX) / std::expm1(kC2 / (lambda_nm * temperature));
}

/// The sigmoid polynomial p at the path's wavelengths (Jakob & Hanika 2019, eq. 3):
/// branch-free, so the compiler evaluates the four wavelengths as one vector.
KAURI_HOST_DEVICE inline SampledSpectrum sample_sigmoid(const SigmoidPolynomial& p, const SampledWavelengths& w) {
  SampledSpectrum s;
  for (int i = 0; i < kSpectrumSamples; ++i) s[i] = p(w.lambda[i]);
  return s;
}

enum class SpectrumType : uint8_t { Constant, DenselySampled, RGBAlbedo, RGBUnbounded, RGBIlluminant, Blackbody };

/// A spectral distribution. Build with the static factories; copyable POD.
struct Spectrum {
  struct RGBData {
    SigmoidPolynomial poly;
    Float scale;              // 1 for albedo
    DenselySampled illuminant;  // used by RGBIlluminant only
  };
  struct BlackbodyData {
    Float temperature;
    Float scale;
  };

  SpectrumType type;
  union {
    Float constant;
    DenselySampled dense;
    RGBData rgb;
    BlackbodyData blackbody;
  };

  /// Default: the zero spectrum.
  KAURI_HOST_DEVICE Spectrum() : type(SpectrumType::Constant), constant(0) {}

  KAURI_HOST_DEVICE static Spectrum make_constant(Float c) {
    Spectrum s;
    s.type = SpectrumType::Constant;
    s.constant = c;
    return s;
  }
  KAURI_HOST_DEVICE static Spectrum make_dense(DenselySampled d) {
    Spectrum s;
    s.type = SpectrumType::DenselySampled;
    s.dense = d;
    return s;
  }
  KAURI_HOST_DEVICE static Spectrum make_rgb_albedo(SigmoidPolynomial p) {
    return make_rgb(SpectrumType::RGBAlbedo, p, 1, DenselySampled{nullptr, 0, 1, 0});
  }
  KAURI_HOST_DEVICE static Spectrum make_rgb_unbounded(SigmoidPolynomial p, Float scale) {
    return make_rgb(SpectrumType::RGBUnbounded, p, scale, DenselySampled{nullptr, 0, 1, 0});
  }
  KAURI_HOST_DEVICE static Spectrum make_rgb_illuminant(SigmoidPolynomial p, Float scale,
                                                        DenselySampled illuminant) {
    return make_rgb(SpectrumType::RGBIlluminant, p, scale, illuminant);
  }
  /// Blackbody normalised to a peak of 1 (so `scale` is the peak value).
  KAURI_HOST_DEVICE static Spectrum make_blackbody(Float temperature, Float scale = 1) {
    Spectrum s;
    s.type = SpectrumType::Blackbody;
    s.blackbody = {temperature, scale};
    return s;
  }

  KAURI_HOST_DEVICE Float operator()(Float lambda) const {
    switch (type) {
      case SpectrumType::Constant: return constant;
      case SpectrumType::DenselySampled: return dense(lambda);
      case SpectrumType::RGBAlbedo: return rgb.poly(lambda);
      case SpectrumType::RGBUnbounded: return rgb.scale * rgb.poly(lambda);
      case SpectrumType::RGBIlluminant: return rgb.scale * rgb.poly(lambda) * rgb.illuminant(lambda);
      case SpectrumType::Blackbody:
        return blackbody.scale * blackbody_normalized(lambda, blackbody.temperature);
    }
    return 0;
  }

  /// `*this` at the path's wavelengths. The reflectances inline: an RGB albedo's sigmoid,
  /// and a constant (every grey albedo: rgb_albedo() makes a flat sigmoid one),
  /// which out of line cost its call ~50 instructions for a copy (the Cornell box's white
  /// walls: 1.2% of its instructions); the other kinds in sample_other.
  KAURI_HOST_DEVICE KAURI_FORCE_INLINE SampledSpectrum sample(const SampledWavelengths& w) const {
    if (type == SpectrumType::RGBAlbedo) return sample_sigmoid(rgb.poly, w);
    if (type == SpectrumType::Constant) return SampledSpectrum(constant);
    SampledSpectrum s;
    sample_other(w, &s);
    return s;
  }
 private:
  /// sample() of every kind but RGBAlbedo and Constant (which sample() takes inline),
  /// written to `*out` rather than returned. Why: the x86-64 ABI returns 4 floats in two
  /// registers (xmm0, xmm1), which GCC stored to the stack as two overlapping stores and
  /// read back as one 16-byte load, a store-forwarding stall of ~15 cycles on every
  /// out-of-line call (perf: 1–2% of the Cornell box's, glossy and textured renders on the
  /// instruction after the light emission's call). Written through a pointer, the result
  /// leaves in one store that any later load of it can forward from.
  KAURI_HOST_DEVICE void sample_other(const SampledWavelengths& w, SampledSpectrum* out) const {
    // One dispatch for all wavelengths (the common kinds are evaluated inline).
    switch (type) {
      case SpectrumType::Constant:
        *out = SampledSpectrum(constant);
        return;
      case SpectrumType::RGBUnbounded:
        *out = sample_sigmoid(rgb.poly, w) * rgb.scale;
        return;
      case SpectrumType::RGBIlluminant:  // every RGB light and environment
        *out = sample_sigmoid(rgb.poly, w) * rgb.scale * sample_dense(rgb.illuminant, w);
        return;
      case SpectrumType::DenselySampled:
        *out = sample_dense(dense, w);
        return;
      default:
        SampledSpectrum s;
        for (int i = 0; i < kSpectrumSamples; ++i) s[i] = (*this)(w.lambda[i]);
        *out = s;
        return;
    }
  }

  KAURI_HOST_DEVICE static Spectrum make_rgb(SpectrumType t, SigmoidPolynomial p, Float scale,
                                             DenselySampled illuminant) {
    Spectrum s;
    s.type = t;
    s.rgb = {p, scale, illuminant};
    return s;
  }
};

/// CIE 1931 CMFs at `lambda` by linear interpolation of the 1 nm tables (0 outside).
KAURI_HOST_DEVICE inline Vec3 cie_xyz_bar(Float lambda) {
  Float t = lambda - tables::kCieLambdaMin;
  if (!(t >= 0) || t > Float(tables::kCieSamples - 1)) return {};
  int i = t >= Float(tables::kCieSamples - 1) ? tables::kCieSamples - 2 : int(t);
  Float f = t - Float(i);
  return {lerp(f, tables::kCieX[i], tables::kCieX[i + 1]), lerp(f, tables::kCieY[i], tables::kCieY[i + 1]),
          lerp(f, tables::kCieZ[i], tables::kCieZ[i + 1])};
}

/// The Monte Carlo weights of XYZ at a path's wavelengths,
///   c_i = (x̄, ȳ, z̄)(λ_i) / (p(λ_i) · N · ∫ȳ)   (0 where p = 0),
/// so that XYZ(L) = Σ_i c_i L(λ_i): one table lookup per wavelength serves every
/// spectrum a sample adds to the film (beauty, its direct part, the albedo AOV).
struct SampledXYZWeights {
  Vec3 c[kSpectrumSamples];

  KAURI_HOST_DEVICE explicit SampledXYZWeights(const SampledWavelengths& w) {
    const Float norm = 1 / (Float(kSpectrumSamples) * tables::kCieYIntegral);
    for (int i = 0; i < kSpectrumSamples; ++i)
      c[i] = w.pdf[i] == 0 ? Vec3{} : cie_xyz_bar(w.lambda[i]) * (norm / w.pdf[i]);
  }
  KAURI_HOST_DEVICE Vec3 operator()(const SampledSpectrum& L) const {
    Vec3 xyz;
    for (int i = 0; i < kSpectrumSamples; ++i) xyz += c[i] * L[i];
    return xyz;
  }
};

/// Film's per-sample XYZ: the Monte Carlo estimate of X = int xbar L dl / CIE_Y_integral
/// (and Y, Z) from the path's wavelengths, (1/N) sum_i xbar(l_i) L_i / p_i; samples with
/// pdf 0 (terminated secondaries) contribute nothing.
KAURI_HOST_DEVICE inline Vec3 sampled_to_xyz(const SampledSpectrum& L, const SampledWavelengths& w) {
  return SampledXYZWeights(w)(L);
}

// ---- host helpers (spectrum.cpp) ----

/// XYZ of a spectrum by summing against the 1 nm CMF table, / CIE_Y_integral
/// (so a constant 1 has Y = 1). Host only: 471 evaluations.
Vec3 spectrum_to_xyz(const Spectrum& s);
Float spectrum_to_y(const Spectrum& s);
/// ∫ (x̄, ȳ, z̄)(λ) s(λ) dλ / CIE_Y_integral over [360, 830] nm with the CMFs interpolated
/// between their 1 nm knots as cie_xyz_bar() does: the expected value of the film's
/// estimate SampledXYZWeights(w)(s at w) under any wavelength density that is positive
/// where the CMFs are. Three-point Gauss–Legendre on each 1 nm interval (exact for the
/// linear CMFs times a quadratic s; the spectra here are smooth on that scale). Host only.
Vec3 spectrum_to_xyz_expected(const Spectrum& s);
/// Largest value over [360, 830] nm (exact for RGB kinds without illuminant and blackbody,
/// sampled at 1 nm otherwise).
Float spectrum_max_value(const Spectrum& s);
/// DenselySampled views of a metal's IOR tables.
DenselySampled metal_eta(const tables::MetalIOR& m);
DenselySampled metal_k(const tables::MetalIOR& m);

}  // namespace kauri
