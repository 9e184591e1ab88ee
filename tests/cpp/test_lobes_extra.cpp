// Statistical tests of the extra BSDF lobes: diffuse transmission, rough (GGX)
// dielectric, thin dielectric and sheen. Sampling against the lobes' own
// densities (chi-square over the sphere), sample() against eval()/pdf(),
// energy (Monte Carlo directional albedo), reciprocity, and per-lobe closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "chi2.h"
#include "lobe_sampling_check.h"
#include "lobe_test_util.h"
#include "kauri/bsdf/lobe.h"
#include "kauri/bsdf/oren_nayar.h"

namespace kauri {
namespace {

using test::SphereChi2Config;

using test::Albedo;
using test::dir;
using test::directional_albedo;
using test::fmt;
using test::next_2d;
using test::rel_close;
using test::spectrum4;
using test::test_wavelengths;

/// This file's lobes: 300k samples with a 20k pilot (their densities are smooth).
template <class L>
void check_extra_lobe_sampling(const L& lobe, Vec3 wo, const std::string& name, uint64_t seed) {
  test::check_lobe_sampling(lobe, wo, name, seed, {300000, 20000});
}

bool no_skip(Vec3, Vec3) { return false; }

/// f(a,b) vs f(b,a) · k(a,b) over random pairs; returns the number of non-zero pairs.
/// `skip(a, b)`: pairs excluded as ill-conditioned in single precision.
template <class L, class Factor, class Skip>
int check_reciprocity(const L& lobe, TransportMode mode, uint64_t seed, const Factor& factor, const std::string& name,
                      const Skip& skip) {
  PCG32 rng(seed, 1);
  int nonzero = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 a = sample_uniform_sphere(next_2d(rng)), b = sample_uniform_sphere(next_2d(rng));
    if (k % 2) b.z = std::copysign(b.z, a.z);  // half the pairs in the same hemisphere
    if (skip(a, b)) continue;
    SampledSpectrum fab = lobe.eval(a, b, mode), fba = lobe.eval(b, a, mode);
    for (int i = 0; i < kSpectrumSamples; ++i) {
      double lhs = double(fab[i]), rhs = double(fba[i]) * factor(a, b, i);
      EXPECT_TRUE(rel_close(lhs, rhs, 2e-3) || std::fabs(lhs - rhs) < 1e-30)
          << name << " a=(" << a.x << "," << a.y << "," << a.z << ") b=(" << b.x << "," << b.y << "," << b.z
          << ") f(a,b) = " << lhs << ", f(b,a)·k = " << rhs;
      if (!rel_close(lhs, rhs, 2e-3) && std::fabs(lhs - rhs) >= 1e-30) return nonzero;
    }
    if (!fab.is_black()) ++nonzero;
  }
  return nonzero;
}

// ================================================================ diffuse transmission

TEST(DiffuseTransmissionLobe, SamplingMatchesPdf) {
  auto l = DiffuseTransmissionLobe::make(spectrum4(0.2f, 0.5f, 0.8f, 1.0f));
  check_extra_lobe_sampling(l, dir(0.6f, 0.3f), "diffuse_transmission wo above", 1100);
  check_extra_lobe_sampling(l, dir(-0.4f, 2.0f), "diffuse_transmission wo below", 1101);
  check_extra_lobe_sampling(l, dir(0.02f, 1.0f), "diffuse_transmission wo grazing", 1102);
}

TEST(DiffuseTransmissionLobe, AlbedoIsTauAndReciprocal) {
  SampledSpectrum tau = spectrum4(0.2f, 0.5f, 0.8f, 1.0f);
  auto l = DiffuseTransmissionLobe::make(tau);
  for (Vec3 wo : {dir(1, 0), dir(0.3f, 1), dir(-0.8f, 2), dir(0.01f, 3)}) {
    Albedo a = directional_albedo(l, wo, 1200, 50000);
    for (int i = 0; i < kSpectrumSamples; ++i) {
      EXPECT_NEAR(a.mean[i], double(tau[i]), 1e-5 * double(tau[i]));
      EXPECT_EQ(l.albedo_t(wo)[i], tau[i]);
      EXPECT_EQ(l.albedo_r(wo)[i], 0);
    }
    EXPECT_NEAR(a.mean_t, double(tau[0]), 1e-5);  // all of it is transmitted
  }
  // Nothing on the incident side.
  EXPECT_TRUE(l.eval(dir(0.5f, 0), dir(0.5f, 2), TransportMode::Radiance).is_black());
  EXPECT_EQ(l.pdf(dir(-0.5f, 0), dir(-0.5f, 2)), 0);
  for (TransportMode m : {TransportMode::Radiance, TransportMode::Importance}) {
    int n = check_reciprocity(l, m, 1201, [](Vec3, Vec3, int) { return 1.0; }, "diffuse_transmission", no_skip);
    EXPECT_GT(n, 4000);
  }
  EXPECT_EQ(l.ior(0), 0);
}

// ================================================================ rough dielectric

struct RDCase {
  Float eta, ax, ay, cos_o;
};

std::string rd_name(const RDCase& c) {
  return "ggx_dielectric eta=" + fmt(double(c.eta)) + " ax=" + fmt(double(c.ax)) + " ay=" + fmt(double(c.ay)) +
         " cos_o=" + fmt(double(c.cos_o));
}

std::vector<RDCase> rd_cases() {
  std::vector<RDCase> cases;
  for (Float eta : {1.5f, 1 / 1.5f})
    for (Float a : {0.5f, 0.05f}) {
      for (Float c : {1.0f, 0.70710678f, 0.1f}) cases.push_back({eta, a, a, c});  // wo above
      cases.push_back({eta, a, a, -0.70710678f});                                 // wo below
    }
  cases.push_back({1.5f, 0.5f, 0.5f, -0.1f});   // grazing from inside (mostly TIR)
  cases.push_back({1.5f, 0.1f, 0.4f, 0.6f});    // anisotropic
  cases.push_back({1.33f, 0.2f, 0.2f, -0.9f});  // water, from below
  return cases;
}

TEST(RoughDielectricLobe, SamplingMatchesPdf) {
  uint64_t seed = 1300;
  for (const RDCase& c : rd_cases()) {
    auto l = RoughDielectricLobe::make(SampledSpectrum(c.eta), c.ax, c.ay);
    ASSERT_EQ(l.scattering(), Scattering::Glossy);
    check_extra_lobe_sampling(l, dir(c.cos_o, 0.6f), rd_name(c), seed++);
  }
}

SampledSpectrum cauchy_eta(const SampledWavelengths& lambda) {
  CauchyIOR ior = CauchyIOR::from_abbe(1.5f, 20);
  SampledSpectrum eta;
  for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda.lambda[i]);
  return eta;
}

