// Compiled materials: lobe parameters (spectra, not yet sampled at wavelengths)
// and the weights a material's program gives them. At a hit, each lobe is
// instantiated at the path's wavelengths and added to the BSDF.
//
// Today a material is a flat list of weighted lobes; the layered-material work
// (Manuka-style operators) compiles its layer trees into this same form plus a
// per-hit weight program, so the BSDF and integrator do not change.
#pragma once

#include "kauri/bsdf/bsdf.h"
#include "kauri/spectral/spectrum.h"

namespace kauri {

struct LobeParams {
  LobeType type = LobeType::Lambert;
  Spectrum a;       // Lambert: albedo; conductor: η
  Spectrum b;       // conductor: κ
  Float alpha_x = 0, alpha_y = 0;  // microfacet roughness
  CauchyIOR ior;    // dielectric

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
        l.mf = {alpha_x, alpha_y};
        l.eta = a.sample(lambda);
        l.k = b.sample(lambda);
        return Lobe(l);
      }
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
  int first_lobe = 0;
  int n_lobes = 0;
};

/// Builds the BSDF of material `m` at a hit with shading frame `frame`.
KAURI_HOST_DEVICE inline void build_bsdf(const MaterialView& m, const LobeParams* lobes, const Float* weights,
                                         const Frame& frame, Normal3 ng, Vec3 wo,
                                         const SampledWavelengths& lambda, BSDF* bsdf) {
  bsdf->frame = frame;
  bsdf->ng = ng;
  bsdf->n_lobes = 0;
  for (int i = 0; i < m.n_lobes; ++i)
    bsdf->add(lobes[m.first_lobe + i].instantiate(lambda), weights[m.first_lobe + i]);
  bsdf->prepare(wo);
}

}  // namespace kauri
