// Rough dielectric interface (frosted glass, rough water): GGX microfacet
// reflection and refraction after Walter, Marschner, Li & Torrance 2007,
// "Microfacet Models for Refraction through Rough Surfaces" (EGSR), with
// visible-normal sampling (Heitz 2018) and a wavelength-dependent IOR, plus
// Kulla–Conty multiple-scattering energy compensation (compensate = true).
//
// Compensation (derived here; /work/shared/refs/layering.md §2). Let E_s(μ) be the
// single-scattering albedo (R + T, importance transport) for ω_o on side s and
// E_s,avg = 2∫E_s(μ)μdμ (tables: dielectric_albedo_tables.h, keyed by the far side's
// relative IOR). For ω_o on side a, the other side b:
//   f_ms,R(ω_o, ω_i) = (1 − t_a) (1 − E_a(μ_o)) (1 − E_a(μ_i)) / (π (1 − E_a,avg))   ω_i on a
//   f_ms,T(ω_o, ω_i) =      t_a  (1 − E_a(μ_o)) (1 − E_b(μ_i)) / (π (1 − E_b,avg))   ω_i on b
// (importance transport; radiance divides f_ms,T by e², e = η_b/η_a, as for f_ss).
// ∫ f_ms,R μ_i dω_i = (1 − t_a)(1 − E_a(μ_o)) and ∫ f_ms,T μ_i dω_i = t_a (1 − E_a(μ_o)),
// so E_a(μ_o) + E_ms = 1 for every μ_o and any share t_a ∈ [0,1]. f_ms,R is symmetric.
// Generalized reciprocity f(ω_o, ω_i)/η_i² = f(ω_i, ω_o)/η_o² for f_ms,T requires
//   t_a (1 − E_a,avg) = (η_b/η_a)² t_b (1 − E_b,avg),
// the η² relation between the two sides' averages. We pick, for the side X whose far
// side is denser (e_X = η_Y/η_X > 1), t_X = E_T,X,avg / E_X,avg (the single-scattering
// transmitted fraction) and t_Y = t_X (1 − E_X,avg)/(e_X² (1 − E_Y,avg)); if that
// exceeds 1, t_Y = 1 and t_X = e_X² (1 − E_Y,avg)/(1 − E_X,avg). Both are then exactly
// reciprocal and energy-conserving (up to the tables' accuracy, ≲ 0.6%). Approximations:
// the angular shape of f_ms is Kelemen/Kulla–Conty's separable one, not the true
// multiple-scattering distribution; the T/R split is a constant per (r, η) rather than
// a function of μ_o; anisotropic α uses the isotropic r = (α_x α_y)^{1/4}.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/dielectric.h"
#include "kauri/bsdf/dielectric_albedo_tables.h"
#include "kauri/bsdf/fresnel.h"
#include "kauri/bsdf/microfacet.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

struct RoughDielectricLobe {
  /// Versioned names: "@2" with energy compensation (the default), "@1" = the plain
  /// single-scattering lobe (compensate = false). Use name(); kName is the default's.
  static constexpr const char* kName = "ggx_dielectric@2";
  static constexpr const char* kNameUncompensated = "ggx_dielectric@1";
  static constexpr LobeClass kClass = LobeClass::BSDF;

  GGXDistribution mf;
  SampledSpectrum eta;  // η_inside / η_outside at the path's wavelengths (inside: z < 0)
  bool compensate = true;  // Kulla–Conty multiple-scattering terms (see the top of this file)