TEST(RoughDielectricLobe, Dispersion) {
  const SampledWavelengths lambda0 = test_wavelengths();
  auto l = RoughDielectricLobe::make(cauchy_eta(lambda0), 0.3f, 0.3f);
  ASSERT_TRUE(l.dispersive());
  Vec3 wo = dir(0.8f, 0.4f);
  // Sampling follows the hero: chi-square of the hero's density (also checks sample().f = eval() for the hero).
  check_extra_lobe_sampling(l, wo, "ggx_dielectric dispersive (Cauchy, Abbe 20) alpha=0.3", 1390);
  PCG32 rng(1391, 1);
  int transmitted = 0;
  for (int k = 0; k < 2000; ++k) {
    SampledWavelengths lambda = lambda0;
    BSDFSample s = l.sample(wo, rng.next_float(), next_2d(rng), lambda, TransportMode::Radiance);
    if (!s.valid()) continue;
    ASSERT_TRUE(lambda.secondary_terminated());
    EXPECT_FLOAT_EQ(lambda.pdf[0], lambda0.pdf[0] / kSpectrumSamples);
    if (!s.transmission) continue;
    ++transmitted;
    EXPECT_NEAR(s.eta, l.eta[0], 1e-6);
    // eval() gives every wavelength its own generalized half-vector: the values differ.
    SampledSpectrum f = l.eval(wo, s.wi, TransportMode::Radiance);
    EXPECT_NE(f[0], f[2]);
  }
  EXPECT_GT(transmitted, 1000);
  // A non-dispersive lobe leaves the wavelengths alone.
  auto plain = RoughDielectricLobe::make(SampledSpectrum(1.5f), 0.3f, 0.3f);
  SampledWavelengths keep = lambda0;
  plain.sample(wo, 0.9f, {0.3f, 0.6f}, keep, TransportMode::Radiance);
  EXPECT_FALSE(keep.secondary_terminated());
}

/// η of the medium on the side of w (outside: 1, inside: eta).
double side_eta(Vec3 w, double eta) { return w.z > 0 ? 1.0 : eta; }

