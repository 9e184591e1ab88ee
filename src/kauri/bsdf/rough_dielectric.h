// Rough dielectric interface (frosted glass, rough water): GGX microfacet
// reflection and refraction after Walter, Marschner, Li & Torrance 2007,
// "Microfacet Models for Refraction through Rough Surfaces" (EGSR), with
// visible-normal sampling (Heitz 2018) and a wavelength-dependent IOR.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/dielectric.h"
#include "kauri/bsdf/fresnel.h"
#include "kauri/bsdf/microfacet.h"

namespace kauri {

struct RoughDielectricLobe {
  static constexpr const char* kName = "ggx_dielectric@1";
  static constexpr LobeClass kClass = LobeClass::BSDF;

  GGXDistribution mf;
  SampledSpectrum eta;  // η_inside / η_outside at the path's wavelengths (inside: z < 0)

  /// eta: η_inside/η_outside per wavelength (the side z < 0 is the inside);
  /// alpha_x, alpha_y: GGX α along the shading frame's x and y (α = roughness²).
  /// η within 1e-3 of 1 is moved to 1 ± 1e-3: at η = 1 every microfacet refracts
  /// straight through, the transmission becomes a delta and Walter's generalized
  /// half-vector is undefined.
  KAURI_HOST_DEVICE static RoughDielectricLobe make(const SampledSpectrum& eta, Float alpha_x, Float alpha_y) {
    RoughDielectricLobe l;
    l.mf.alpha_x = alpha_x;
    l.mf.alpha_y = alpha_y;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      Float e = eta[i];
      if (std::fabs(e - 1) < 1e-3f) e = e < 1 ? Float(1 - 1e-3f) : Float(1 + 1e-3f);
      l.eta[i] = e;
    }
    return l;
  }

  KAURI_HOST_DEVICE Scattering scattering() const {
    return mf.effectively_smooth() ? Scattering::Specular : Scattering::Glossy;
  }
  /// Refraction directions depend on wavelength when η does.
  KAURI_HOST_DEVICE bool dispersive() const {
    for (int i = 1; i < kSpectrumSamples; ++i)
      if (eta[i] != eta[0]) return true;
    return false;
  }

