// Compiled materials at render time: lobe parameters (spectra, not yet sampled at
// wavelengths), per-point inputs, and the layer programs that weight the lobes.
// At a hit, build_bsdf() instantiates each lobe at the path's wavelengths, runs
// the accumulation program (IOR / roughness, notes §8.4.3) if enabled, then the
// weight program (eqs. 3–11) for the current ω_o, and fills the BSDF.
#pragma once

#include <new>

#include "kauri/bsdf/bsdf.h"
#include "kauri/layer/layer_program.h"
#include "kauri/spectral/spectrum.h"
#include "kauri/texture/image_texture.h"

namespace kauri {


/// A scalar material input: a constant, or a per-vertex attribute times a scale.
struct ScalarInput {
  int16_t attribute = -1;
  Float value = 1;
  KAURI_HOST_DEVICE Float eval(const Float* attrs) const {
    return attribute < 0 ? value : attrs[attribute] * value;
  }
};

/// What a material reads at a shading point besides directions: interpolated vertex
/// attributes, texture coordinates and the scene's textures.
struct ShadingInputs {
  const Float* attrs = nullptr;
  Vec2 uv;
  const ImageTexture* textures = nullptr;
  KAURI_HOST_DEVICE ShadingInputs(const Float* a, Vec2 uv_ = {}, const ImageTexture* t = nullptr)
      : attrs(a), uv(uv_), textures(t) {}
};

struct LobeParams {
  LobeType type = LobeType::Lambert;
  Spectrum a;       // Lambert albedo, transmission τ, sheen colour; conductor: η (or reflectivity)
  int16_t a_texture = -1;  // ≥ 0: `a` is this image texture's reflectance at the hit's uv
  Spectrum b;       // conductor: κ (or edge tint)
  Float alpha_x = 0, alpha_y = 0;  // microfacet roughness (sheen: roughness in alpha_x)
  CauchyIOR ior;    // dielectrics
  MicrofacetType microfacet = MicrofacetType::GGX;
  bool compensate = true;   // conductor / rough dielectric multiple-scattering compensation
  bool artist = false;      // conductor: a, b are reflectivity and edge tint
  bool emission = false;    // an EDF (emission node): a is its radiance; `type` is unused
  bool two_sided = false;   // EDF emits from both sides
  Float focus = 0;          // EDF: 0 diffuse, n > 0 a cos^n focused lobe

  KAURI_HOST_DEVICE Lobe instantiate(const SampledWavelengths& lambda) const {
    return instantiate(lambda, [&] { return a.sample(lambda); });
  }
  /// The lobe with `a` at the wavelengths given by `a_sampled()` (called only by lobes
  /// that read `a`): a texture's reflectance at the hit, or `a` itself.
  template <class SampledA>
  KAURI_HOST_DEVICE Lobe instantiate(const SampledWavelengths& lambda, const SampledA& a_sampled) const {
    switch (type) {
      case LobeType::SmoothDielectric: {
        SmoothDielectricLobe l;
        for (int i = 0; i < kSpectrumSamples; ++i) l.eta[i] = ior(lambda.lambda[i]);
        l.dispersive = ior.dispersive();
        return Lobe(l);
      }
      case LobeType::GGXConductor: {
        GGXConductorLobe l;
        l.mf = {alpha_x, alpha_y, microfacet};
        l.compensate = compensate;
        if (artist) {
          artist_conductor_ior(a_sampled(), b.sample(lambda), &l.eta, &l.k);
        } else {
          l.eta = a_sampled();
          l.k = b.sample(lambda);
        }
        return Lobe(l);
      }
      case LobeType::RoughDielectric: {
        SampledSpectrum eta;
        for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda.lambda[i]);
        return Lobe(RoughDielectricLobe::make(eta, alpha_x, alpha_y, compensate));
      }
      case LobeType::ThinDielectric: {
        SampledSpectrum eta;
        for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda.lambda[i]);
        return Lobe(ThinDielectricLobe::make(eta));
      }
      case LobeType::DiffuseTransmission: return Lobe(DiffuseTransmissionLobe::make(a_sampled()));
      case LobeType::OrenNayar: return Lobe(OrenNayarLobe::make(a_sampled(), alpha_x));
      case LobeType::Sheen: return Lobe(SheenLobe::make(a_sampled(), alpha_x));
      case LobeType::Lambert:
      default: {
        LambertLobe l;
        l.albedo = a_sampled();
        return Lobe(l);
      }
    }
  }
};