TEST(RoughDielectricLobe, EnergyConservation) {
  // Importance transport conserves energy: R + T ≤ 1. Radiance transport scales T by
  // (η_o/η_i)², checked sample by sample against importance.
  std::cout << "ggx_dielectric directional albedo (importance; R+T, T):\n";
  uint64_t seed = 1400;
  for (const RDCase& c : rd_cases()) {
    // Single-scattering lobe (R + T ≤ 1 strictly); the compensated one: test_rough_dielectric_energy.cpp.
    auto l = RoughDielectricLobe::make(SampledSpectrum(c.eta), c.ax, c.ay, false);
    Vec3 wo = dir(c.cos_o, 0.6f);
    Albedo a = directional_albedo(l, wo, seed++, 100000, TransportMode::Importance);
    std::cout << "  " << rd_name(c) << ": " << fmt(a.mean[0]) << " ± " << fmt(a.sigma[0], 2) << ", T "
              << fmt(a.mean_t) << " (approx. albedo_r+t = " << fmt((l.albedo_r(wo) + l.albedo_t(wo))[0])
              << ", albedo_t " << fmt(l.albedo_t(wo)[0]) << ")\n";
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_LE(a.mean[i], 1 + 3 * a.sigma[i]) << rd_name(c);
    // Sharp, near-normal incidence: almost nothing is lost to masking.
    if (c.ax == 0.05f && std::fabs(c.cos_o) > 0.7f) {
      EXPECT_GE(a.mean[0], 0.97) << rd_name(c);
    }
    // The approximate albedo_t is within 0.1 of the true transmitted fraction where little energy is lost.
    if (c.ax <= 0.2f && std::fabs(c.cos_o) > 0.5f) {
      EXPECT_NEAR(a.mean_t, double(l.albedo_t(wo)[0]), 0.1) << rd_name(c);
    }
    // Radiance vs importance, sample by sample.
    PCG32 rng(seed++, 7);
    for (int k = 0; k < 2000; ++k) {
      SampledWavelengths l1 = test_wavelengths(), l2 = l1;
      Float uc = rng.next_float();
      Vec2 u = next_2d(rng);
      BSDFSample si = l.sample(wo, uc, u, l1, TransportMode::Importance);
      BSDFSample sr = l.sample(wo, uc, u, l2, TransportMode::Radiance);
      ASSERT_EQ(si.valid(), sr.valid());
      if (!si.valid()) continue;
      double k2 = si.transmission ? 1 / (double(si.eta) * double(si.eta)) : 1.0;
      EXPECT_TRUE(rel_close(double(sr.f[0]), double(si.f[0]) * k2, 1e-5)) << rd_name(c);
      if (si.transmission) {
        EXPECT_NEAR(double(si.eta), side_eta(si.wi, c.eta) / side_eta(wo, c.eta), 1e-6);
      }
    }
  }
}

TEST(RoughDielectricLobe, GeneralizedReciprocity) {
  // Importance mode: f(ω_o, ω_i)/η_i² = f(ω_i, ω_o)/η_o² (Veach 1997, §5.2), η of each direction's side.
  for (Float eta : {1.5f, 1 / 1.5f, 2.4f})
    for (Float a : {0.05f, 0.3f, 1.0f}) {
      auto l = RoughDielectricLobe::make(SampledSpectrum(eta), a, a * 0.7f);
      const double e = double(eta);
      int n = check_reciprocity(
          l, TransportMode::Importance, 1500,
          [&](Vec3 wo, Vec3 wi, int) { return std::pow(side_eta(wi, e) / side_eta(wo, e), 2); },
          "ggx_dielectric importance eta=" + fmt(e) + " alpha=" + fmt(double(a)), [&](Vec3 x, Vec3 y) {
            // Near-grazing on the microfacet (|ω·ω_m| < 0.05) 1 − F is a difference of nearly equal
            // numbers and the two evaluation orders differ by up to a few % in single precision.
            Vec3 xu = x.z > 0 ? x : -x, yu = x.z > 0 ? y : -y, wm;
            if (!RoughDielectricLobe::half_vector(xu, yu, RoughDielectricLobe::relative_eta(eta, x.z > 0), &wm))
              return false;
            return std::fabs(dot(xu, wm)) < 0.05f || std::fabs(dot(yu, wm)) < 0.05f;
          });
      EXPECT_GT(n, 2500) << eta << " " << a;
      // Radiance mode: f_rad(ω_o, ω_i) = f_imp(ω_o, ω_i)·(η_o/η_i)² (Veach 1997, eq. 5.19).
      PCG32 rng(1501, 2);
      for (int k = 0; k < 2000; ++k) {
        Vec3 x = sample_uniform_sphere(next_2d(rng)), y = sample_uniform_sphere(next_2d(rng));
        double fi = double(l.eval(x, y, TransportMode::Importance)[0]);
        double fr = double(l.eval(x, y, TransportMode::Radiance)[0]);
        double k2 = std::pow(side_eta(x, e) / side_eta(y, e), 2);
        EXPECT_TRUE(rel_close(fr, fi * k2, 1e-4) || std::fabs(fr - fi * k2) < 1e-30);
      }
    }
}