  /// f(ω_o, ω_i). ω_o may lie on either side: the lobe is evaluated with both
  /// directions mirrored so that ω_o is up, and η replaced by the IOR of ω_i's
  /// side relative to ω_o's. Each wavelength uses its own η (its own generalized
  /// half-vector), so the value is correct for all four even with dispersion.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode mode) const {
    if (mf.effectively_smooth() || wo.z == 0 || wi.z == 0) return SampledSpectrum(0);
    const bool outside = wo.z > 0;
    if (!outside) { wo = -wo; wi = -wi; }
    if (!dispersive()) return SampledSpectrum(eval_up(wo, wi, relative_eta(eta[0], outside), mode));
    SampledSpectrum f;
    for (int i = 0; i < kSpectrumSamples; ++i) f[i] = eval_up(wo, wi, relative_eta(eta[i], outside), mode);
    return f;
  }

  /// Density of sample(): the VNDF density of ω_m times the probability of the
  /// reflect/refract choice (F or 1 − F of the hero wavelength) times the Jacobian
  /// of the map ω_m → ω_i: 1/(4|ω_o·ω_m|) for reflection (Walter eq. 14) and
  /// η²|ω_i·ω_m| / (ω_o·ω_m + η ω_i·ω_m)² for refraction (Walter eq. 17).
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    if (mf.effectively_smooth() || wo.z == 0 || wi.z == 0) return 0;
    const bool outside = wo.z > 0;
    if (!outside) { wo = -wo; wi = -wi; }
    const Float e = relative_eta(eta[0], outside);
    Vec3 wm;
    if (!half_vector(wo, wi, e, &wm)) return 0;
    const Float dot_o = dot(wo, wm), dot_i = dot(wi, wm);
    const Float F = fresnel_dielectric(dot_o, e);
    if (wi.z > 0) return mf.D_visible(wo, wm) / (4 * dot_o) * F;
    return mf.D_visible(wo, wm) * (1 - F) * e * e * std::fabs(dot_i) / sqr(dot_o + e * dot_i);
  }

  /// Samples ω_m from the visible normals of ω_o, then reflects with probability
  /// F(ω_o·ω_m) (hero wavelength) and refracts through ω_m otherwise. With
  /// dispersion only the hero's refracted direction is followed, so secondary
  /// wavelengths are terminated (Wilkie et al. 2014, §4), as in SmoothDielectricLobe.
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float uc, Vec2 u, SampledWavelengths& lambda,
                                      TransportMode mode) const {
    const bool disp = dispersive();
    if (mf.effectively_smooth()) {
      SmoothDielectricLobe smooth;
      smooth.eta = eta;
      smooth.dispersive = disp;
      return smooth.sample(wo, uc, u, lambda, mode);
    }
    BSDFSample s;
    if (wo.z == 0) return s;
    if (disp) lambda.terminate_secondary();
    const bool outside = wo.z > 0;
    const Vec3 wo_up = outside ? wo : -wo;
    const Float e = relative_eta(eta[0], outside);
    const Vec3 wm = mf.sample_visible_normal(wo_up, u);
    const Float dot_o = dot(wo_up, wm);
    if (!(dot_o > 0)) return s;
    const Float F = fresnel_dielectric(dot_o, e);
    Vec3 wi_up;
    const bool reflect_it = uc < F;
    if (reflect_it) {
      wi_up = reflect(wo_up, wm);
      if (wi_up.z <= 0) return s;  // reflected below the macrosurface: no sample
    } else {
      if (!refract(wo_up, wm, e, &wi_up) || wi_up.z >= 0) return s;
    }
    s.wi = outside ? wi_up : -wi_up;
    // Value and density from eval()/pdf() so the three always agree exactly
    // (the half-vector recomputed from (ω_o, ω_i) is ω_m up to rounding).
    s.pdf = pdf(wo, s.wi);
    if (!(s.pdf > 0)) return BSDFSample{};
    s.f = eval(wo, s.wi, mode);
    s.scattering = Scattering::Glossy;
    s.transmission = !reflect_it;
    s.eta = reflect_it ? Float(1) : e;
    return s;
  }

  /// Approximation used for lobe selection and layering: the smooth interface's
  /// Fresnel split at θ_o, F(cosθ_o) and 1 − F(cosθ_o). It ignores the spread of
  /// microfacet angles and the single-scattering masking loss (a few % at α ≤ 0.5,
  /// more at grazing angles and high α); a tabulated albedo would replace it.
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    SampledSpectrum r;
    for (int i = 0; i < kSpectrumSamples; ++i) r[i] = fresnel_dielectric(cos_theta(wo), eta[i]);
    return r;
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3 wo) const { return SampledSpectrum(1) - albedo_r(wo); }
  KAURI_HOST_DEVICE Float ior(int i) const { return eta[i]; }
  KAURI_HOST_DEVICE Float roughness() const { return std::sqrt(std::sqrt(mf.alpha_x * mf.alpha_y)); }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return reflect_z(wo); }

  /// IOR of the far side relative to ω_o's side.
  KAURI_HOST_DEVICE static Float relative_eta(Float eta_in_out, bool wo_outside) {
    return wo_outside ? eta_in_out : 1 / eta_in_out;
  }

  /// Microfacet normal (z > 0) that maps ω_o (z > 0) to ω_i, for relative IOR e.
  /// Reflection: ω_m ∝ ω_o + ω_i (Walter eq. 13). Refraction: the generalized
  /// half-vector ω_m ∝ −(ω_o + e ω_i) (Walter eq. 16), turned to the upper side; it
  /// must see ω_o from its front and ω_i from its back (Walter eq. 21's χ⁺ terms).
  KAURI_HOST_DEVICE static bool half_vector(Vec3 wo, Vec3 wi, Float e, Vec3* wm) {
    const bool refl = wi.z > 0;
    Vec3 h = refl ? wo + wi : wo + wi * e;
    const Float l2 = length_squared(h);
    if (!(l2 > 0)) return false;
    h = h / std::sqrt(l2);
    if (h.z < 0) h = -h;
    if (h.z == 0) return false;
    const Float dot_o = dot(wo, h), dot_i = dot(wi, h);
    if (!(dot_o > 0)) return false;
    if (refl ? !(dot_i > 0) : !(dot_i < 0)) return false;
    *wm = h;
    return true;
  }

  /// f for ω_o up (z > 0) and relative IOR e of ω_i's side.
  /// Reflection (Walter eq. 20): D G F / (4 |cosθ_o cosθ_i|).
  /// Refraction (Walter eq. 21, with η_o → 1, η_i → e):
  ///   |ω_i·ω_m| |ω_o·ω_m| e² (1 − F) G D / (|cosθ_o cosθ_i| (ω_o·ω_m + e ω_i·ω_m)²),
  /// which conserves importance; radiance is additionally divided by e² (Veach
  /// 1997, §5.2), so f_imp(ω_o, ω_i)/η_i² = f_imp(ω_i, ω_o)/η_o² (generalized reciprocity).
  /// G is the height-correlated Smith term 1/(1 + Λ(ω_o) + Λ(ω_i)) (Heitz 2014,
  /// eq. 99) for both; for refraction this is the usual approximation of the exact
  /// height-correlated form, and it never exceeds G1(ω_o), which bounds the albedo by 1.
  KAURI_HOST_DEVICE Float eval_up(Vec3 wo, Vec3 wi, Float e, TransportMode mode) const {
    Vec3 wm;
    if (!half_vector(wo, wi, e, &wm)) return 0;
    const Float dot_o = dot(wo, wm), dot_i = dot(wi, wm);
    const Float F = fresnel_dielectric(dot_o, e);
    const Float DG = mf.D(wm) * mf.G(wo, wi);
    if (wi.z > 0) return DG * F / (4 * wo.z * wi.z);
    Float ft = DG * (1 - F) * dot_o * std::fabs(dot_i) / (wo.z * std::fabs(wi.z) * sqr(dot_o + e * dot_i));
    if (mode == TransportMode::Importance) ft *= e * e;
    return ft;
  }
};

}  // namespace kauri
