// Lambertian reflection, the reference diffuse lobe.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

struct LambertLobe {
  static constexpr const char* kName = "lambert@1";
  static constexpr LobeClass kClass = LobeClass::BRDF;
  static constexpr Scattering kScattering = Scattering::Diffuse;

  SampledSpectrum albedo;  // ρ ∈ [0,1] per wavelength

  // Directions are in the local shading frame. The lobe reflects on the side of
  // ω_o, so it is two-sided; single-sided stacks are the layer system's job.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode) const {
    if (!same_hemisphere(wo, wi)) return SampledSpectrum(0);
    return albedo * kInvPi;
  }
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf(abs_cos_theta(wi)) : 0;
  }
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float, Vec2 u, SampledWavelengths&, TransportMode) const {
    BSDFSample s;
    s.wi = sample_cosine_hemisphere(u);
    if (wo.z < 0) s.wi.z = -s.wi.z;
    s.pdf = cosine_hemisphere_pdf(abs_cos_theta(s.wi));
    s.f = albedo * kInvPi;
    s.scattering = Scattering::Diffuse;
    return s;
  }

  // Queries used by the layer system.
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3) const { return albedo; }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3) const { return SampledSpectrum(0); }
  /// Lambert has no notion of IOR: 0 tells IOR accumulation to skip it (notes §8.4.3).
  KAURI_HOST_DEVICE Float ior(int) const { return 0; }
  KAURI_HOST_DEVICE Float roughness() const { return 1; }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return {0, 0, wo.z < 0 ? Float(-1) : Float(1)}; }
};

}  // namespace kauri