TEST(RoughDielectricLobe, SmoothLimitIsSpecular) {
  auto rough = RoughDielectricLobe::make(SampledSpectrum(1.5f), 1e-4f, 1e-4f);
  SmoothDielectricLobe smooth;
  smooth.eta = SampledSpectrum(1.5f);
  EXPECT_EQ(rough.scattering(), Scattering::Specular);
  EXPECT_EQ(Lobe(rough).scattering(), Scattering::Specular);
  for (Float cos_o : {0.9f, 0.3f, -0.5f, -0.9f})
    for (Float uc : {0.01f, 0.5f, 0.99f}) {
      Vec3 wo = dir(cos_o, 0.7f);
      SampledWavelengths l1 = test_wavelengths(), l2 = l1;
      BSDFSample a = rough.sample(wo, uc, {0.2f, 0.8f}, l1, TransportMode::Radiance);
      BSDFSample b = smooth.sample(wo, uc, {0.2f, 0.8f}, l2, TransportMode::Radiance);
      ASSERT_TRUE(a.valid());
      EXPECT_TRUE(a.is_specular());
      EXPECT_EQ(a.transmission, b.transmission);
      EXPECT_EQ(a.pdf, b.pdf);
      EXPECT_EQ(a.wi.x, b.wi.x);
      EXPECT_EQ(a.wi.z, b.wi.z);
      EXPECT_EQ(a.f[0], b.f[0]);
      EXPECT_EQ(rough.pdf(wo, a.wi), 0);
      EXPECT_TRUE(rough.eval(wo, a.wi, TransportMode::Radiance).is_black());
    }
}

// ================================================================ thin dielectric

TEST(ThinDielectricLobe, ReflectanceSumsToOneAndClosedForm) {
  for (Float eta : {1.0f, 1.33f, 1.5f, 2.4f, 4.0f})
    for (int k = -100; k <= 100; ++k) {
      Float c = Float(k) / 100;
      if (c == 0) c = 1e-4f;
      auto l = ThinDielectricLobe::make(spectrum4(eta, 1.2f, 1.7f, 3.0f));
      Vec3 wo = dir(c, 0.3f);
      SampledSpectrum r = l.albedo_r(wo), t = l.albedo_t(wo);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        EXPECT_EQ(r[i] + t[i], 1.0f) << "eta " << eta << " cos " << c;  // exactly
        EXPECT_GE(r[i], 0);
        EXPECT_GE(t[i], 0);
      }
      // Without absorption R' = R + T²R/(1 − R²) simplifies to 2R/(1 + R).
      double R = double(fresnel_dielectric(std::fabs(c), eta));
      EXPECT_NEAR(double(r[0]), 2 * R / (1 + R), 1e-6);
      // The sheet reflects at least as much as one interface, and R'(θ) is the same from both sides.
      EXPECT_GE(double(r[0]) + 1e-7, R);
      EXPECT_EQ(r[0], l.albedo_r(dir(-c, 0.3f))[0]);
    }
  EXPECT_EQ(ThinDielectricLobe::make(SampledSpectrum(1.5f)).ior(0), 0);
}

