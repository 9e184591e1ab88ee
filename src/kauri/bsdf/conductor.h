// Rough conductor: GGX microfacet reflection with a spectral complex IOR.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/fresnel.h"
#include "kauri/bsdf/microfacet.h"

namespace kauri {

struct GGXConductorLobe {
  static constexpr const char* kName = "ggx_conductor@1";
  static constexpr LobeClass kClass = LobeClass::BRDF;

  GGXDistribution mf;
  SampledSpectrum eta, k;  // complex IOR η + iκ relative to the outside

  KAURI_HOST_DEVICE Scattering scattering() const {
    return mf.effectively_smooth() ? Scattering::Specular : Scattering::Glossy;
  }

  /// Torrance–Sparrow: f = D(ω_m) G(ω_o, ω_i) F(ω_o·ω_m) / (4 cosθ_o cosθ_i).
  /// The lobe is mirrored to the side of ω_o (two-sided shading).
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode) const {
    if (!same_hemisphere(wo, wi) || mf.effectively_smooth()) return SampledSpectrum(0);
    if (wo.z < 0) { wo = -wo; wi = -wi; }
    Float co = wo.z, ci = wi.z;
    if (co == 0 || ci == 0) return SampledSpectrum(0);
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return SampledSpectrum(0);
    wm = normalize(wm);
    SampledSpectrum F = fresnel_conductor(absdot(wo, wm), eta, k);
    return F * (mf.D(wm) * mf.G(wo, wi) / (4 * co * ci));
  }
  /// VNDF density transformed by the reflection Jacobian 1/(4 |ω_o·ω_m|).
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    if (!same_hemisphere(wo, wi) || mf.effectively_smooth()) return 0;
    if (wo.z < 0) { wo = -wo; wi = -wi; }
    Vec3 wm = wo + wi;
    if (length_squared(wm) == 0) return 0;
    wm = normalize(wm);
    return mf.D_visible(wo, wm) / (4 * absdot(wo, wm));
  }
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float, Vec2 u, SampledWavelengths&, TransportMode mode) const {
    BSDFSample s;
    Float flip = wo.z < 0 ? Float(-1) : Float(1);
    Vec3 wo_up = wo * flip;
    if (mf.effectively_smooth()) {
      s.wi = reflect_z(wo);
      s.pdf = 1;
      s.scattering = Scattering::Specular;
      s.f = fresnel_conductor(abs_cos_theta(wo), eta, k) / abs_cos_theta(s.wi);
      return s;
    }
    if (wo_up.z == 0) return s;
    Vec3 wm = mf.sample_visible_normal(wo_up, u);
    Vec3 wi_up = reflect(wo_up, wm);
    if (wi_up.z <= 0) return s;  // reflected below the surface: no sample
    s.wi = wi_up * flip;
    s.pdf = mf.D_visible(wo_up, wm) / (4 * absdot(wo_up, wm));
    s.f = eval(wo, s.wi, mode);
    s.scattering = Scattering::Glossy;
    return s;
  }

  /// Directional albedo estimate F(θ_o) for lobe selection. It ignores the
  /// masking loss of rough surfaces; the layered-material issue replaces it with
  /// tabulated albedos.
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    return fresnel_conductor(abs_cos_theta(wo), eta, k);
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3) const { return SampledSpectrum(0); }
  KAURI_HOST_DEVICE Float ior(int i) const { return eta[i]; }
  KAURI_HOST_DEVICE Float roughness() const { return std::sqrt(std::sqrt(mf.alpha_x * mf.alpha_y)); }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return reflect_z(wo); }
};

}  // namespace kauri
