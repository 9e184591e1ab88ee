// Smooth dielectric interface (glass, water): specular reflection and refraction
// with a wavelength-dependent IOR.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/fresnel.h"

namespace kauri {

/// Cauchy's equation n(λ) = A + B/λ² fitted to an IOR n_d at 587.56 nm and an Abbe
/// number V_d = (n_d − 1)/(n_F − n_C) (F: 486.13 nm, C: 656.27 nm). V_d = 0 → no dispersion.
struct CauchyIOR {
  Float A = 1.5f, B = 0;
  KAURI_HOST_DEVICE static CauchyIOR from_abbe(Float n_d, Float abbe) {
    CauchyIOR c;
    if (abbe <= 0) {
      c.A = n_d;
      c.B = 0;
      return c;
    }
    const Float inv_f2 = 1 / sqr(486.13f), inv_c2 = 1 / sqr(656.27f), inv_d2 = 1 / sqr(587.56f);
    c.B = (n_d - 1) / (abbe * (inv_f2 - inv_c2));
    c.A = n_d - c.B * inv_d2;
    return c;
  }
  KAURI_HOST_DEVICE Float operator()(Float lambda) const { return A + B / (lambda * lambda); }
  KAURI_HOST_DEVICE bool dispersive() const { return B != 0; }
};

struct SmoothDielectricLobe {
  static constexpr const char* kName = "smooth_dielectric@1";
  static constexpr LobeClass kClass = LobeClass::BSDF;
  static constexpr Scattering kScattering = Scattering::Specular;

  SampledSpectrum eta;  // η_inside / η_outside at the path's wavelengths
  bool dispersive = false;

  // Delta lobe: eval and pdf are zero for any pair of directions.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3, Vec3, TransportMode) const { return SampledSpectrum(0); }
  KAURI_HOST_DEVICE Float pdf(Vec3, Vec3) const { return 0; }

  /// Chooses reflection with probability F, else refraction. With dispersion the
  /// refracted direction exists for the hero wavelength only, so the secondary
  /// wavelengths are terminated (hero wavelength sampling, Wilkie et al. 2014, §4).
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float uc, Vec2, SampledWavelengths& lambda,
                                      TransportMode mode) const {
    if (dispersive) lambda.terminate_secondary();
    const Float e = eta[0];
    BSDFSample s;
    s.scattering = Scattering::Specular;
    Float F = fresnel_dielectric(cos_theta(wo), e);
    Vec3 wt;
    Float e_rel = 1;
    if (uc < F || !refract(wo, Vec3{0, 0, 1}, e, &wt, &e_rel)) {
      s.wi = reflect_z(wo);
      Float p = (uc < F) ? F : 1;
      s.pdf = p;
      s.f = SampledSpectrum(p / abs_cos_theta(s.wi));
      if (!dispersive) {  // every wavelength sees its own Fresnel term
        for (int i = 0; i < kSpectrumSamples; ++i)
          s.f[i] = fresnel_dielectric(cos_theta(wo), eta[i]) / abs_cos_theta(s.wi);
      }
      return s;
    }
    s.wi = wt;
    s.pdf = 1 - F;
    s.transmission = true;
    s.eta = e_rel;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      Float ei = dispersive ? e : eta[i];
      Float Ti = 1 - fresnel_dielectric(cos_theta(wo), ei);
      Float erel = cos_theta(wo) > 0 ? ei : 1 / ei;
      // Radiance is compressed into the smaller solid angle: scale by 1/η² (Veach §5.2).
      if (mode == TransportMode::Radiance) Ti /= sqr(erel);
      s.f[i] = Ti / abs_cos_theta(s.wi);
    }
    return s;
  }

  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    SampledSpectrum r;
    for (int i = 0; i < kSpectrumSamples; ++i) r[i] = fresnel_dielectric(cos_theta(wo), eta[i]);
    return r;
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3 wo) const { return SampledSpectrum(1) - albedo_r(wo); }
  KAURI_HOST_DEVICE Float ior(int i) const { return eta[i]; }
  KAURI_HOST_DEVICE Float roughness() const { return 0; }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return reflect_z(wo); }
};

}  // namespace kauri
