// Oren–Nayar-type rough diffuse reflection that conserves energy: a white lobe
// (ρ = 1) reflects exactly 1 at every angle of incidence, for every roughness.
//
// Model: "EON", Portsmouth, Kutz & Hill 2025, "EON: A practical energy-preserving
// rough diffuse BRDF" (JCGT; the OpenPBR diffuse). Written here from the math:
//
// Single scattering — Fujii's "qualitative" Oren–Nayar (FON), with σ ∈ [0,1]:
//   f_ss(ω_o, ω_i) = ρ/π · A · (1 + σ s/t),   A = 1 / (1 + c₁ σ),
//   s = ω_o·ω_i − μ_o μ_i  (= sinθ_o sinθ_i cos Δφ),   t = max(μ_o, μ_i) if s > 0 else 1,
//   c₁ = 1/2 − 2/(3π). f_ss ≥ A(1 − σ) ≥ 0 and is symmetric in ω_o, ω_i.
// Its directional albedo (white) has the closed form, with μ = cosθ, a = sinθ,
//   E(μ) = A (1 + σ G(μ)/π),
//   G(μ) = ∫ (s/t) μ_i dω_i = a(θ − aμ) + (2/3) a ((1 − a³)/μ − 1),
// derived by integrating over Δφ (±2 for the two half-planes) and then μ_i split at
// μ_o; (1 − a³)/μ is evaluated as μ(1 + a + a²)/(1 + a) (no cancellation at grazing).
// Its cosine-weighted hemispherical average E_avg = 2∫E(μ) μ dμ = A (1 + c₂ σ),
// c₂ = 2/3 − 28/(15π). Both closed forms are checked against quadrature in
// tests/cpp/test_oren_nayar.cpp, so no table is needed.
//
// Multiple scattering (Kulla–Conty-style compensation):
//   f_ms(ω_o, ω_i) = ρ_ms/π · (1 − E(μ_o)) (1 − E(μ_i)) / (1 − E_avg),
//   ρ_ms = ρ² E_avg / (1 − ρ (1 − E_avg)).
// ∫ f_ms μ_i dω_i = ρ_ms (1 − E(μ_o)), so the directional albedo is exactly
//   R(μ_o) = ρ E(μ_o) + ρ_ms (1 − E(μ_o)),
// which is 1 for ρ = 1 and ≤ ρ for ρ ≤ 1 (ρ_ms ≤ ρ ⇔ ρ ≤ 1). ρ_ms is the albedo of
// the energy that keeps bouncing on a surface of single-bounce albedo ρ·E_avg, i.e.
// the geometric series ρ E_avg Σ (ρ(1 − E_avg))^k scaled by ρ: it saturates the
// colour of rough diffuse surfaces as multiple bounces do.
//
// Roughness: σ = roughness ∈ [0,1] directly (FON's σ; it is not Oren–Nayar's slope
// standard deviation). σ = 0 gives A = 1, E ≡ 1, f_ms ≡ 0: exactly Lambert.
//
// Sampling: cosine-weighted hemisphere (the lobe covers the whole hemisphere; the
// weight f·cos/pdf = π f is bounded by π f(μ_o, μ_i → 0) ≤ ρ A (1 + σ sinθ_o/μ_o) + …).
#pragma once

#include <cmath>

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/bsdf/cosine_sampling.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

inline constexpr Float kFonC1 = Float(0.5 - 2.0 / (3.0 * 3.14159265358979323846));
inline constexpr Float kFonC2 = Float(2.0 / 3.0 - 28.0 / (15.0 * 3.14159265358979323846));

/// G(μ) = ∫ (s/t) μ_i dω_i of the FON lobe (see the header comment); G(1) = 0, G(0) = π/2 − 2/3.
KAURI_HOST_DEVICE inline Float fon_g(Float mu) {
  mu = clamp(mu, 0, 1);
  Float a = safe_sqrt(1 - mu * mu);
  Float theta = std::atan2(a, mu);
  return a * (theta - a * mu) + Float(2) / 3 * a * (mu * (1 + a + a * a) / (1 + a) - 1);
}