  /// eta: η_inside/η_outside per wavelength (the side z < 0 is the inside);
  /// alpha_x, alpha_y: GGX α along the shading frame's x and y (α = roughness²).
  /// η within 1e-3 of 1 is moved to 1 ± 1e-3: at η = 1 every microfacet refracts
  /// straight through, the transmission becomes a delta and Walter's generalized
  /// half-vector is undefined.
  KAURI_HOST_DEVICE static RoughDielectricLobe make(const SampledSpectrum& eta, Float alpha_x, Float alpha_y,
                                                    bool compensate = true) {
    RoughDielectricLobe l;
    l.compensate = compensate;
    l.mf.alpha_x = alpha_x;
    l.mf.alpha_y = alpha_y;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      Float e = eta[i];
      if (std::fabs(e - 1) < 1e-3f) e = e < 1 ? Float(1 - 1e-3f) : Float(1 + 1e-3f);
      l.eta[i] = e;
    }
    return l;
  }

  KAURI_HOST_DEVICE const char* name() const { return compensate ? kName : kNameUncompensated; }
  KAURI_HOST_DEVICE bool compensated() const { return compensate && !mf.effectively_smooth(); }
  KAURI_HOST_DEVICE Float table_roughness() const { return mf.perceptual_roughness(); }

  /// Compensation quantities for ω_o on the side given by `outside`, for one wavelength's
  /// η (inside/outside): far-side relative IOR e, transmitted share t_o (see the top).
  struct MS {
    DielAlbedoKey key_o, key_i;  // table keys of ω_o's side and of the far side
    Float e, t_o, ea_o, ea_i;    // e = η_far/η_o; E_avg of both sides
  };
  KAURI_HOST_DEVICE MS ms_terms(Float eta_io, bool outside) const {
    MS m;
    const Float r = table_roughness();
    m.e = relative_eta(eta_io, outside);
    m.key_o = diel_albedo_key(r, m.e);
    m.key_i = diel_albedo_key(r, 1 / m.e);
    m.ea_o = diel_albedo_avg(kGGXDielectricAlbedoAvg, m.key_o);
    m.ea_i = diel_albedo_avg(kGGXDielectricAlbedoAvg, m.key_i);
    // Side X: the one whose far side is denser (table side 0). Computed identically from
    // both sides so that the reciprocity relation holds to rounding.
    const bool o_is_x = m.key_o.side == 0;
    const DielAlbedoKey& kx = o_is_x ? m.key_o : m.key_i;
    const Float eax = o_is_x ? m.ea_o : m.ea_i, eay = o_is_x ? m.ea_i : m.ea_o;
    const Float ex = o_is_x ? m.e : 1 / m.e;
    const Float mx = fmax_(1 - eax, 1e-7f), my = fmax_(1 - eay, 1e-7f);
    Float tx = clamp(diel_albedo_avg(kGGXDielectricAlbedoTAvg, kx) / fmax_(eax, 1e-7f), 0, 1);
    Float ty = tx * mx / (ex * ex * my);
    if (ty > 1) {
      ty = 1;
      tx = ex * ex * my / mx;
    }
    m.t_o = o_is_x ? tx : ty;
    return m;
  }
  /// f_ms for ω_o up (z > 0), ω_i on either side, one wavelength.
  KAURI_HOST_DEVICE Float eval_ms_up(Vec3 wo, Vec3 wi, Float eta_io, bool outside, TransportMode mode) const {
    const MS m = ms_terms(eta_io, outside);
    const Float lo = fmax_(1 - diel_albedo(kGGXDielectricAlbedo, m.key_o, wo.z), 0);
    if (wi.z > 0) {
      if (!(m.ea_o < 1)) return 0;
      const Float li = fmax_(1 - diel_albedo(kGGXDielectricAlbedo, m.key_o, wi.z), 0);
      return (1 - m.t_o) * lo * li / (kPi * (1 - m.ea_o));
    }
    if (!(m.ea_i < 1)) return 0;
    const Float li = fmax_(1 - diel_albedo(kGGXDielectricAlbedo, m.key_i, -wi.z), 0);
    Float ft = m.t_o * lo * li / (kPi * (1 - m.ea_i));
    if (mode == TransportMode::Radiance) ft /= m.e * m.e;
    return ft;
  }
  /// Probability of the compensation (cosine) strategy, 1 − E(μ_o) of the hero, and the
  /// share t_o of its samples sent to the far hemisphere.
  KAURI_HOST_DEVICE void ms_sampling(Float mu_o, bool outside, Float* p_ms, Float* t_o) const {
    *p_ms = 0;
    *t_o = 0;
    if (!compensated()) return;
    const MS m = ms_terms(eta[0], outside);
    *p_ms = clamp(1 - diel_albedo(kGGXDielectricAlbedo, m.key_o, mu_o), 0, 0.99f);
    *t_o = m.t_o;
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
    const bool ms = compensated();
    auto one = [&](Float eta_io) {
      Float v = eval_up(wo, wi, relative_eta(eta_io, outside), mode);
      if (ms) v += eval_ms_up(wo, wi, eta_io, outside, mode);
      return v;
    };
    if (!dispersive()) return SampledSpectrum(one(eta[0]));
    SampledSpectrum f;
    for (int i = 0; i < kSpectrumSamples; ++i) f[i] = one(eta[i]);
    return f;
  }

  /// Density of sample(): the VNDF density of ω_m times the probability of the
  /// reflect/refract choice (F or 1 − F of the hero wavelength) times the Jacobian
  /// of the map ω_m → ω_i: 1/(4|ω_o·ω_m|) for reflection (Walter eq. 14) and
  /// η²|ω_i·ω_m| / (ω_o·ω_m + η ω_i·ω_m)² for refraction (Walter eq. 17).
  /// With compensation: the one-sample mixture (1 − P_ms) · that + P_ms · cosine density
  /// on the hemisphere of ω_i, weighted by 1 − t_o (reflection) or t_o (transmission).
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    if (mf.effectively_smooth() || wo.z == 0 || wi.z == 0) return 0;
    const bool outside = wo.z > 0;
    if (!outside) { wo = -wo; wi = -wi; }
    return with_ms_pdf(pdf_ss_up(wo, wi, relative_eta(eta[0], outside)), wo, wi, outside);
  }
  /// The one-sample mixture with the compensation strategy (ω_o up), from the
  /// single-scattering density `p_ss`; `p_ss` itself when uncompensated.
  KAURI_HOST_DEVICE Float with_ms_pdf(Float p_ss, Vec3 wo, Vec3 wi, bool outside) const {
    if (!compensated()) return p_ss;
    Float pms, t;
    ms_sampling(wo.z, outside, &pms, &t);
    return (1 - pms) * p_ss + pms * (wi.z > 0 ? 1 - t : t) * std::fabs(wi.z) * kInvPi;
  }
  /// Density of the single-scattering strategy, ω_o up.
  KAURI_HOST_DEVICE Float pdf_ss_up(Vec3 wo, Vec3 wi, Float e) const {
    Float p;
    ss_up(wo, wi, e, TransportMode::Radiance, &p);
    return p;
  }

  /// eval() and pdf() together (non-dispersive η: one half-vector, Fresnel, D and Λ(ω_o)
  /// serve both); with dispersion, each wavelength has its own half-vector, so the two
  /// are evaluated apart.
  KAURI_HOST_DEVICE SampledSpectrum eval_pdf(Vec3 wo, Vec3 wi, TransportMode mode, Float* pdf_out) const {
    *pdf_out = 0;
    if (mf.effectively_smooth() || wo.z == 0 || wi.z == 0) return SampledSpectrum(0);
    if (dispersive()) {
      *pdf_out = pdf(wo, wi);
      return eval(wo, wi, mode);
    }
    const bool outside = wo.z > 0;
    if (!outside) { wo = -wo; wi = -wi; }
    Float p_ss;
    Float f = ss_up(wo, wi, relative_eta(eta[0], outside), mode, &p_ss);
    if (compensated()) f += eval_ms_up(wo, wi, eta[0], outside, mode);
    *pdf_out = with_ms_pdf(p_ss, wo, wi, outside);
    return SampledSpectrum(f);
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
    Vec3 wi_up;
    Float pms, t;
    ms_sampling(wo_up.z, outside, &pms, &t);
    if (uc < pms) {  // compensation: cosine on the reflection or transmission hemisphere
      wi_up = sample_cosine_hemisphere(u);
      if (uc < pms * t) wi_up.z = -wi_up.z;
      if (wi_up.z == 0) return s;
    } else {
      uc = (uc - pms) / (1 - pms);
      const Vec3 wm = mf.sample_visible_normal(wo_up, u);
      const Float dot_o = dot(wo_up, wm);
      if (!(dot_o > 0)) return s;
      const Float F = fresnel_dielectric(dot_o, e);
      if (uc < F) {
        wi_up = reflect(wo_up, wm);
        if (wi_up.z <= 0) return s;  // reflected below the macrosurface: no sample
      } else {
        if (!refract(wo_up, wm, e, &wi_up) || wi_up.z >= 0) return s;
      }
    }
    const bool reflect_it = wi_up.z > 0;
    s.wi = outside ? wi_up : -wi_up;
    // Value and density as eval()/pdf() give them, so the three always agree exactly
    // (the half-vector recomputed from (ω_o, ω_i) is ω_m up to rounding).
    s.f = eval_pdf(wo, s.wi, mode, &s.pdf);
    if (!(s.pdf > 0)) return BSDFSample{};
    s.scattering = Scattering::Glossy;
    s.transmission = !reflect_it;
    s.eta = reflect_it ? Float(1) : e;
    return s;
  }

  /// Directional albedos (importance transport, which conserves energy) from the tables:
  ///   albedo_r = E(μ_o) − E_T(μ_o) + (1 − t_o)(1 − E(μ_o)),  albedo_t = E_T(μ_o) + t_o (1 − E(μ_o))
  /// (the compensation terms only when compensated; they are exact for f_ms given the
  /// tables). The smooth limit uses the Fresnel split at θ_o. Accuracy ~1–2% against
  /// Monte Carlo (tests/cpp/test_rough_dielectric_energy.cpp), limited by the trilinear
  /// interpolation (the T/R split near the critical angle at small α is the worst case).
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    SampledSpectrum r, t;
    albedo_rt(wo, &r, &t);
    return r;
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3 wo) const {
    SampledSpectrum r, t;
    albedo_rt(wo, &r, &t);
    return t;
  }
  KAURI_HOST_DEVICE void albedo_rt(Vec3 wo, SampledSpectrum* r, SampledSpectrum* t) const {
    const Float mu = std::fabs(cos_theta(wo));
    const bool outside = wo.z >= 0;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      if (mf.effectively_smooth()) {
        (*r)[i] = fresnel_dielectric(cos_theta(wo), eta[i]);
        (*t)[i] = 1 - (*r)[i];
        continue;
      }
      const MS m = ms_terms(eta[i], outside);
      const Float E = diel_albedo(kGGXDielectricAlbedo, m.key_o, mu);
      const Float ET = fmin_(diel_albedo(kGGXDielectricAlbedoT, m.key_o, mu), E);
      Float ar = E - ET, at = ET;
      if (compensate) {
        const Float miss = fmax_(1 - E, 0);
        ar += (1 - m.t_o) * miss;
        at += m.t_o * miss;
      }
      (*r)[i] = ar;
      (*t)[i] = at;
    }
  }
  KAURI_HOST_DEVICE Float ior(int i) const { return eta[i]; }
  KAURI_HOST_DEVICE Float roughness() const { return table_roughness(); }
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
    h = h * rsqrt(l2);
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
    Float p;
    return ss_up(wo, wi, e, mode, &p);
  }
  /// eval_up's value, and the single-scattering density in *pdf_out: the VNDF density
  /// D_ωo(ω_m) = G1(ω_o) D(ω_m) |ω_o·ω_m| / cosθ_o times the reflect (F) or refract
  /// (1 − F) probability and the Jacobian of ω_m → ω_i (see pdf()).
  KAURI_HOST_DEVICE Float ss_up(Vec3 wo, Vec3 wi, Float e, TransportMode mode, Float* pdf_out) const {
    *pdf_out = 0;
    Vec3 wm;
    if (!half_vector(wo, wi, e, &wm)) return 0;
    const Float dot_o = dot(wo, wm), dot_i = dot(wi, wm);
    const Float F = fresnel_dielectric(dot_o, e);
    const Float D = mf.D(wm), lambda_o = mf.Lambda(wo);
    const Float DG = D / (1 + lambda_o + mf.Lambda(wi));
    const Float D_vis = D * dot_o / ((1 + lambda_o) * wo.z);
    if (wi.z > 0) {
      *pdf_out = D_vis / (4 * dot_o) * F;
      return DG * F / (4 * wo.z * wi.z);
    }
    const Float denom = sqr(dot_o + e * dot_i);
    *pdf_out = D_vis * (1 - F) * e * e * std::fabs(dot_i) / denom;
    Float ft = DG * (1 - F) * dot_o * std::fabs(dot_i) / (wo.z * std::fabs(wi.z) * denom);
    if (mode == TransportMode::Importance) ft *= e * e;
    return ft;
  }
};

}  // namespace kauri