struct MaterialView {
  bool emissive = false;      // has emission nodes: shapes using it are lights
  LayerProgram front;         // stack as authored, for rays arriving on the front side
  LayerProgram back;          // inverse order (single-sided) or the same (symmetric)
  int first_lobe = 0, n_lobes = 0;  // into SceneView::lobes
  int first_weight = 0;       // node weights (one per program node) in SceneView::node_weights
  bool ior_accumulation = false;
  bool roughness_accumulation = false;
  bool has_coat = true;       // the program has a coat node (only coat reads lobe albedos);
                              // set by the compiler, true (always compute) by default
  bool reads_uv = true;       // a lobe reads an image texture at the hit's uv (spheres and
                              // disks skip their trigonometric uv otherwise); set by the compiler
};

namespace material_detail {

/// Interface a lobe offers to the lobes beneath it; Lambert-like lobes take no part.
KAURI_HOST_DEVICE inline LobeInterface lobe_interface(const Lobe& l) {
  LobeInterface r;
  switch (l.type) {
    case LobeType::SmoothDielectric:
    case LobeType::RoughDielectric:
    case LobeType::GGXConductor:
      for (int i = 0; i < kSpectrumSamples; ++i) r.ior[i] = l.ior(i);
      r.roughness = l.roughness();
      break;
    default: break;
  }
  return r;
}

/// Makes lobe `l` see the IOR above it (relative IOR) and be at least as rough as
/// the layers above it.
KAURI_HOST_DEVICE inline void apply_accumulation(Lobe& l, const LayerAbove& above, bool ior_acc, bool rough_acc) {
  const bool has_above_ior = ior_acc && !above.ior.is_black();
  switch (l.type) {
    case LobeType::SmoothDielectric:
      if (has_above_ior) l.dielectric.eta = l.dielectric.eta.safe_div(above.ior);
      break;
    case LobeType::RoughDielectric:
      if (has_above_ior) l.rough_dielectric = RoughDielectricLobe::make(
          l.rough_dielectric.eta.safe_div(above.ior), l.rough_dielectric.mf.alpha_x, l.rough_dielectric.mf.alpha_y,
          l.rough_dielectric.compensate);
      if (rough_acc && above.roughness > 0) {
        Float a_min = sqr(above.roughness);
        l.rough_dielectric.mf.alpha_x = fmax_(l.rough_dielectric.mf.alpha_x, a_min);
        l.rough_dielectric.mf.alpha_y = fmax_(l.rough_dielectric.mf.alpha_y, a_min);
      }
      break;
    case LobeType::GGXConductor:
      if (has_above_ior) {
        l.conductor.eta = l.conductor.eta.safe_div(above.ior);
        l.conductor.k = l.conductor.k.safe_div(above.ior);
      }
      if (rough_acc && above.roughness > 0) {
        Float a_min = sqr(above.roughness);
        l.conductor.mf.alpha_x = fmax_(l.conductor.mf.alpha_x, a_min);
        l.conductor.mf.alpha_y = fmax_(l.conductor.mf.alpha_y, a_min);
      }
      break;
    default: break;
  }
}

/// The lobe of `p` at this point: its albedo from the texture when it has one.
KAURI_HOST_DEVICE inline Lobe instantiate(const LobeParams& p, const ShadingInputs& sp,
                                          const SampledWavelengths& lambda) {
  if (p.a_texture < 0) return p.instantiate(lambda);
  return p.instantiate(lambda, [&] { return sp.textures[p.a_texture].albedo(sp.uv, lambda); });
}

}  // namespace material_detail

