// BSDF at a shading point: a weighted sum of lobes in a shading frame.
// The weights are what a material's layer program yields for this point and ω_o;
// sampling picks one lobe by weight × albedo and combines the densities of all
// lobes (one-sample MIS, Veach 1997 §9.2.4), so stacks of many lobes stay efficient.
#pragma once

#include "kauri/bsdf/lobe.h"
#include "kauri/core/scratch_array.h"

namespace kauri {

inline constexpr int kMaxLobes = 8;

struct BSDF {
  Frame frame;      // shading frame, z = shading normal
  Normal3 ng;       // geometric normal (world)
  int n_lobes = 0;
  Lobe lobes[kMaxLobes];
  ScratchArray<SampledSpectrum, kMaxLobes> weight;  // spectral: a tinted stack tints what lies below it
  Float transmission[kMaxLobes];      // fraction of a lobe's transmission leaving the stack (coat tops: less)
  Float select_prob[kMaxLobes];       // set by prepare()

  KAURI_HOST_DEVICE void add(const Lobe& l, const SampledSpectrum& w, Float transmission_scale = 1) {
    if (n_lobes < kMaxLobes && w.max_value() > 0) {
      lobes[n_lobes] = l;
      weight[n_lobes] = w;
      transmission[n_lobes] = transmission_scale;
      ++n_lobes;
    }
  }
  KAURI_HOST_DEVICE void add(const Lobe& l, Float w) { add(l, SampledSpectrum(w)); }

  /// How much of lobe i counts for the pair (wo, wi) (local frame): 1 for reflection,
  /// its transmission scale for transmission.
  KAURI_HOST_DEVICE Float lobe_scale(int i, Vec3 wo, Vec3 wi) const {
    return same_hemisphere(wo, wi) ? Float(1) : transmission[i];
  }
  /// Directional albedo of the whole BSDF for ω_o (local frame): Σ weight × (reflection
  /// + scaled transmission albedo).
  KAURI_HOST_DEVICE SampledSpectrum albedo(Vec3 wo) const {
    SampledSpectrum a(0);
    for (int i = 0; i < n_lobes; ++i) a += lobe_albedo(i, wo) * weight[i];
    return a;
  }
  KAURI_HOST_DEVICE SampledSpectrum lobe_albedo(int i, Vec3 wo) const {
    return lobes[i].albedo_r(wo) + lobes[i].albedo_t(wo) * transmission[i];
  }
  /// Lobe selection probabilities ∝ weight × average reflection+transmission albedo.
  /// A single lobe needs no albedo query (for a conductor that is a 3×3 quadrature).
  KAURI_HOST_DEVICE void prepare(Vec3 wo_world) {
    if (n_lobes == 1) {
      select_prob[0] = 1;
      return;
    }
    Vec3 wo = frame.to_local(wo_world);
    Float total = 0;
    for (int i = 0; i < n_lobes; ++i) {
      Float a = (lobe_albedo(i, wo) * weight[i]).average();
      select_prob[i] = fmax_(a, 1e-3f * weight[i].average());
      total += select_prob[i];
    }
    for (int i = 0; i < n_lobes; ++i) select_prob[i] = total > 0 ? select_prob[i] / total : 0;
  }

  KAURI_HOST_DEVICE bool has_non_specular() const {
    for (int i = 0; i < n_lobes; ++i)
      if (lobes[i].scattering() != Scattering::Specular) return true;
    return false;
  }

  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo_world, Vec3 wi_world, TransportMode mode) const {
    Vec3 wo = frame.to_local(wo_world), wi = frame.to_local(wi_world);
    if (wo.z == 0) return SampledSpectrum(0);
    SampledSpectrum f(0);
    for (int i = 0; i < n_lobes; ++i) {
      Float t = lobe_scale(i, wo, wi);
      if (t > 0) f += lobes[i].eval(wo, wi, mode) * weight[i] * t;
    }
    return f * shading_normal_correction(wo_world, wi_world, wo, wi);
  }
  KAURI_HOST_DEVICE Float pdf(Vec3 wo_world, Vec3 wi_world) const {
    Vec3 wo = frame.to_local(wo_world), wi = frame.to_local(wi_world);
    Float p = 0;
    for (int i = 0; i < n_lobes; ++i) p += select_prob[i] * lobes[i].pdf(wo, wi);
    return p;
  }
  /// A lone Lambert lobe, the most common BSDF: eval_pdf() and sample() take it inline
  /// (lone_lambert_*), with the general code's operations in its order, so bit for bit
  /// what the general code gives. Out of line, the dispatch over every lobe kind cost ~50
  /// instructions of register saves a call.
  KAURI_HOST_DEVICE bool lone_lambert() const { return n_lobes == 1 && lobes[0].type == LobeType::Lambert; }

