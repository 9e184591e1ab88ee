// Anisotropic microfacet distributions — GGX (Trowbridge–Reitz) and Beckmann —
// with height-correlated Smith masking-shadowing and visible-normal sampling.
// One plain struct dispatches on a tag, so a lobe holds either without virtuals.
#pragma once

#include "kauri/core/math.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

enum class MicrofacetType : uint8_t { GGX, Beckmann };

struct MicrofacetDistribution {
  Float alpha_x = 0, alpha_y = 0;
  MicrofacetType type = MicrofacetType::GGX;  // third member: `{ax, ay}` still means GGX

  /// Perceptual roughness r ∈ [0,1] → α = r² (Burley 2012), the artist convention.
  KAURI_HOST_DEVICE static Float roughness_to_alpha(Float r) { return r * r; }
  /// Below this α the lobe is treated as a perfect mirror / refractor.
  KAURI_HOST_DEVICE bool effectively_smooth() const { return fmax_(alpha_x, alpha_y) < 1e-3f; }
  /// Perceptual roughness of the isotropic equivalent, r = (α_x α_y)^(1/4): the key of
  /// the albedo tables (albedo_tables.h) for anisotropic lobes (an approximation).
  KAURI_HOST_DEVICE Float perceptual_roughness() const { return std::sqrt(std::sqrt(alpha_x * alpha_y)); }

