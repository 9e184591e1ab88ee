// Generates src/kauri/bsdf/data/dielectric_albedo_tables.cpp: directional albedos
// E(μ, r, e) (reflection + transmission) and E_T(μ, r, e) (transmission) of the
// single-scattering rough GGX dielectric lobe in importance transport, and their
// hemispherical averages (grid and use: src/kauri/bsdf/dielectric_albedo_tables.h).
//
// Build and run (from the repository root):
//   g++ -O2 -std=c++20 -pthread -I src tools/gen_dielectric_albedo_tables.cpp -o /tmp/gen_dielectric_albedo_tables
//   /tmp/gen_dielectric_albedo_tables > src/kauri/bsdf/data/dielectric_albedo_tables.cpp
// Deterministic (midpoint quadrature, no random numbers; threads split whole rows).
// Uses the runtime's microfacet.h and fresnel.h, so D, Λ, G, the VNDF sampler, the
// Fresnel term and refract() are the renderer's. Self-check to stderr and the header.
//
// Integrand: ω_m ~ D_ωo (VNDF). The lobe reflects with probability F(ω_o·ω_m) and
// refracts otherwise; with f from RoughDielectricLobe::eval_up (importance mode) the
// estimator f |μ_i| / pdf is G2(ω_o, ω_i)/G1(ω_o) for either branch (the Jacobians and
// D cancel, Walter et al. 2007 eqs. 14/17/20/21), so per ω_m
//   E  += F G2(ω_o, ω_r)/G1 [ω_r above]  +  (1 − F) G2(ω_o, ω_t)/G1 [ω_t below],
//   E_T += (1 − F) G2(ω_o, ω_t)/G1 [ω_t below]      (TIR: F = 1).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "kauri/bsdf/dielectric_albedo_tables.h"
#include "kauri/bsdf/fresnel.h"
#include "kauri/bsdf/microfacet.h"

using namespace kauri;

namespace {

constexpr int kMu = kDielAlbedoMu, kR = kDielAlbedoR, kEta = kDielAlbedoEta;
constexpr int kQuad = 256;  // midpoints per axis of the VNDF sample square

struct ET {
  double e, t;
};

ET albedo(const MicrofacetDistribution& mf, double mu, double e, int q) {
  mu = std::max(mu, 1e-4);
  if (mf.effectively_smooth()) {
    double F = fresnel_dielectric(Float(mu), Float(e));
    return {1.0, 1 - F};
  }
  Vec3 wo{Float(std::sqrt(1 - mu * mu)), 0, Float(mu)};
  const double g1 = double(mf.G1(wo));
  double se = 0, st = 0;
  for (int b = 0; b < q; ++b)
    for (int a = 0; a < q; ++a) {
      Vec2 u{Float((a + 0.5) / q), Float((b + 0.5) / q)};
      Vec3 wm = mf.sample_visible_normal(wo, u);
      Float dot_o = dot(wo, wm);
      if (!(dot_o > 0)) continue;
      double F = fresnel_dielectric(dot_o, Float(e));
      Vec3 wr = reflect(wo, wm);
      if (wr.z > 0) se += F * double(mf.G(wo, wr)) / g1;
      Vec3 wt;
      if (F < 1 && refract(wo, wm, Float(e), &wt) && wt.z < 0) {
        double v = (1 - F) * double(mf.G(wo, wt)) / g1;
        se += v;
        st += v;
      }
    }
  double n = double(q) * q;
  return {se / n, st / n};
}

MicrofacetDistribution dist(double r) {
  MicrofacetDistribution mf;
  mf.alpha_x = mf.alpha_y = Float(r * r);
  return mf;
}
double node_eta(int k) { return kDielAlbedoEtaMin + (kDielAlbedoEtaMax - kDielAlbedoEtaMin) * k / (kEta - 1); }
double side_e(int s, int k) { return s == 0 ? node_eta(k) : 1 / node_eta(k); }

/// 2 ∫_0^1 E(μ) μ dμ of the piecewise-linear interpolant of one row (what the runtime's
/// lookup integrates to, so the compensation restores exactly 1 − E of the table).
double avg_of_interpolant(const double* row) {
  double s = 0, h = 1.0 / (kMu - 1);
  for (int i = 0; i + 1 < kMu; ++i) {
    double m0 = i * h, m1 = (i + 1) * h, e0 = row[i], e1 = row[i + 1];
    double i1 = (m1 * m1 - m0 * m0) / 2;
    double i2 = (m1 * m1 * m1 - m0 * m0 * m0) / 3 - m0 * i1;
    s += e0 * i1 + (e1 - e0) / h * i2;
  }
  return 2 * s;
}

void emit(const char* name, const std::vector<double>& v, const char* size_expr) {
  std::printf("const float %s[%s] = {", name, size_expr);
  for (size_t i = 0; i < v.size(); ++i) {
    if (i % 8 == 0) std::printf("\n   ");
    std::printf(" %.7ff,", v[i]);
  }
  std::printf("\n};\n\n");
}

}  // namespace