  /// eval() and pdf() of one direction pair in one pass (next-event estimation needs both),
  /// sharing each lobe's common terms.
  KAURI_HOST_DEVICE KAURI_FORCE_INLINE SampledSpectrum eval_pdf(Vec3 wo_world, Vec3 wi_world, TransportMode mode,
                                                                Float* pdf_out) const {
    if (lone_lambert()) return lone_lambert_eval_pdf(wo_world, wi_world, pdf_out);
    return eval_pdf_lobes(wo_world, wi_world, mode, pdf_out);
  }
  KAURI_HOST_DEVICE SampledSpectrum eval_pdf_lobes(Vec3 wo_world, Vec3 wi_world, TransportMode mode,
                                                   Float* pdf_out) const {
    Vec3 wo = frame.to_local(wo_world), wi = frame.to_local(wi_world);
    SampledSpectrum f(0);
    Float p = 0;
    for (int i = 0; i < n_lobes; ++i) {
      Float p_i;
      SampledSpectrum f_i = lobes[i].eval_pdf(wo, wi, mode, &p_i);
      p += select_prob[i] * p_i;
      Float t = lobe_scale(i, wo, wi);
      if (t > 0) f += f_i * weight[i] * t;
    }
    *pdf_out = p;
    if (wo.z == 0) return SampledSpectrum(0);
    return f * shading_normal_correction(wo_world, wi_world, wo, wi);
  }
  /// `uc` picks the lobe (and is reused, rescaled, for the lobe's own discrete choice).
  KAURI_HOST_DEVICE KAURI_FORCE_INLINE BSDFSample sample(Vec3 wo_world, Float uc, Vec2 u, SampledWavelengths& lambda,
                                                         TransportMode mode) const {
    if (lone_lambert()) return lone_lambert_sample(wo_world, u, lambda);
    return sample_lobes(wo_world, uc, u, lambda, mode);
  }
  KAURI_HOST_DEVICE BSDFSample sample_lobes(Vec3 wo_world, Float uc, Vec2 u, SampledWavelengths& lambda,
                                            TransportMode mode) const {
    BSDFSample none;
    if (n_lobes == 0) return none;
    Vec3 wo = frame.to_local(wo_world);
    if (wo.z == 0) return none;
    int chosen = n_lobes - 1;
    Float cdf = 0;
    for (int i = 0; i < n_lobes; ++i) {
      if (uc < cdf + select_prob[i] || i == n_lobes - 1) {
        chosen = i;
        uc = select_prob[i] > 0 ? fmin_((uc - cdf) / select_prob[i], kOneMinusEpsilon) : Float(0);
        break;
      }
      cdf += select_prob[i];
    }
    if (select_prob[chosen] <= 0) return none;
    BSDFSample s = lobes[chosen].sample(wo, uc, u, lambda, mode);
    if (!s.valid() || s.wi.z == 0) return none;
    const Float t_chosen = lobe_scale(chosen, wo, s.wi);
    if (t_chosen <= 0) return none;  // energy handed to the layers below
    Vec3 wi_world = frame.to_world(s.wi);
    if (s.is_specular() || n_lobes == 1) {
      // A delta lobe cannot be combined with the others: the estimator is its own. A lone
      // lobe's sample already carries eval() and pdf() at its direction (each lobe's test
      // checks sample().f == eval() and sample().pdf == pdf()): no second evaluation.
      s.f *= weight[chosen] * t_chosen;
      s.pdf *= select_prob[chosen];
    } else {
      s.f = SampledSpectrum(0);
      s.pdf = 0;
      for (int i = 0; i < n_lobes; ++i) {
        if (lobes[i].scattering() == Scattering::Specular) continue;
        Float p_i;
        s.f += lobes[i].eval_pdf(wo, s.wi, mode, &p_i) * weight[i] * lobe_scale(i, wo, s.wi);
        s.pdf += select_prob[i] * p_i;
      }
    }
    s.f *= shading_normal_correction(wo_world, wi_world, wo, s.wi);
    s.wi = wi_world;
    return s;
  }

  /// eval_pdf_lobes() of a lone Lambert lobe: the lobe's own eval and pdf, times its
  /// weight and selection probability (its transmission scale never applies: a Lambert lobe
  /// is 0 off ω_o's side).
  KAURI_HOST_DEVICE SampledSpectrum lone_lambert_eval_pdf(Vec3 wo_world, Vec3 wi_world, Float* pdf_out) const {
    const Vec3 wo = frame.to_local(wo_world), wi = frame.to_local(wi_world);
    const LambertLobe& l = lobes[0].lambert;
    *pdf_out = select_prob[0] * l.pdf(wo, wi);
    if (wo.z == 0) return SampledSpectrum(0);
    return l.eval(wo, wi, TransportMode::Radiance) * weight[0] * shading_normal_correction(wo_world, wi_world, wo, wi);
  }
  /// sample_lobes() of a lone Lambert lobe (its weight's factor t = 1: the lobe samples
  /// ω_o's side).
  KAURI_HOST_DEVICE BSDFSample lone_lambert_sample(Vec3 wo_world, Vec2 u, SampledWavelengths& lambda) const {
    BSDFSample none;
    const Vec3 wo = frame.to_local(wo_world);
    if (wo.z == 0 || select_prob[0] <= 0) return none;
    BSDFSample s = lobes[0].lambert.sample(wo, 0, u, lambda, TransportMode::Radiance);
    if (!s.valid() || s.wi.z == 0) return none;
    const Vec3 wi_world = frame.to_world(s.wi);
    s.f *= weight[0];
    s.pdf *= select_prob[0];
    s.f *= shading_normal_correction(wo_world, wi_world, wo, s.wi);
    s.wi = wi_world;
    return s;
  }

  /// Light leaks where shading and geometric normals disagree: a direction on
  /// the wrong side of the true surface gets no reflection/transmission it
  /// cannot physically have.
  /// `wo_local`, `wi_local`: the same directions in the shading frame (the callers have them).
  KAURI_HOST_DEVICE Float shading_normal_correction(Vec3 wo_world, Vec3 wi_world, Vec3 wo_local, Vec3 wi_local) const {
    bool geo_reflect = dot(wo_world, ng) * dot(wi_world, ng) > 0;
    bool shading_reflect = wo_local.z * wi_local.z > 0;
    return geo_reflect == shading_reflect ? Float(1) : Float(0);
  }
};

}  // namespace kauri
