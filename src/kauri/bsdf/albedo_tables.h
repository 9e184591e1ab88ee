// Directional-albedo tables of the single-scattering microfacet reflection lobes
// with Fresnel = 1, for the multiple-scattering energy compensation of Kulla &
// Conty 2017 ("Revisiting Physically Based Shading at Imageworks", SIGGRAPH PBS
// course; see /work/shared/refs/layering.md §2):
//   E(μ_o, r) = ∫_H f_ss(ω_o, ω_i) μ_i dω_i,     E_avg(r) = 2 ∫_0^1 E(μ) μ dμ.
//
// Grid: kAlbedoTableSize = 32 nodes per axis, node i at μ = i/31 and r = j/31
// (perceptual roughness, α = r²); values are stored row-major [r][μ]. Nodes with
// α < 1e-3 (effectively smooth: a mirror) store 1. The μ = 0 nodes store the linear
// extrapolation of the μ = 1/31 and 2/31 nodes: the true E has a boundary layer at
// grazing (E → P(ω_i above horizon) as Λ(ω_o) → ∞) far narrower than a cell at small
// α, and interpolating towards that limit would bias the whole first cell.
//
// Generator: tools/gen_albedo_tables.cpp, which includes microfacet.h so the
// tables match the runtime model exactly. Integration: E(μ) = E_{ω_m ~ D_ωo}[G2/G1(ω_o)]
// (F = 1, VNDF importance sampling makes f μ_i / pdf = G2(ω_o, ω_i)/G1(ω_o), zero below
// the horizon), evaluated with the runtime's own sample_visible_normal() at the
// 512×512 midpoints of [0,1)² (deterministic, 2^18 points per node). E_avg by a
// 64-point Gauss–Legendre rule in μ with 256×256 midpoints per μ. Accuracy, by the
// generator's self-check against 2048×2048 midpoints: |ΔE| < 1e-4 at the nodes; the
// error at run time is dominated by bilinear interpolation (≲ 3e-3 near μ → 0 at low r,
// ≲ 5e-4 elsewhere; tests/cpp/test_conductor_energy.cpp checks off-grid points).
//
// The arrays live in data/albedo_tables.cpp (generated, committed). A CUDA build
// needs __device__/__constant__ copies of them; the lookups take the arrays through
// albedo_table()/albedo_avg_table() so that is a change in one place.
#pragma once

#include "kauri/bsdf/microfacet.h"

namespace kauri {

inline constexpr int kAlbedoTableSize = 32;

extern const float kGGXAlbedo[kAlbedoTableSize * kAlbedoTableSize];
extern const float kGGXAlbedoAvg[kAlbedoTableSize];
extern const float kBeckmannAlbedo[kAlbedoTableSize * kAlbedoTableSize];
extern const float kBeckmannAlbedoAvg[kAlbedoTableSize];

KAURI_HOST_DEVICE inline const float* albedo_table(MicrofacetType t) {
  return t == MicrofacetType::Beckmann ? kBeckmannAlbedo : kGGXAlbedo;
}
KAURI_HOST_DEVICE inline const float* albedo_avg_table(MicrofacetType t) {
  return t == MicrofacetType::Beckmann ? kBeckmannAlbedoAvg : kGGXAlbedoAvg;
}

/// Continuous grid coordinate of x ∈ [0,1] → (cell index, fraction).
KAURI_HOST_DEVICE inline void albedo_grid_coord(Float x, int* i, Float* f) {
  Float g = clamp(x, 0, 1) * Float(kAlbedoTableSize - 1);
  int k = int(g);
  if (k > kAlbedoTableSize - 2) k = kAlbedoTableSize - 2;
  *i = k;
  *f = g - Float(k);
}

/// E(μ, r): directional albedo (F = 1) of the single-scattering lobe, bilinear.
KAURI_HOST_DEVICE inline Float microfacet_albedo(MicrofacetType t, Float mu, Float r) {
  const float* tab = albedo_table(t);
  int i, j;
  Float fu, fr;
  albedo_grid_coord(mu, &i, &fu);
  albedo_grid_coord(r, &j, &fr);
  const int n = kAlbedoTableSize;
  Float a = lerp(fu, tab[j * n + i], tab[j * n + i + 1]);
  Float b = lerp(fu, tab[(j + 1) * n + i], tab[(j + 1) * n + i + 1]);
  return lerp(fr, a, b);
}

/// E_avg(r) = 2 ∫ E(μ) μ dμ, linear in r.
KAURI_HOST_DEVICE inline Float microfacet_albedo_avg(MicrofacetType t, Float r) {
  const float* tab = albedo_avg_table(t);
  int j;
  Float fr;
  albedo_grid_coord(r, &j, &fr);
  return lerp(fr, tab[j], tab[j + 1]);
}

}  // namespace kauri