/// Radiance an emission node (EDF) sends towards local direction `wo`: diffuse, or
/// focused as cos^n with the peak scaled by (n + 2)/2 so the radiant exitance matches
/// the diffuse EDF of the same radiance.
KAURI_HOST_DEVICE inline SampledSpectrum edf_radiance(const LobeParams& p, Vec3 wo, const SampledWavelengths& lambda) {
  Float c = wo.z;
  if (c <= 0 && !p.two_sided) return SampledSpectrum(0);
  c = std::fabs(c);
  Float shape = p.focus > 0 ? (p.focus + 2) / 2 * std::pow(c, p.focus) : Float(1);
  return p.a.sample(lambda) * shape;
}

namespace material_detail {

/// One scattering lobe and nothing to accumulate (most materials): the BSDF is that lobe
/// with its own weight w_b, no layer program to run.
KAURI_HOST_DEVICE inline bool single_lobe(const MaterialView& m, const LobeParams* params) {
  return m.n_lobes == 1 && m.front.n_nodes == 1 && !params[0].emission && !m.ior_accumulation &&
         !m.roughness_accumulation;
}

/// The BSDF of a single_lobe() material into `bsdf`, whose frame is set: the lobe built in
/// the BSDF's slot (placement new of the prvalue, no copy; a local Lobe copied into the
/// BSDF cost a store-forwarding stall per hit), its selection probability 1.
KAURI_HOST_DEVICE inline void build_single_lobe(const MaterialView& m, const LobeParams& p,
                                                const ScalarInput* node_weights, const ShadingInputs& sp,
                                                const SampledWavelengths& lambda, BSDF* bsdf) {
  bsdf->n_lobes = 0;
  const Float w = clamp(node_weights[m.first_weight].eval(sp.attrs), 0, 1);
  if (!(w > 0)) return;
  if (p.type == LobeType::Lambert) {
    // The most common lobe, without instantiate()'s dispatch over every kind (out of line
    // in the profiled build: ~45 instructions a hit). The same albedo as instantiate().
    LambertLobe lambert;
    lambert.albedo = p.a_texture < 0 ? p.a.sample(lambda) : sp.textures[p.a_texture].albedo(sp.uv, lambda);
    new (&bsdf->lobes[0]) Lobe(lambert);
  } else {
    Lobe* l = new (&bsdf->lobes[0]) Lobe(instantiate(p, sp, lambda));
    if (l->type == LobeType::GGXConductor) l->conductor.cache_multiple_scattering();
  }
  bsdf->weight[0] = SampledSpectrum(w);
  bsdf->transmission[0] = 1;
  bsdf->select_prob[0] = 1;  // prepare() of one lobe
  bsdf->n_lobes = 1;
}

}  // namespace material_detail