struct OrenNayarLobe {
  static constexpr const char* kName = "oren_nayar@1";
  static constexpr LobeClass kClass = LobeClass::BRDF;
  static constexpr Scattering kScattering = Scattering::Diffuse;

  SampledSpectrum albedo;   // ρ ∈ [0,1] per wavelength
  SampledSpectrum rho_ms;   // ρ² E_avg / (1 − ρ(1 − E_avg)), set by make()
  Float sigma = 0;          // σ ∈ [0,1]
  Float A = 1;              // 1 / (1 + c₁ σ)
  Float E_avg = 1;          // A (1 + c₂ σ)
  Float ms_norm = 0;        // 1 / (π (1 − E_avg)), 0 when σ = 0

  /// albedo: ρ per wavelength (clamped to [0,1]); roughness: σ ∈ [0,1] (clamped);
  /// 0 is Lambert, 1 the roughest (flattest, back-scattering) surface.
  KAURI_HOST_DEVICE static OrenNayarLobe make(const SampledSpectrum& albedo, Float roughness) {
    OrenNayarLobe l;
    l.sigma = clamp(roughness, 0, 1);
    l.A = 1 / (1 + kFonC1 * l.sigma);
    l.E_avg = l.A * (1 + kFonC2 * l.sigma);
    const Float one_minus_avg = 1 - l.E_avg;
    l.ms_norm = one_minus_avg > Float(1e-6) ? kInvPi / one_minus_avg : Float(0);
    for (int i = 0; i < kSpectrumSamples; ++i) {
      Float rho = clamp(albedo[i], 0, 1);
      l.albedo[i] = rho;
      l.rho_ms[i] = rho * rho * l.E_avg / (1 - rho * one_minus_avg);
    }
    return l;
  }

  /// White single-scattering directional albedo E(μ) = A (1 + σ G(μ)/π).
  KAURI_HOST_DEVICE Float E(Float mu) const { return A * (1 + sigma * kInvPi * fon_g(mu)); }

  // Two-sided like LambertLobe: the lobe reflects on the side of ω_o.
  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode) const {
    if (!same_hemisphere(wo, wi)) return SampledSpectrum(0);
    if (wo.z < 0) { wo = -wo; wi = -wi; }
    const Float mu_o = fmin_(wo.z, 1), mu_i = fmin_(wi.z, 1);
    Float s = dot(wo, wi) - mu_o * mu_i;
    Float s_over_t = s > 0 ? s / fmax_(mu_o, mu_i) : s;
    Float f_ss = A * (1 + sigma * s_over_t) * kInvPi;
    Float f_ms = ms_norm > 0 ? ms_norm * (1 - E(mu_o)) * (1 - E(mu_i)) : Float(0);
    return albedo * f_ss + rho_ms * f_ms;
  }
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf(abs_cos_theta(wi)) : 0;
  }
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float, Vec2 u, SampledWavelengths&, TransportMode mode) const {
    return sample_cosine_reflection(*this, wo, u, mode);
  }

  /// Exact directional albedo ρ E(μ_o) + ρ_ms (1 − E(μ_o)) (closed form, see above).
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    Float e = E(abs_cos_theta(wo));
    if (ms_norm == 0) return albedo * e;
    return albedo * e + rho_ms * (1 - e);
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3) const { return SampledSpectrum(0); }
  /// No notion of IOR: 0 tells IOR accumulation to skip it (as LambertLobe).
  KAURI_HOST_DEVICE Float ior(int) const { return 0; }
  /// The σ parameter (0: Lambert-like, 1: roughest).
  KAURI_HOST_DEVICE Float roughness() const { return sigma; }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const { return {0, 0, wo.z < 0 ? Float(-1) : Float(1)}; }
};

}  // namespace kauri