int main() {
  const size_t n_rows = size_t(2 * kEta * kR);
  std::vector<double> E(n_rows * kMu), T(n_rows * kMu), Eavg(n_rows), Tavg(n_rows);
  auto do_row = [&](size_t row) {
    int s = int(row / (kEta * kR)), k = int(row / kR % kEta), j = int(row % kR);
    MicrofacetDistribution mf = dist(double(j) / (kR - 1));
    double e = side_e(s, k);
    double* re = &E[row * kMu];
    double* rt = &T[row * kMu];
    for (int i = 1; i < kMu; ++i) {
      ET a = albedo(mf, double(i) / (kMu - 1), e, kQuad);
      re[i] = std::min(a.e, 1.0);
      rt[i] = std::min(a.t, re[i]);
    }
    // μ = 0 node: linear extrapolation (see dielectric_albedo_tables.h).
    re[0] = std::clamp(2 * re[1] - re[2], 0.0, 1.0);
    rt[0] = std::clamp(2 * rt[1] - rt[2], 0.0, re[0]);
    Eavg[row] = avg_of_interpolant(re);
    Tavg[row] = avg_of_interpolant(rt);
  };
  unsigned nt = std::max(2u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < nt; ++t)
    pool.emplace_back([&, t] {
      for (size_t row = t; row < n_rows; row += nt) do_row(row);
    });
  for (auto& th : pool) th.join();

  // Self-check: nodes against a 4x finer rule.
  double max_err = 0;
  for (int s = 0; s < 2; ++s)
    for (int k : {0, 5, 15})
      for (int j : {1, 4, 10, 15})
        for (int i : {1, 6, 31}) {
          ET f = albedo(dist(double(j) / (kR - 1)), double(i) / (kMu - 1), side_e(s, k), 4 * kQuad);
          size_t idx = size_t((s * kEta + k) * kR + j) * kMu + size_t(i);
          double d = std::max(std::fabs(f.e - E[idx]), std::fabs(f.t - T[idx]));
          if (d > 2e-3) std::fprintf(stderr, "  s=%d k=%d j=%d i=%d: %.2e\n", s, k, j, i, d);
          max_err = std::max(max_err, d);
        }
  std::fprintf(stderr, "max |node - 4x finer rule| = %.2e\n", max_err);

  std::printf(
      "// GENERATED by tools/gen_dielectric_albedo_tables.cpp — do not edit; re-run the generator.\n"
      "//   g++ -O2 -std=c++20 -pthread -I src tools/gen_dielectric_albedo_tables.cpp -o /tmp/gen_dielectric_albedo_tables\n"
      "//   /tmp/gen_dielectric_albedo_tables > src/kauri/bsdf/data/dielectric_albedo_tables.cpp\n"
      "// Directional albedos E, E_T [side][eta][r][mu] and averages [side][eta][r] of the\n"
      "// single-scattering rough GGX dielectric (importance transport); grid and method:\n"
      "// dielectric_albedo_tables.h. Midpoint quadrature, %dx%d points per node over the VNDF\n"
      "// sample square; self-check max |node - 4x finer rule| = %.1e.\n"
      "#include \"kauri/bsdf/dielectric_albedo_tables.h\"\n\nnamespace kauri {\n\n",
      kQuad, kQuad, max_err);
  emit("kGGXDielectricAlbedo", E, "2 * kDielAlbedoSide");
  emit("kGGXDielectricAlbedoT", T, "2 * kDielAlbedoSide");
  emit("kGGXDielectricAlbedoAvg", Eavg, "2 * kDielAlbedoAvgSide");
  emit("kGGXDielectricAlbedoTAvg", Tavg, "2 * kDielAlbedoAvgSide");
  std::printf("}  // namespace kauri\n");
  return 0;
}