/// Evaluates material `m` at a point for the outgoing direction `wo_world`: fills
/// `bsdf` (if given) with the weighted scattering lobes and adds the weighted
/// emission towards `wo_world` to `*emitted` (if given). `sp` holds the interpolated
/// per-vertex attributes, the uv and the textures.
KAURI_HOST_DEVICE inline void evaluate_material(const MaterialView& m, const LobeParams* lobe_params,
                                                const ScalarInput* node_weights, const ShadingInputs& sp,
                                                const Frame& frame, Normal3 ng, Vec3 wo_world,
                                                const SampledWavelengths& lambda, BSDF* bsdf,
                                                SampledSpectrum* emitted) {
  if (bsdf) {
    bsdf->frame = frame;
    bsdf->ng = ng;
    bsdf->n_lobes = 0;
  }
  const int n = m.n_lobes < kMaxLayerNodes ? m.n_lobes : kMaxLayerNodes;
  const LobeParams* params = lobe_params + m.first_lobe;
  if (material_detail::single_lobe(m, params)) {
    if (bsdf) material_detail::build_single_lobe(m, params[0], node_weights, sp, lambda, bsdf);
    return;
  }
  Lobe lobes[kMaxLayerNodes];
  for (int i = 0; i < n; ++i)
    if (!params[i].emission) lobes[i] = material_detail::instantiate(params[i], sp, lambda);

  // Single-sided stacks: arriving from behind the surface runs the inverse program.
  const LayerProgram& prog = dot(wo_world, ng) < 0 ? m.back : m.front;
  if (m.ior_accumulation || m.roughness_accumulation) {
    LobeInterface ifs[kMaxLayerNodes];
    LayerAbove above[kMaxLayerNodes];
    for (int i = 0; i < n; ++i)
      ifs[i] = params[i].emission ? LobeInterface{} : material_detail::lobe_interface(lobes[i]);
    evaluate_accumulation(prog, ifs, above);
    for (int i = 0; i < n; ++i)
      if (!params[i].emission)
        material_detail::apply_accumulation(lobes[i], above[i], m.ior_accumulation, m.roughness_accumulation);
  }

  for (int i = 0; i < n; ++i)
    if (!params[i].emission && lobes[i].type == LobeType::GGXConductor) lobes[i].conductor.cache_multiple_scattering();

  Vec3 wo = frame.to_local(wo_world);
  ScratchArray<SampledSpectrum, kMaxLayerNodes> w;
  Float transmission[kMaxLayerNodes];
  if (prog.n_nodes == 1) {
    // A single lobe: its weight is its own w_b (the common case; no program to run).
    w[0] = SampledSpectrum(clamp(node_weights[m.first_weight].eval(sp.attrs), 0, 1));
    transmission[0] = 1;
  } else {
    LayerInputs in;
    for (int i = 0; i < prog.n_nodes; ++i) in.node_weight[i] = clamp(node_weights[m.first_weight + i].eval(sp.attrs), 0, 1);
    // Only coat reads the stopped albedos a_b = 1 − a_t (eq. 5); an EDF stops no light
    // (a_t = 1): a layer under it is fully lit, one above it dims it.
    for (int i = 0; i < n; ++i)
      in.lobe_stopped[i] = !m.has_coat || params[i].emission ? SampledSpectrum(0) : SampledSpectrum(1) - lobes[i].albedo_t(wo);
    evaluate_layer_weights(prog, in, w.data(), transmission);
  }
  for (int i = 0; i < n; ++i) {
    if (params[i].emission) {
      if (emitted) *emitted += w[i] * edf_radiance(params[i], wo, lambda);
    } else if (bsdf) {
      bsdf->add(lobes[i], w[i], transmission[i]);
    }
  }
  if (bsdf) bsdf->prepare(wo_world);
}

KAURI_HOST_DEVICE inline void build_bsdf(const MaterialView& m, const LobeParams* lobe_params,
                                         const ScalarInput* node_weights, const ShadingInputs& sp, const Frame& frame,
                                         Normal3 ng, Vec3 wo_world, const SampledWavelengths& lambda, BSDF* bsdf) {
  // Single-lobe materials skip evaluate_material's call, whose prologue and frame of locals
  // for the layer program made building a Lambert BSDF ~200 instructions a hit (Cornell
  // box, callgrind); inline, ~105.
  const LobeParams* params = lobe_params + m.first_lobe;
  if (material_detail::single_lobe(m, params)) {
    bsdf->frame = frame;
    bsdf->ng = ng;
    material_detail::build_single_lobe(m, params[0], node_weights, sp, lambda, bsdf);
    return;
  }
  evaluate_material(m, lobe_params, node_weights, sp, frame, ng, wo_world, lambda, bsdf, nullptr);
}

}  // namespace kauri
