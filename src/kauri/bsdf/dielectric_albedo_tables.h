// Directional-albedo tables of the single-scattering rough GGX dielectric lobe
// (RoughDielectricLobe with compensate = false, importance transport, Fresnel from the
// microfacet normal), for its Kulla–Conty multiple-scattering compensation and for its
// albedo_r/albedo_t queries (/work/shared/refs/layering.md §2):
//   E(μ_o, r, e)   = ∫_S² f_ss(ω_o, ω_i) |μ_i| dω_i          (reflection + transmission)
//   E_T(μ_o, r, e) = ∫_{lower hemisphere} f_ss(ω_o, ω_i) |μ_i| dω_i   (transmission only)
//   E_avg = 2 ∫_0^1 E(μ) μ dμ, E_T,avg likewise,
// with ω_o on the upper side and e the IOR of the far side relative to ω_o's side.
// Importance transport conserves energy (E ≤ 1); radiance differs only by the e²
// scaling of transmission, which the lobe applies itself.
//
// Grid: side s = 0 holds e = η_k ("entering", e > 1), s = 1 holds e = 1/η_k ("exiting",
// with total internal reflection); η_k = 1.01 + k (3 − 1.01)/15, k = 0..15 (linear in η),
// r = j/15 (perceptual roughness, α = r²), μ = i/31. Layout [s][k][j][i] (μ fastest).
// Outside η ∈ [1.01, 3] the lookup clamps η (|e − 1| < 0.01 is then slightly too lossy
// — at most the loss of η = 1.01, a fraction of a per cent — and e > 3 uses e = 3).
// Nodes with α < 1e-3 (a smooth interface) store E = 1, E_T = 1 − F(μ). The μ = 0 nodes
// hold the linear extrapolation of the μ = 1/31 and 2/31 nodes (as in albedo_tables.h:
// the grazing boundary layer is narrower than a cell at small α).
//
// Generator: tools/gen_dielectric_albedo_tables.cpp (midpoint quadrature of the VNDF
// sample square with the runtime's microfacet.h/fresnel.h; method and self-check
// there); the arrays are in data/dielectric_albedo_tables.cpp (generated, committed).
// The stored averages integrate the piecewise-linear μ interpolant exactly, so the
// compensation lobe restores exactly 1 − E of the table. A CUDA build needs
// __constant__ copies of the arrays (as for albedo_tables.h).
#pragma once

#include "kauri/core/math.h"

namespace kauri {

inline constexpr int kDielAlbedoMu = 32, kDielAlbedoR = 16, kDielAlbedoEta = 16;
inline constexpr float kDielAlbedoEtaMin = 1.01f, kDielAlbedoEtaMax = 3.0f;
inline constexpr int kDielAlbedoSide = kDielAlbedoEta * kDielAlbedoR * kDielAlbedoMu;  // floats per side
inline constexpr int kDielAlbedoAvgSide = kDielAlbedoEta * kDielAlbedoR;

extern const float kGGXDielectricAlbedo[2 * kDielAlbedoSide];     // E
extern const float kGGXDielectricAlbedoT[2 * kDielAlbedoSide];    // E_T
extern const float kGGXDielectricAlbedoAvg[2 * kDielAlbedoAvgSide];   // E_avg  [s][k][j]
extern const float kGGXDielectricAlbedoTAvg[2 * kDielAlbedoAvgSide];  // E_T,avg

/// Continuous grid coordinate of x ∈ [0,1] on n nodes → (cell index, fraction).
KAURI_HOST_DEVICE inline void diel_grid_coord(Float x, int n, int* i, Float* f) {
  Float g = clamp(x, 0, 1) * Float(n - 1);
  int k = int(g);
  if (k > n - 2) k = n - 2;
  *i = k;
  *f = g - Float(k);
}

/// Table position of (r, e): side offset and the (η, r) cell.
struct DielAlbedoKey {
  int side, k, j;
  Float fk, fr;
};
KAURI_HOST_DEVICE inline DielAlbedoKey diel_albedo_key(Float r, Float e) {
  DielAlbedoKey key;
  key.side = e >= 1 ? 0 : 1;
  Float eta = e >= 1 ? e : 1 / e;
  diel_grid_coord((eta - kDielAlbedoEtaMin) / (kDielAlbedoEtaMax - kDielAlbedoEtaMin), kDielAlbedoEta, &key.k, &key.fk);
  diel_grid_coord(r, kDielAlbedoR, &key.j, &key.fr);
  return key;
}

/// Trilinear E(μ, r, e) (tab = kGGXDielectricAlbedo or ...AlbedoT).
KAURI_HOST_DEVICE inline Float diel_albedo(const float* tab, const DielAlbedoKey& key, Float mu) {
  int i;
  Float fu;
  diel_grid_coord(mu, kDielAlbedoMu, &i, &fu);
  const float* t = tab + key.side * kDielAlbedoSide;
  auto row = [&](int k, int j) {
    const float* p = t + (k * kDielAlbedoR + j) * kDielAlbedoMu + i;
    return lerp(fu, Float(p[0]), Float(p[1]));
  };
  Float a = lerp(key.fr, row(key.k, key.j), row(key.k, key.j + 1));
  Float b = lerp(key.fr, row(key.k + 1, key.j), row(key.k + 1, key.j + 1));
  return lerp(key.fk, a, b);
}

/// Bilinear E_avg(r, e) (tab = kGGXDielectricAlbedoAvg or ...TAvg).
KAURI_HOST_DEVICE inline Float diel_albedo_avg(const float* tab, const DielAlbedoKey& key) {
  const float* t = tab + key.side * kDielAlbedoAvgSide;
  auto at = [&](int k, int j) { return Float(t[k * kDielAlbedoR + j]); };
  Float a = lerp(key.fr, at(key.k, key.j), at(key.k, key.j + 1));
  Float b = lerp(key.fr, at(key.k + 1, key.j), at(key.k + 1, key.j + 1));
  return lerp(key.fk, a, b);
}

}  // namespace kauri