TEST(ThinDielectricLobe, SamplingFrequenciesAndWeights) {
  // A delta lobe has no density to bin over the sphere: the chi-square test is over
  // its two discrete outcomes (reflect, pass through) against the claimed probabilities.
  auto l = ThinDielectricLobe::make(spectrum4(1.5f, 1.45f, 1.6f, 2.0f));
  uint64_t seed = 1600;
  for (Float cos_o : {1.0f, 0.3f, -0.2f}) {
    Vec3 wo = dir(cos_o, 1.1f);
    const SampledWavelengths lambda0 = test_wavelengths();
    const SampledSpectrum R = l.albedo_r(wo);
    double P = 0;
    int bad = 0;
    double sum[kSpectrumSamples] = {};
    const int n = 100000;
    auto sample = [&](PCG32& rng, double* x, double* y) {
      SampledWavelengths lambda = lambda0;
      BSDFSample s = l.sample(wo, rng.next_float(), next_2d(rng), lambda, TransportMode::Radiance);
      if (!s.valid()) return false;
      if (!s.is_specular() || lambda.secondary_terminated()) ++bad;
      if (s.transmission) {
        if (!(s.wi.x == -wo.x && s.wi.y == -wo.y && s.wi.z == -wo.z)) ++bad;
      } else {
        if (!(s.wi.x == -wo.x && s.wi.y == -wo.y && s.wi.z == wo.z)) ++bad;
        P = double(s.pdf);
      }
      for (int i = 0; i < kSpectrumSamples; ++i) sum[i] += double(s.f[i]) * std::fabs(double(s.wi.z)) / double(s.pdf);
      *x = s.transmission ? 0.75 : 0.25;
      *y = 0.5;
      return true;
    };
    const double Pexp = double(R.average());
    test::RectChi2Config cfg("thin_dielectric reflect/transmit cos_o=" + fmt(double(cos_o)), 0, 1, 0, 1, 2, 1, n,
                             seed++);
    EXPECT_TRUE(test::rect_chi2(sample, [&](double x, double) { return x < 0.5 ? 2 * Pexp : 2 * (1 - Pexp); }, cfg));
    EXPECT_EQ(bad, 0);
    EXPECT_NEAR(P, Pexp, 1e-7);
    // E[f |cos| / pdf] = R' + T' = 1 per wavelength (weights R'/P and T'/(1 − P)).
    for (int i = 0; i < kSpectrumSamples; ++i) {
      double wr = double(R[i]) / Pexp, wt = (1 - double(R[i])) / (1 - Pexp);
      double sd = std::fabs(wr - wt) * std::sqrt(Pexp * (1 - Pexp) / n);
      EXPECT_NEAR(sum[i] / n, 1, 5 * sd + 1e-5) << "cos_o " << cos_o << " i " << i;
    }
  }
}

// ================================================================ sheen

TEST(SheenLobe, SamplingMatchesPdf) {
  uint64_t seed = 1700;
  for (Float r : {0.05f, 0.3f, 1.0f})
    check_extra_lobe_sampling(SheenLobe::make(spectrum4(1, 0.8f, 0.5f, 0.2f), r), dir(0.7f, 0.5f),
                        "sheen r=" + fmt(double(r)), seed++);
  check_extra_lobe_sampling(SheenLobe::make(SampledSpectrum(1), 0.4f), dir(-0.2f, 2.5f), "sheen r=0.4 wo below", seed++);
}

TEST(SheenLobe, EnergyBoundedAndTabulatedAlbedo) {
  std::cout << "sheen directional albedo (white): MC vs table\n";
  uint64_t seed = 1800;
  double worst = 0;
  for (Float r : {0.05f, 0.08f, 0.15f, 0.3f, 0.62f, 1.0f})
    for (Float c : {1.0f, 0.5f, 0.1f, 0.02f, 0.001f, -0.3f}) {
      auto l = SheenLobe::make(SampledSpectrum(1), r);
      Vec3 wo = dir(c, 0.2f);
      Albedo a = directional_albedo(l, wo, seed++, 40000);
      const double tab = double(l.albedo_r(wo)[0]);
      worst = std::max(worst, a.mean[0]);
      std::cout << "  r=" << r << " cos_o=" << c << ": " << fmt(a.mean[0]) << " ± " << fmt(a.sigma[0], 2)
                << " (table " << fmt(tab) << ")\n";
      EXPECT_LE(a.mean[0], 1 + 3 * a.sigma[0]) << "r " << r << " cos " << c;
      EXPECT_LE(tab, 0.995 + 1e-6);
      EXPECT_NEAR(a.mean[0], tab, 5 * a.sigma[0] + 0.02) << "r " << r << " cos " << c;
      EXPECT_TRUE(l.albedo_t(wo).is_black());
    }
  std::cout << "  largest: " << fmt(worst) << "\n";
}

TEST(SheenLobe, Reciprocity) {
  for (Float r : {0.05f, 0.3f, 1.0f}) {
    auto l = SheenLobe::make(spectrum4(1, 0.8f, 0.5f, 0.2f), r);
    int n = check_reciprocity(l, TransportMode::Radiance, 1900, [](Vec3, Vec3, int) { return 1.0; }, "sheen", no_skip);
    EXPECT_GT(n, 5000);
  }
}