  /// D(ω_m). GGX: Walter et al. 2007, eq. 33 (anisotropic form). Beckmann: Walter et
  /// al. 2007, eq. 25 / Heitz 2014, eq. 71 (anisotropic form).
  KAURI_HOST_DEVICE Float D(Vec3 wm) const {
    Float c2 = cos2_theta(wm);
    if (c2 <= 0) return 0;
    // tan²θ_m (cos²φ/α_x² + sin²φ/α_y²) written in Cartesian components.
    Float e = (sqr(wm.x / alpha_x) + sqr(wm.y / alpha_y)) / c2;
    if (type == MicrofacetType::Beckmann) return std::exp(-e) / (kPi * alpha_x * alpha_y * c2 * c2);
    return 1 / (kPi * alpha_x * alpha_y * c2 * c2 * sqr(1 + e));
  }
  /// Smith Λ(ω). GGX: Heitz 2014, eq. 86. Beckmann: Heitz 2014, eq. 80,
  /// Λ = (erf(a) − 1)/2 + exp(−a²)/(2a√π) with a = 1/(α(ω) tanθ).
  KAURI_HOST_DEVICE Float Lambda(Vec3 w) const {
    Float c2 = cos2_theta(w);
    if (c2 <= 0) return kInfinity;
    // α(ω)² tan²θ with α(ω)² = cos²φ α_x² + sin²φ α_y², in Cartesian components.
    Float a2t2 = (sqr(w.x * alpha_x) + sqr(w.y * alpha_y)) / c2;
    if (type == MicrofacetType::Beckmann) {
      if (a2t2 <= 0) return 0;
      Float a = 1 / std::sqrt(a2t2);
      if (a > 6) return 0;  // Λ < 1e-17: below float resolution of 1 + Λ
      return (std::erf(a) - 1) / 2 + std::exp(-a * a) / (2 * a * 1.7724538509f);
    }
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

  /// Samples ω_m ∝ D_ωo (w in the upper hemisphere).
  KAURI_HOST_DEVICE Vec3 sample_visible_normal(Vec3 w, Vec2 u) const {
    return type == MicrofacetType::Beckmann ? sample_visible_normal_beckmann(w, u) : sample_visible_normal_ggx(w, u);
  }

  /// GGX by spherical caps (Dupuy & Benyoub 2023, "Sampling Visible GGX Normals with
  /// Spherical Caps", HPG, listing 3): stretch ω to the α = 1 configuration (ω_s), where
  /// the visible normals are h = ω_s + c with c uniform on the cap of the unit sphere
  /// above z = −ω_s.z, and unstretch h. The same density as Heitz's construction (2018,
  /// JCGT 7(4): a disk warped onto the visible hemisphere in a basis around ω_s) without
  /// the basis and the disk's division: one normalisation fewer on the chain from the
  /// stretched direction to the sampled normal.
  KAURI_HOST_DEVICE Vec3 sample_visible_normal_ggx(Vec3 w, Vec2 u) const {
    Vec3 ws = normalize(Vec3{alpha_x * w.x, alpha_y * w.y, w.z});
    if (ws.z < 0) ws = -ws;
    const Float z = (1 - u.y) * (1 + ws.z) - ws.z;  // uniform in (−ω_s.z, 1]
    const Float sin_t = safe_sqrt((1 - z) * (1 + z));
    const Vec2 cs = cos_sin_turns(u.x);
    const Vec3 h{ws.x + sin_t * cs.x, ws.y + sin_t * cs.y, ws.z + z};
    return normalize(Vec3{alpha_x * h.x, alpha_y * h.y, fmax_(1e-6f, h.z)});
  }

  /// Beckmann (Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs using
  /// the Distribution of Visible Normals", §4 and appendix): stretch ω to α = 1, sample
  /// the visible slopes (x̃, ỹ) for the stretched incidence θ, rotate by its azimuth,
  /// unstretch. Derivation used here: for ω = (sinθ, 0, cosθ) and α = 1, the visible
  /// slope density is ∝ (cosθ − x̃ sinθ) e^{−x̃²−ỹ²}/π on x̃ < cotθ, so ỹ is an
  /// independent unit Gaussian of variance ½ and x̃ has the CDF
  ///   C(x) = [cosθ (1 + erf x) + sinθ e^{−x²}/√π] / 2   (1 + erf x = erfc(−x), exact in the tail),   C' = (cosθ − x sinθ) e^{−x²}/√π,
  /// which is inverted by safeguarded Newton iteration (bisection on failure).
  KAURI_HOST_DEVICE Vec3 sample_visible_normal_beckmann(Vec3 w, Vec2 u) const {
    Vec3 ws = normalize(Vec3{alpha_x * w.x, alpha_y * w.y, w.z});
    if (ws.z < 0) ws = -ws;
    // sin θ from the tangential components, not √(1 − cos²θ): near normal incidence that
    // difference cancels to a float ulp of 1, so sin θ and the azimuth came out wrong (an
    // incidence at sin θ = 2e-4 sampled slopes of variance 0.17 for 0.5, and ω = +z, whose
    // normalised z the CPU's rsqrt estimate may round to 1 − 2^-24, sampled every slope as 0).
    Float sin_t = std::sqrt(ws.x * ws.x + ws.y * ws.y), cos_t = ws.z;
    Float cos_phi = 1, sin_phi = 0;
    if (sin_t > 0) {
      cos_phi = ws.x / sin_t;
      sin_phi = ws.y / sin_t;
    }
    constexpr Float kInvSqrtPi = 0.5641895835f;
    // Slope x̃: solve C(x) = u·C(x_max), x_max = cotθ (at normal incidence: a Gaussian).
    Float x;
    if (sin_t < 1e-4f) {
      x = erf_inv(clamp(2 * u.x - 1, -kOneMinusEpsilon, kOneMinusEpsilon));
    } else {
      auto C = [&](Float t) { return (cos_t * std::erfc(-t) + sin_t * std::exp(-t * t) * kInvSqrtPi) / 2; };
      Float hi = fmin_(cos_t / sin_t, 8), lo = -8;
      Float target = u.x * C(hi);
      x = clamp(Float(0), lo, hi);  // start at the mode region
      if (x >= hi) x = (lo + hi) / 2;
      for (int it = 0; it < 40; ++it) {
        Float c = C(x) - target;
        if (std::fabs(c) < 1e-7f) break;
        if (c > 0) hi = x; else lo = x;
        Float d = (cos_t - x * sin_t) * std::exp(-x * x) * kInvSqrtPi;
        Float xn = d > 0 ? x - c / d : lo - 1;
        x = (xn > lo && xn < hi) ? xn : (lo + hi) / 2;
        if (hi - lo < 1e-6f) break;
      }
    }
    Float y = erf_inv(clamp(2 * u.y - 1, -kOneMinusEpsilon, kOneMinusEpsilon));
    // Rotate the slopes to the azimuth of ω_s, then unstretch.
    Float sx = cos_phi * x - sin_phi * y, sy = sin_phi * x + cos_phi * y;
    return normalize(Vec3{-alpha_x * sx, -alpha_y * sy, 1});
  }
};

/// The name every existing call site uses; `{αx, αy}` still means GGX.
using GGXDistribution = MicrofacetDistribution;

}  // namespace kauri
