// Thin dielectric sheet (window pane, soap film without interference): two
// parallel smooth interfaces so close that the light leaves where it entered.
// Light is reflected or passes straight through, after any number of internal
// bounces summed incoherently.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/fresnel.h"

namespace kauri {

struct ThinDielectricLobe {
  static constexpr const char* kName = "thin_dielectric@1";
  static constexpr LobeClass kClass = LobeClass::BSDF;
  static constexpr Scattering kScattering = Scattering::Specular;

  SampledSpectrum eta;  // IOR of the sheet relative to the surrounding medium

  /// eta: the sheet's IOR relative to the medium on both sides, per wavelength.
  KAURI_HOST_DEVICE static ThinDielectricLobe make(const SampledSpectrum& eta) {
    ThinDielectricLobe l;
    l.eta = eta;
    return l;
  }

  /// Reflectance of the sheet: with R the single-interface Fresnel reflectance
  /// (the same at both faces: the inner angle is the refracted one and Fresnel
  /// is symmetric) and T = 1 − R, the geometric series of internal bounces gives
  ///   R' = R + T² R Σ_k R^(2k) = R + T² R / (1 − R²)
  /// (e.g. Pharr, Jakob & Humphreys, PBR 4th ed., §9.5.1 derive the same series),
  /// which without absorption simplifies to 2R / (1 + R). R = 1 (grazing) gives R' = 1.
  KAURI_HOST_DEVICE static Float sheet_reflectance(Float cos_o, Float e) {
    Float R = fresnel_dielectric(std::fabs(cos_o), e);
    if (R >= 1) return 1;
    Float T = 1 - R;
    return fmin_(R + T * T * R / (1 - R * R), 1);
  }
  KAURI_HOST_DEVICE SampledSpectrum reflectance(Vec3 wo) const {
    SampledSpectrum r;
    for (int i = 0; i < kSpectrumSamples; ++i) r[i] = sheet_reflectance(cos_theta(wo), eta[i]);
    return r;
  }

  // Delta lobe: eval and pdf are zero for any pair of directions.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3, Vec3, TransportMode) const { return SampledSpectrum(0); }
  KAURI_HOST_DEVICE Float pdf(Vec3, Vec3) const { return 0; }

  /// Mirror reflection with probability P = mean over wavelengths of R', else
  /// straight transmission ω_i = −ω_o (the two refractions cancel, and the light
  /// ends in the medium it came from: no 1/η² scaling in either transport mode).
  /// Directions do not depend on λ, so no wavelength is terminated.
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float uc, Vec2, SampledWavelengths&, TransportMode) const {
    BSDFSample s;
    if (wo.z == 0) return s;
    const SampledSpectrum R = reflectance(wo);
    const Float P = R.average();
    const Float inv_cos = 1 / abs_cos_theta(wo);
    s.scattering = Scattering::Specular;
    if (uc < P) {
      s.wi = reflect_z(wo);
      s.pdf = P;
      s.f = R * inv_cos;
    } else {
      s.wi = -wo;
      s.pdf = 1 - P;
      s.f = (SampledSpectrum(1) - R) * inv_cos;
      s.transmission = true;
      s.eta = 1;
    }
    if (!(s.pdf > 0)) return BSDFSample{};
    return s;
  }

  /// Exact: R' and T' = 1 − R'.
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const { return reflectance(wo); }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3 wo) const { return SampledSpectrum(1) - reflectance(wo); }
  /// A thin sheet leaves the light in the medium it came from: what lies behind it
  /// sees no change of IOR, so 0 tells IOR accumulation to skip it.
  KAURI_HOST_DEVICE Float ior(int) const { return 0; }
  KAURI_HOST_DEVICE Float roughness() const { return 0; }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return reflect_z(wo); }
};

}  // namespace kauri