// ================================================================ Lobe dispatch

TEST(LobeUnion, ExtraLobesDispatch) {
  const SampledWavelengths lambda0 = test_wavelengths();
  std::vector<Lobe> lobes = {Lobe(DiffuseTransmissionLobe::make(SampledSpectrum(0.5f))),
                             Lobe(RoughDielectricLobe::make(SampledSpectrum(1.5f), 0.3f, 0.3f)),
                             Lobe(ThinDielectricLobe::make(SampledSpectrum(1.5f))),
                             Lobe(SheenLobe::make(SampledSpectrum(0.5f), 0.4f))};
  const char* names[] = {"diffuse_transmission@1", "ggx_dielectric@2", "thin_dielectric@1", "sheen@1"};
  const LobeClass classes[] = {LobeClass::BTDF, LobeClass::BSDF, LobeClass::BSDF, LobeClass::BRDF};
  const Scattering scat[] = {Scattering::Diffuse, Scattering::Glossy, Scattering::Specular, Scattering::Diffuse};
  for (size_t k = 0; k < lobes.size(); ++k) {
    EXPECT_STREQ(lobes[k].name(), names[k]);
    EXPECT_EQ(lobes[k].lobe_class(), classes[k]);
    EXPECT_EQ(lobes[k].scattering(), scat[k]);
    EXPECT_GE(lobes[k].roughness(), 0);
    EXPECT_LE(lobes[k].roughness(), 1);
    SampledWavelengths lambda = lambda0;
    Vec3 wo = dir(0.6f, 0.3f);
    BSDFSample s = lobes[k].sample(wo, 0.7f, {0.4f, 0.6f}, lambda, TransportMode::Radiance);
    EXPECT_TRUE(s.valid()) << names[k];
    if (!s.is_specular()) {
      EXPECT_TRUE(rel_close(double(s.pdf), double(lobes[k].pdf(wo, s.wi)), 1e-5)) << names[k];
    }
    SampledSpectrum a = lobes[k].albedo_r(wo) + lobes[k].albedo_t(wo);
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_LE(a[i], 1.0f) << names[k];
  }
}

// ================================================================ near-normal incidence

// Every extra lobe at a direction a float ulp off the normal, as normalize() leaves +z on a
// CPU whose rsqrt estimate rounds it below 1, and at one with a small tangential part
// (sin θ ≈ 2e-4), where √(1 − cos²θ) cancels: Beckmann's visible-normal sampling took its
// azimuth from that difference and sampled the wrong lobe there (test_conductor_energy.cpp).
// 14 chi-square tests (kChi2TestCount in chi2.h counts them).
TEST(ExtraLobes, SamplingMatchesPdfNearNormalIncidence) {
  const Vec3 ulp_off{0, 0, 1 - 0x1p-24f}, tilted = normalize(Vec3{2e-4f, 1e-4f, 1});
  uint64_t seed = 1900;
  for (Vec3 wo : {ulp_off, tilted}) {
    const std::string at = wo.x == 0 ? " wo ulp off +z" : " wo sin(theta)=2.2e-4";
    check_extra_lobe_sampling(SheenLobe::make(SampledSpectrum(1), 0.3f), wo, "sheen r=0.3" + at, seed++);
    check_extra_lobe_sampling(SheenLobe::make(SampledSpectrum(1), 1.0f), wo, "sheen r=1" + at, seed++);
    check_extra_lobe_sampling(DiffuseTransmissionLobe::make(SampledSpectrum(0.7f)), wo, "diffuse_transmission" + at,
                              seed++);
    check_extra_lobe_sampling(RoughDielectricLobe::make(SampledSpectrum(1.5f), 0.5f, 0.5f), wo,
                              "ggx_dielectric eta=1.5 a=0.5" + at, seed++);
    check_extra_lobe_sampling(RoughDielectricLobe::make(SampledSpectrum(1.5f), 0.1f, 0.4f), wo,
                              "ggx_dielectric eta=1.5 aniso" + at, seed++);
    check_extra_lobe_sampling(RoughDielectricLobe::make(SampledSpectrum(1 / 1.5f), 0.5f, 0.5f), wo,
                              "ggx_dielectric eta=1/1.5 a=0.5" + at, seed++);
    check_extra_lobe_sampling(OrenNayarLobe::make(SampledSpectrum(0.8f), 0.6f), wo, "oren_nayar sigma=0.6" + at, seed++);
  }
}

}  // namespace
}  // namespace kauri
