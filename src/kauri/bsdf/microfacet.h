// Anisotropic GGX (Trowbridge–Reitz) microfacet distribution with
// height-correlated masking-shadowing and visible-normal sampling.
#pragma once

#include "kauri/core/math.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

struct GGXDistribution {
  Float alpha_x = 0, alpha_y = 0;

  /// Perceptual roughness r ∈ [0,1] → α = r² (Burley 2012), the artist convention.
  KAURI_HOST_DEVICE static Float roughness_to_alpha(Float r) { return r * r; }
  /// Below this α the lobe is treated as a perfect mirror / refractor.
  KAURI_HOST_DEVICE bool effectively_smooth() const { return fmax_(alpha_x, alpha_y) < 1e-3f; }

  /// D(ω_m) (Walter et al. 2007, eq. 33; anisotropic form).
  KAURI_HOST_DEVICE Float D(Vec3 wm) const {
    Float c2 = cos2_theta(wm);
    if (c2 <= 0) return 0;
    // tan²θ_m (cos²φ/α_x² + sin²φ/α_y²) written in Cartesian components.
    Float e = (sqr(wm.x / alpha_x) + sqr(wm.y / alpha_y)) / c2;
    return 1 / (kPi * alpha_x * alpha_y * c2 * c2 * sqr(1 + e));
  }
  /// Smith Λ(ω) (Heitz 2014, eq. 86).
  KAURI_HOST_DEVICE Float Lambda(Vec3 w) const {
    Float c2 = cos2_theta(w);
    if (c2 <= 0) return kInfinity;
    // α(ω)² tan²θ with α(ω)² = cos²φ α_x² + sin²φ α_y², in Cartesian components.
    Float a2t2 = (sqr(w.x * alpha_x) + sqr(w.y * alpha_y)) / c2;
    return (std::sqrt(1 + a2t2) - 1) / 2;
  }
  KAURI_HOST_DEVICE Float G1(Vec3 w) const { return 1 / (1 + Lambda(w)); }
  /// Height-correlated masking-shadowing (Heitz 2014, eq. 99).
  KAURI_HOST_DEVICE Float G(Vec3 wo, Vec3 wi) const { return 1 / (1 + Lambda(wo) + Lambda(wi)); }
  /// Distribution of visible normals D_ωo(ω_m) (Heitz 2014, eq. 16).
  KAURI_HOST_DEVICE Float D_visible(Vec3 w, Vec3 wm) const {
    Float c = abs_cos_theta(w);
    if (c == 0) return 0;
    return G1(w) / c * D(wm) * std::fabs(dot(w, wm));
  }

  /// Samples ω_m ∝ D_ωo (Heitz 2018, "Sampling the GGX distribution of visible
  /// normals", JCGT 7(4)): stretch to the α = 1 configuration, sample the
  /// projected hemisphere, unstretch.
  KAURI_HOST_DEVICE Vec3 sample_visible_normal(Vec3 w, Vec2 u) const {
    Vec3 wh = normalize(Vec3{alpha_x * w.x, alpha_y * w.y, w.z});
    if (wh.z < 0) wh = -wh;
    Vec3 t1 = wh.z < 0.99999f ? normalize(cross(Vec3{0, 0, 1}, wh)) : Vec3{1, 0, 0};
    Vec3 t2 = cross(wh, t1);
    Vec2 p = sample_uniform_disk(u);
    // Warp the disk so it projects onto the visible part of the hemisphere.
    Float h = std::sqrt(1 - p.x * p.x);
    Float s = (1 + wh.z) / 2;
    p.y = lerp(s, h, p.y);
    Float pz = safe_sqrt(1 - p.x * p.x - p.y * p.y);
    Vec3 nh = t1 * p.x + t2 * p.y + wh * pz;
    return normalize(Vec3{alpha_x * nh.x, alpha_y * nh.y, fmax_(1e-6f, nh.z)});
  }
};

}  // namespace kauri
