// Diffuse (Lambertian) transmission: light that crosses a thin, strongly
// scattering sheet (paper, leaves, lampshades) leaves in a cosine distribution
// on the far side.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

struct DiffuseTransmissionLobe {
  static constexpr const char* kName = "diffuse_transmission@1";
  static constexpr LobeClass kClass = LobeClass::BTDF;
  static constexpr Scattering kScattering = Scattering::Diffuse;

  SampledSpectrum transmittance;  // τ ∈ [0,1] per wavelength: the fraction transmitted

  /// τ: the diffuse transmittance per wavelength (clamped to [0,1]).
  KAURI_HOST_DEVICE static DiffuseTransmissionLobe make(const SampledSpectrum& tau) {
    DiffuseTransmissionLobe l;
    for (int i = 0; i < kSpectrumSamples; ++i) l.transmittance[i] = clamp(tau[i], 0, 1);
    return l;
  }

  // f(ω_o, ω_i) = τ/π for ω_i on the opposite side of ω_o, so that
  // ∫ f |cosθ_i| dω_i = τ. It is symmetric in its arguments (reciprocal), and
  // the sheet is assumed index-matched on both sides: no 1/η² radiance scaling.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode) const {
    if (!(wo.z * wi.z < 0)) return SampledSpectrum(0);
    return transmittance * kInvPi;
  }
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    return wo.z * wi.z < 0 ? cosine_hemisphere_pdf(abs_cos_theta(wi)) : 0;
  }
  /// Cosine-weighted sampling (Malley's method) of the hemisphere opposite ω_o.
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float, Vec2 u, SampledWavelengths&, TransportMode) const {
    BSDFSample s;
    if (wo.z == 0) return s;
    s.wi = sample_cosine_hemisphere(u);
    if (wo.z > 0) s.wi.z = -s.wi.z;
    if (s.wi.z == 0) return s;
    s.pdf = cosine_hemisphere_pdf(abs_cos_theta(s.wi));
    s.f = transmittance * kInvPi;
    s.scattering = Scattering::Diffuse;
    s.transmission = true;
    s.eta = 1;
    return s;
  }

  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3) const { return SampledSpectrum(0); }
  /// Exact: ∫ τ/π |cosθ_i| dω_i over a hemisphere = τ.
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3) const { return transmittance; }
  /// No refraction happens: 0 tells IOR accumulation to skip it.
  KAURI_HOST_DEVICE Float ior(int) const { return 0; }
  KAURI_HOST_DEVICE Float roughness() const { return 1; }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return {0, 0, wo.z < 0 ? Float(1) : Float(-1)}; }
};

}  // namespace kauri
