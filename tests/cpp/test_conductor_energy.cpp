// Multiple-scattering energy compensation of the rough conductor (Kulla & Conty
// 2017), the directional-albedo tables (bsdf/albedo_tables.h), the Beckmann
// distribution (bsdf/microfacet.h) and the artist-friendly conductor Fresnel
// (Gulbrandsen 2014).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "chi2.h"
#include "lobe_test_util.h"
#include "kauri/bsdf/bsdf.h"

namespace kauri {
namespace {

using namespace test;

std::string fmt(double v) { return std::to_string(v); }

GGXConductorLobe conductor(Float ax, Float ay, MicrofacetType t, bool white, bool compensate = true) {
  GGXConductorLobe l;
  l.mf = {ax, ay, t};
  if (white) {  // F = 1 at every angle (test_bsdf.cpp checks this configuration)
    l.eta = SampledSpectrum(1);
    l.k = SampledSpectrum(1e4f);
  } else {  // gold-like, coloured
    l.eta = spectrum4(0.2f, 0.45f, 1.1f, 0.3f);
    l.k = spectrum4(3.5f, 2.4f, 1.9f, 3.0f);
  }
  l.compensate = compensate;
  return l;
}

Albedo mc_albedo(const GGXConductorLobe& lobe, Vec3 wo, uint64_t seed, int n) {
  return directional_albedo(lobe, wo, seed, n, TransportMode::Radiance, 7);
}

/// Fresh deterministic estimate of the single-scattering E(μ) (F = 1), by a finer
/// midpoint rule over the VNDF square than the generator's (odd count: other points).
double fresh_E(MicrofacetType t, double mu, double r, int q = 301) {
  MicrofacetDistribution mf;
  mf.alpha_x = mf.alpha_y = Float(r * r);
  mf.type = t;
  Vec3 wo{Float(std::sqrt(1 - mu * mu)), 0, Float(mu)};
  double g1 = mf.G1(wo), s = 0;
  for (int b = 0; b < q; ++b)
    for (int a = 0; a < q; ++a) {
      Vec3 wm = mf.sample_visible_normal(wo, Vec2{Float((a + 0.5) / q), Float((b + 0.5) / q)});
      Vec3 wi = reflect(wo, wm);
      if (wi.z > 0) s += double(mf.G(wo, wi)) / g1;
    }
  return s / (double(q) * q);
}

const MicrofacetType kTypes[] = {MicrofacetType::GGX, MicrofacetType::Beckmann};
const char* type_name(MicrofacetType t) { return t == MicrofacetType::GGX ? "ggx" : "beckmann"; }

// ------------------------------------------------------------ white furnace

TEST(ConductorEnergy, WhiteFurnaceKeepsEnergy) {
  uint64_t seed = 900;
  for (MicrofacetType t : kTypes)
    for (Float r : {1.0f, 0.5f, 0.1f})
      for (Float mu : {1.0f, 0.5f, 0.1f}) {
        Float a = r * r;
        Vec3 wo = dir(mu, 0.6f);
        Albedo w = mc_albedo(conductor(a, a, t, true), wo, seed++, 100000);
        std::string name = std::string(type_name(t)) + " r=" + fmt(r) + " mu=" + fmt(mu);
        EXPECT_GE(w.mean[0], 0.99 - 3 * w.sigma[0]) << name;
        EXPECT_LE(w.mean[0], 1.01 + 3 * w.sigma[0]) << name;
        ::testing::Test::RecordProperty("furnace " + name, fmt(w.mean[0]));
        std::cout << "furnace " << name << ": " << w.mean[0] << " +- " << w.sigma[0] << "\n";
      }
  // Anisotropic: r = (αx αy)^(1/4) for the lookup is an approximation (strong anisotropy
  // recovers only part of the loss); it must still help and never create energy.
  Vec3 wo = dir(0.5f, 0.6f);
  Albedo w = mc_albedo(conductor(0.1f, 0.8f, MicrofacetType::GGX, true), wo, 950, 100000);
  Albedo w1 = mc_albedo(conductor(0.1f, 0.8f, MicrofacetType::GGX, true, false), wo, 951, 100000);
  std::cout << "anisotropic ax=0.1 ay=0.8 mu=0.5: compensated " << w.mean[0] << ", single scattering " << w1.mean[0]
            << "\n";
  EXPECT_GT(w.mean[0], w1.mean[0]);
  EXPECT_LE(w.mean[0], 1.01 + 3 * w.sigma[0]);
}

TEST(ConductorEnergy, UncompensatedIsTheSingleScatteringLobe) {
  // compensate = false reproduces "@1": the tables' E (checked against test_bsdf.cpp's
  // scipy reference 0.30685 at α = 1, μ = 1).
  GGXConductorLobe l = conductor(1, 1, MicrofacetType::GGX, true, false);
  EXPECT_STREQ(l.name(), "ggx_conductor@1");
  EXPECT_STREQ(conductor(1, 1, MicrofacetType::GGX, true).name(), "ggx_conductor@2");
  Albedo w = mc_albedo(l, dir(1, 0), 960, 100000);
  EXPECT_NEAR(w.mean[0], 0.3068528, 5 * w.sigma[0] + 1e-3);
  EXPECT_NEAR(microfacet_albedo(MicrofacetType::GGX, 1, 1), 0.3068528, 1e-3);
}

// ------------------------------------------------------------ albedo_r

TEST(ConductorEnergy, AlbedoMatchesMonteCarlo) {
  uint64_t seed = 1000;
  for (MicrofacetType t : kTypes)
    for (bool white : {true, false})
      for (Float r : {0.3f, 0.7f, 1.0f})
        for (Float mu : {1.0f, 0.5f, 0.2f}) {
          GGXConductorLobe l = conductor(r * r, r * r, t, white);
          Vec3 wo = dir(mu, 0.3f);
          Albedo m = mc_albedo(l, wo, seed++, 100000);
          SampledSpectrum a = l.albedo_r(wo);
          for (int i = 0; i < kSpectrumSamples; ++i)
            EXPECT_NEAR(double(a[i]), m.mean[i], 0.02 * m.mean[i] + 3 * m.sigma[i])
                << type_name(t) << (white ? " white" : " gold") << " r=" << r << " mu=" << mu << " channel " << i;
        }
}

// ------------------------------------------------------------ sampling, reciprocity

void check_sampling(const GGXConductorLobe& lobe, Vec3 wo, const std::string& name, uint64_t seed) {
  SampledWavelengths lambda0 = SampledWavelengths::sample_visible(0.3f);
  int mismatch = 0;
  auto sample = [&](PCG32& rng, Vec3* w) {
    SampledWavelengths lambda = lambda0;
    Float uc = rng.next_float();
    BSDFSample s = lobe.sample(wo, uc, next_2d(rng), lambda, TransportMode::Radiance);
    if (!s.valid()) return false;
    *w = s.wi;
    Float p = lobe.pdf(wo, s.wi);
    if (std::fabs(s.pdf - p) > 1e-3f * p) ++mismatch;
    SampledSpectrum f = lobe.eval(wo, s.wi, TransportMode::Radiance);
    for (int i = 0; i < kSpectrumSamples; ++i)
      if (std::fabs(s.f[i] - f[i]) > 1e-3f * f[i]) ++mismatch;
    return true;
  };
  test::SphereChi2Config cfg;
  cfg.name = name;
  cfg.forced_cos = {0};
  cfg.seed = seed;
  cfg.samples = 400000;
  cfg.ncos = 30;
  cfg.nphi = 30;
  EXPECT_TRUE(test::sphere_chi2(sample, [&](Vec3 w) { return double(lobe.pdf(wo, w)); }, cfg));
  EXPECT_EQ(mismatch, 0) << name << ": sample() disagrees with eval()/pdf()";
}

// 5 chi-square tests (kChi2TestCount in chi2.h counts them).
TEST(ConductorEnergy, CompensatedSamplingMatchesPdf) {
  check_sampling(conductor(0.64f, 0.64f, MicrofacetType::GGX, false), dir(0.5f, 0.6f), "compensated ggx r=0.8", 1100);
  check_sampling(conductor(0.1f, 0.6f, MicrofacetType::GGX, false), dir(-0.3f, 0.6f),
                 "compensated ggx aniso, wo below", 1101);
  check_sampling(conductor(0.5f, 0.5f, MicrofacetType::Beckmann, false), dir(0.3f, 0.6f),
                 "compensated beckmann a=0.5", 1102);
}

TEST(Beckmann, VisibleNormalSamplingMatchesPdf) {
  check_sampling(conductor(0.2f, 0.2f, MicrofacetType::Beckmann, false, false), dir(0.1f, 0.6f),
                 "beckmann a=0.2 grazing", 1200);
  check_sampling(conductor(0.15f, 0.7f, MicrofacetType::Beckmann, false, false), dir(0.7f, 0.6f),
                 "beckmann aniso", 1201);
  // Normal and near-normal incidence: sin θ of the stretched direction came from
  // √(1 − cos²θ), which cancels there (slopes of a third of their variance at sin θ = 2e-4;
  // at ω = +z none at all where the CPU's rsqrt estimate rounds the normalised z below 1).
  check_sampling(conductor(0.5f, 0.5f, MicrofacetType::Beckmann, false, false), dir(1.0f, 0.0f),
                 "beckmann a=0.5 normal", 1202);
  check_sampling(conductor(0.5f, 0.5f, MicrofacetType::Beckmann, false, false), normalize(Vec3{2e-4f, 1e-4f, 1}),
                 "beckmann a=0.5 near-normal", 1203);
}

// GGX's visible normals by spherical caps (microfacet.h): the uncompensated lobe's sampled
// directions (reflections of the sampled normals) against its pdf, at grazing, oblique and
// normal incidence, isotropic and anisotropic, smooth and rough.
TEST(GGX, VisibleNormalSamplingMatchesPdf) {
  check_sampling(conductor(0.2f, 0.2f, MicrofacetType::GGX, false, false), dir(0.1f, 0.6f), "ggx a=0.2 grazing", 1210);
  check_sampling(conductor(0.15f, 0.7f, MicrofacetType::GGX, false, false), dir(0.7f, 0.6f), "ggx aniso", 1211);
  check_sampling(conductor(0.05f, 0.05f, MicrofacetType::GGX, false, false), dir(1.0f, 0.0f), "ggx a=0.05 normal",
                 1212);
  check_sampling(conductor(0.9f, 0.4f, MicrofacetType::GGX, false, false), dir(0.35f, 2.2f), "ggx rough aniso", 1213);
}

TEST(ConductorEnergy, CompensatedLobeIsReciprocal) {
  PCG32 rng(1300, 1);
  for (MicrofacetType t : kTypes)
    for (int k = 0; k < 2000; ++k) {
      Float ax = 0.05f + rng.next_float(), ay = 0.05f + rng.next_float();
      GGXConductorLobe l = conductor(ax, ay, t, false);
      Vec3 a = dir(0.02f + 0.98f * rng.next_float(), 6.28f * rng.next_float());
      Vec3 b = dir(0.02f + 0.98f * rng.next_float(), 6.28f * rng.next_float());
      SampledSpectrum fab = l.eval(a, b, TransportMode::Radiance), fba = l.eval(b, a, TransportMode::Radiance);
      for (int i = 0; i < kSpectrumSamples; ++i) ASSERT_NEAR(fab[i], fba[i], 1e-4f * fmax_(fab[i], 1e-3f));
    }
}

// ------------------------------------------------------------ Beckmann distribution

/// ∫ D(ω_m) cosθ_m dω_m = 1 and ∫ D_ωo(ω_m) dω_m = 1 (Smith Λ consistent with D).
TEST(Beckmann, Normalisation) {
  for (MicrofacetType t : kTypes)
    for (auto [ax, ay] : {std::pair{0.1f, 0.1f}, std::pair{0.5f, 0.5f}, std::pair{1.0f, 1.0f}, std::pair{0.1f, 0.6f}}) {
      MicrofacetDistribution mf{ax, ay, t};
      Vec3 wo = dir(0.4f, 0.7f);
      const int nt = 2000, np = 256;
      double s = 0, sv = 0;
      for (int i = 0; i < nt; ++i) {
        double th = (i + 0.5) / nt * test::kPiD / 2;
        for (int j = 0; j < np; ++j) {
          double ph = (j + 0.5) / np * 2 * test::kPiD;
          Vec3 m{Float(std::sin(th) * std::cos(ph)), Float(std::sin(th) * std::sin(ph)), Float(std::cos(th))};
          double dw = std::sin(th) * (test::kPiD / 2 / nt) * (2 * test::kPiD / np);
          s += double(mf.D(m)) * std::cos(th) * dw;
          if (dot(wo, m) > 0) sv += double(mf.D_visible(wo, m)) * dw;
        }
      }
      EXPECT_NEAR(s, 1, 2e-3) << type_name(t) << " ax=" << ax << " ay=" << ay;
      EXPECT_NEAR(sv, 1, 2e-3) << type_name(t) << " visible, ax=" << ax << " ay=" << ay;
    }
}

// ------------------------------------------------------------ tables

TEST(AlbedoTables, OffGridLookupsMatchFreshEstimate) {
  const double pts[][2] = {{0.37, 0.43}, {0.81, 0.77}, {0.15, 0.62}, {0.55, 0.2}, {0.93, 0.95}, {0.25, 0.9}};
  for (MicrofacetType t : kTypes)
    for (auto& p : pts) {
      double ref = fresh_E(t, p[0], p[1]);
      double tab = microfacet_albedo(t, Float(p[0]), Float(p[1]));
      EXPECT_NEAR(tab, ref, 5e-3) << type_name(t) << " mu=" << p[0] << " r=" << p[1];
    }
  // E_avg = 2 ∫ E μ dμ by 8-point Gauss–Legendre on fresh estimates, off-grid r.
  const double x[4] = {0.1834346425, 0.5255324099, 0.7966664774, 0.9602898565};
  const double w[4] = {0.3626837834, 0.3137066459, 0.2223810345, 0.1012285363};
  for (MicrofacetType t : kTypes)
    for (double r : {0.45, 0.83}) {
      double s = 0;
      for (int i = 0; i < 4; ++i)
        for (double mu : {(1 - x[i]) / 2, (1 + x[i]) / 2}) s += w[i] / 2 * fresh_E(t, mu, r, 151) * mu;
      EXPECT_NEAR(microfacet_albedo_avg(t, Float(r)), 2 * s, 5e-3) << type_name(t) << " r=" << r;
    }
}

// ------------------------------------------------------------ artist parameterisation

TEST(ArtistConductor, NormalIncidenceReflectivityIsR) {
  for (Float r : {0.0f, 0.04f, 0.3f, 0.5f, 0.8f, 0.95f, 0.99f})
    for (Float g : {0.0f, 0.3f, 0.7f, 1.0f}) {
      Float eta, k;
      artist_conductor_ior(r, g, &eta, &k);
      EXPECT_GE(eta, 0);
      EXPECT_GE(k, 0);
      EXPECT_NEAR(fresnel_conductor(1.0f, eta, k), r, 2e-4f) << "r=" << r << " g=" << g;
    }
  // Spectral overload and edge tint: more tint → brighter at 80° for the same r.
  SampledSpectrum eta, k;
  artist_conductor_ior(SampledSpectrum(0.6f), spectrum4(0, 0.3f, 0.6f, 0.9f), &eta, &k);
  for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_NEAR(fresnel_conductor(1.0f, eta[i], k[i]), 0.6f, 2e-4f);
  for (int i = 0; i + 1 < kSpectrumSamples; ++i)
    EXPECT_LT(fresnel_conductor(0.17f, eta[i], k[i]), fresnel_conductor(0.17f, eta[i + 1], k[i + 1]));
}

}  // namespace
}  // namespace kauri
