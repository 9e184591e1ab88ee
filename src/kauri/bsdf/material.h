// Compiled materials at render time: lobe parameters (spectra, not yet sampled at
// wavelengths), per-point inputs, and the layer programs that weight the lobes.
// At a hit, build_bsdf() instantiates each lobe at the path's wavelengths, runs
// the accumulation program (IOR / roughness, notes §8.4.3) if enabled, then the
// weight program (eqs. 3–11) for the current ω_o, and fills the BSDF.
#pragma once

#include "kauri/bsdf/bsdf.h"
#include "kauri/layer/layer_program.h"
#include "kauri/spectral/spectrum.h"

namespace kauri {


/// A scalar material input: a constant, or a per-vertex attribute times a scale.
struct ScalarInput {
  int16_t attribute = -1;
  Float value = 1;
  KAURI_HOST_DEVICE Float eval(const Float* attrs) const {
    return attribute < 0 ? value : attrs[attribute] * value;
  }
};

struct LobeParams {
  LobeType type = LobeType::Lambert;
  Spectrum a;       // Lambert albedo, transmission τ, sheen colour; conductor: η (or reflectivity)
  Spectrum b;       // conductor: κ (or edge tint)
  Float alpha_x = 0, alpha_y = 0;  // microfacet roughness (sheen: roughness in alpha_x)
  CauchyIOR ior;    // dielectrics
  MicrofacetType microfacet = MicrofacetType::GGX;
  bool compensate = true;   // conductor multiple-scattering compensation
  bool artist = false;      // conductor: a, b are reflectivity and edge tint

  KAURI_HOST_DEVICE Lobe instantiate(const SampledWavelengths& lambda) const {
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
          artist_conductor_ior(a.sample(lambda), b.sample(lambda), &l.eta, &l.k);
        } else {
          l.eta = a.sample(lambda);
          l.k = b.sample(lambda);
        }
        return Lobe(l);
      }
      case LobeType::RoughDielectric: {
        SampledSpectrum eta;
        for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda.lambda[i]);
        return Lobe(RoughDielectricLobe::make(eta, alpha_x, alpha_y));
      }
      case LobeType::ThinDielectric: {
        SampledSpectrum eta;
        for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda.lambda[i]);
        return Lobe(ThinDielectricLobe::make(eta));
      }
      case LobeType::DiffuseTransmission: return Lobe(DiffuseTransmissionLobe::make(a.sample(lambda)));
      case LobeType::Sheen: return Lobe(SheenLobe::make(a.sample(lambda), alpha_x));
      case LobeType::Lambert:
      default: {
        LambertLobe l;
        l.albedo = a.sample(lambda);
        return Lobe(l);
      }
    }
  }
};

struct MaterialView {
  LayerProgram front;         // stack as authored, for rays arriving on the front side
  LayerProgram back;          // inverse order (single-sided) or the same (symmetric)
  int first_lobe = 0, n_lobes = 0;  // into SceneView::lobes
  int first_weight = 0;       // node weights (one per program node) in SceneView::node_weights
  bool ior_accumulation = false;
  bool roughness_accumulation = false;
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
          l.rough_dielectric.eta.safe_div(above.ior), l.rough_dielectric.mf.alpha_x, l.rough_dielectric.mf.alpha_y);
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

}  // namespace material_detail

/// Builds the BSDF of material `m` at a hit. `attrs` are the interpolated
/// per-vertex attributes; `wo_world` points away from the surface.
KAURI_HOST_DEVICE inline void build_bsdf(const MaterialView& m, const LobeParams* lobe_params,
                                         const ScalarInput* node_weights, const Float* attrs, const Frame& frame,
                                         Normal3 ng, Vec3 wo_world, const SampledWavelengths& lambda, BSDF* bsdf) {
  bsdf->frame = frame;
  bsdf->ng = ng;
  bsdf->n_lobes = 0;
  const int n = m.n_lobes < kMaxLayerNodes ? m.n_lobes : kMaxLayerNodes;
  Lobe lobes[kMaxLayerNodes];
  for (int i = 0; i < n; ++i) lobes[i] = lobe_params[m.first_lobe + i].instantiate(lambda);

  // Single-sided stacks: arriving from behind the surface runs the inverse program.
  const LayerProgram& prog = dot(wo_world, ng) < 0 ? m.back : m.front;
  if (m.ior_accumulation || m.roughness_accumulation) {
    LobeInterface ifs[kMaxLayerNodes];
    LayerAbove above[kMaxLayerNodes];
    for (int i = 0; i < n; ++i) ifs[i] = material_detail::lobe_interface(lobes[i]);
    evaluate_accumulation(prog, ifs, above);
    for (int i = 0; i < n; ++i)
      material_detail::apply_accumulation(lobes[i], above[i], m.ior_accumulation, m.roughness_accumulation);
  }

  Vec3 wo = frame.to_local(wo_world);
  LayerInputs in;
  for (int i = 0; i < prog.n_nodes; ++i) in.node_weight[i] = clamp(node_weights[m.first_weight + i].eval(attrs), 0, 1);
  for (int i = 0; i < n; ++i) in.lobe_stopped[i] = SampledSpectrum(1) - lobes[i].albedo_t(wo);
  SampledSpectrum w[kMaxLayerNodes];
  Float transmission[kMaxLayerNodes];
  evaluate_layer_weights(prog, in, w, transmission);
  for (int i = 0; i < n; ++i) bsdf->add(lobes[i], w[i], transmission[i]);
  bsdf->prepare(wo_world);
}

}  // namespace kauri
