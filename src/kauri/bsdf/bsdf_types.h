// Shared vocabulary of the BSDF interface (ARCHITECTURE.md, "The BSDF interface").
#pragma once

#include "kauri/spectral/sampled.h"

namespace kauri {

/// What a lobe does with light: reflect, transmit, both, scatter off curves, or emit.
enum class LobeClass : uint8_t { BRDF, BTDF, BSDF, BCSDF, EDF };

/// How sharply it scatters; drives sampling decisions, bounce-depth budgets and LPEs.
enum class Scattering : uint8_t { Diffuse = 1, Glossy = 2, Specular = 4 };

/// Which quantity a path carries: radiance (camera paths) or importance (light paths).
/// Refraction scales radiance by 1/η² but not importance (Veach 1997, §5.2).
enum class TransportMode : uint8_t { Radiance, Importance };

/// Result of sampling a lobe or a BSDF. `pdf == 0` means "no sample".
struct BSDFSample {
  SampledSpectrum f;         // BSDF value (without the cosine)
  Vec3 wi;                   // sampled direction (local or world, per caller)
  Float pdf = 0;             // solid-angle density; for Specular, the discrete probability
  Scattering scattering = Scattering::Diffuse;
  bool transmission = false;
  Float eta = 1;             // relative IOR crossed (1 unless transmitted)
  KAURI_HOST_DEVICE bool valid() const { return pdf > 0; }
  KAURI_HOST_DEVICE bool is_specular() const { return scattering == Scattering::Specular; }
};

}  // namespace kauri
