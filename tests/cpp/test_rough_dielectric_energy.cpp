// Multiple-scattering energy compensation of the rough GGX dielectric (Kulla & Conty
// 2017 extended to refraction; rough_dielectric.h) and its tabulated albedos
// (bsdf/dielectric_albedo_tables.h): white furnace in importance transport, albedo_r /
// albedo_t against Monte Carlo, generalized reciprocity and chi-square of the sampler.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "chi2.h"
#include "lobe_test_util.h"
#include "kauri/bsdf/lobe.h"

namespace kauri {
namespace {

using namespace test;

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f", v);
  return b;
}

struct MC {
  double r, t, sigma;
};
/// Monte Carlo R and T (hero wavelength) with the lobe's own sampler.
MC mc_rt(const RoughDielectricLobe& l, Vec3 wo, uint64_t seed, int n, TransportMode mode) {
  PCG32 rng(seed, 11);
  double sr = 0, st = 0, s2 = 0;
  for (int k = 0; k < n; ++k) {
    SampledWavelengths lambda = test_wavelengths();
    Float uc = rng.next_float();
    BSDFSample s = l.sample(wo, uc, next_2d(rng), lambda, mode);
    if (!s.valid()) continue;
    double w = double(s.f[0]) * std::fabs(double(s.wi.z)) / double(s.pdf);
    (s.wi.z * wo.z > 0 ? sr : st) += w;
    s2 += w * w;
  }
  double m = (sr + st) / n;
  return {sr / n, st / n, std::sqrt(std::max(0.0, s2 / n - m * m) / n)};
}

TEST(RoughDielectricEnergy, WhiteFurnaceAndTabulatedAlbedo) {
  std::cout << "ggx_dielectric@2 importance R+T (uncompensated @1 in brackets), albedo_r/t table vs MC:\n";
  uint64_t seed = 5000;
  for (Float eta : {1.5f, 1 / 1.5f})
    for (Float r : {0.3f, 0.6f, 1.0f})
      for (Float mu : {1.0f, 0.5f, 0.2f})
        for (Float side : {1.0f, -1.0f}) {
          const Float a = r * r;
          auto l = RoughDielectricLobe::make(SampledSpectrum(eta), a, a);
          auto l1 = RoughDielectricLobe::make(SampledSpectrum(eta), a, a, false);
          ASSERT_STREQ(Lobe(l).name(), "ggx_dielectric@2");
          ASSERT_STREQ(Lobe(l1).name(), "ggx_dielectric@1");
          const Vec3 wo = dir(side * mu, 0.4f);
          MC m = mc_rt(l, wo, seed++, 200000, TransportMode::Importance);
          MC m1 = mc_rt(l1, wo, seed++, 50000, TransportMode::Importance);
          const double ar = double(l.albedo_r(wo)[0]), at = double(l.albedo_t(wo)[0]);
          const double ar1 = double(l1.albedo_r(wo)[0]), at1 = double(l1.albedo_t(wo)[0]);
          const std::string name = "eta=" + fmt(eta) + " r=" + fmt(r) + " cos_o=" + fmt(side * mu);
          std::cout << "  " << name << ": R+T " << fmt(m.r + m.t) << " ± " << fmt(m.sigma) << " [" << fmt(m1.r + m1.t)
                    << "]; R " << fmt(m.r) << " vs " << fmt(ar) << ", T " << fmt(m.t) << " vs " << fmt(at) << " [T "
                    << fmt(m1.t) << " vs " << fmt(at1) << "]\n";
          EXPECT_GE(m.r + m.t, 0.99) << name;
          EXPECT_LE(m.r + m.t, 1.01) << name;
          EXPECT_NEAR(ar, m.r, 0.025) << name;
          EXPECT_NEAR(at, m.t, 0.025) << name;
          EXPECT_NEAR(ar1, m1.r, 0.025) << name;
          EXPECT_NEAR(at1, m1.t, 0.025) << name;
        }
}

TEST(RoughDielectricEnergy, EnergyAtAlphaOneAllAngles) {
  // Roughness 1 (α = 1), a sweep of angles and IORs, both sides.
  uint64_t seed = 5200;
  for (Float eta : {1.33f, 1.5f, 2.4f, 1 / 1.5f})
    for (Float c : {0.95f, 0.7f, 0.35f, 0.1f, -0.1f, -0.35f, -0.7f, -0.95f}) {
      auto l = RoughDielectricLobe::make(SampledSpectrum(eta), 1.0f, 1.0f);
      MC m = mc_rt(l, dir(c, 1.1f), seed++, 100000, TransportMode::Importance);
      EXPECT_GE(m.r + m.t, 0.99) << eta << " " << c;
      EXPECT_LE(m.r + m.t, 1.01) << eta << " " << c;
    }
}

TEST(RoughDielectricEnergy, CompensationIsReciprocal) {
  // Importance: f(ω_o, ω_i)/η_i² = f(ω_i, ω_o)/η_o², including f_ms,T's η² relation.
  PCG32 rng(5300, 1);
  for (Float eta : {1.5f, 1 / 1.5f, 2.4f})
    for (Float a : {0.3f, 1.0f}) {
      auto l = RoughDielectricLobe::make(SampledSpectrum(eta), a, a);
      int n = 0;
      for (int k = 0; k < 4000; ++k) {
        Vec3 x = sample_uniform_sphere(next_2d(rng)), y = sample_uniform_sphere(next_2d(rng));
        const double fms_xy = double(l.eval(x, y, TransportMode::Importance)[0]);
        const double fms_yx = double(l.eval(y, x, TransportMode::Importance)[0]);
        auto side = [&](Vec3 w) { return w.z > 0 ? 1.0 : double(eta); };
        // Compare the compensation parts alone (the single-scattering part has its own test).
        auto l1 = RoughDielectricLobe::make(SampledSpectrum(eta), a, a, false);
        const double xy = fms_xy - double(l1.eval(x, y, TransportMode::Importance)[0]);
        const double yx = fms_yx - double(l1.eval(y, x, TransportMode::Importance)[0]);
        if (xy <= 1e-6) continue;
        ++n;
        EXPECT_NEAR(xy / std::pow(side(y), 2), yx / std::pow(side(x), 2), 1e-3 * xy) << eta << " " << a;
      }
      EXPECT_GT(n, 3000);
    }
}

TEST(RoughDielectricEnergy, SamplingChi2) {
  struct Case {
    Float eta, ax, ay, cos_o;
  };
  const Case cases[] = {{1.5f, 1.0f, 1.0f, 0.6f}, {1.5f, 0.36f, 0.36f, -0.5f}, {1 / 1.5f, 1.0f, 1.0f, 0.3f},
                        {1.5f, 0.1f, 0.4f, 0.6f}};
  uint64_t seed = 5400;
  for (const Case& c : cases) {
    auto l = RoughDielectricLobe::make(SampledSpectrum(c.eta), c.ax, c.ay);
    const Vec3 wo = dir(c.cos_o, 0.6f);
    int f_mismatch = 0, pdf_mismatch = 0;
    auto sample = [&](PCG32& r, Vec3* w) {
      SampledWavelengths lambda = test_wavelengths();
      Float uc = r.next_float();
      BSDFSample s = l.sample(wo, uc, next_2d(r), lambda, TransportMode::Radiance);
      if (!s.valid()) return false;
      *w = s.wi;
      const double p = double(l.pdf(wo, s.wi)), f = double(l.eval(wo, s.wi, TransportMode::Radiance)[0]);
      if (std::fabs(double(s.pdf) - p) > 1e-3 * p) ++pdf_mismatch;
      if (std::fabs(double(s.f[0]) - f) > 1e-3 * f) ++f_mismatch;
      return true;
    };
    SphereChi2Config cfg;
    cfg.name = "ggx_dielectric@2 eta=" + fmt(c.eta) + " ax=" + fmt(c.ax) + " ay=" + fmt(c.ay) + " cos_o=" + fmt(c.cos_o);
    cfg.forced_cos = {0};
    cfg.seed = seed++;
    cfg.samples = 300000;
    cfg.pilot = 20000;
    EXPECT_TRUE(sphere_chi2(sample, [&](Vec3 w) { return double(l.pdf(wo, w)); }, cfg));
    EXPECT_EQ(f_mismatch, 0) << cfg.name;
    EXPECT_EQ(pdf_mismatch, 0) << cfg.name;
  }
}

}  // namespace
}  // namespace kauri
