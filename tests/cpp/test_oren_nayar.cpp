// Tests of the energy-preserving Oren–Nayar (EON) lobe, src/kauri/bsdf/oren_nayar.h:
// sampling against pdf() (chi-square), the closed-form albedos against quadrature,
// white furnace, ρ < 1 bound, Monte Carlo vs albedo_r(), reciprocity, σ = 0 = Lambert.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "chi2.h"
#include "lobe_test_util.h"
#include "kauri/bsdf/lobe.h"

namespace kauri {
namespace {

using namespace test;

constexpr double kPi = 3.14159265358979323846;



/// Chi-square of sample() against pdf(), plus sample().f == eval(), sample().pdf == pdf().
void check_sampling(const OrenNayarLobe& lobe, Vec3 wo, const std::string& name, uint64_t seed) {
  const SampledWavelengths lambda0 = test_wavelengths();
  int mismatch = 0;
  auto sample = [&](PCG32& r, Vec3* w) {
    SampledWavelengths lambda = lambda0;
    Float uc = r.next_float();
    BSDFSample s = lobe.sample(wo, uc, next_2d(r), lambda, TransportMode::Radiance);
    if (!s.valid()) return false;
    if (s.is_specular() || s.wi.z * wo.z <= 0) ++mismatch;
    Float p = lobe.pdf(wo, s.wi);
    if (std::fabs(s.pdf - p) > 1e-4f * p) ++mismatch;
    SampledSpectrum f = lobe.eval(wo, s.wi, TransportMode::Radiance);
    for (int i = 0; i < kSpectrumSamples; ++i)
      if (std::fabs(s.f[i] - f[i]) > 1e-4f * f[i]) ++mismatch;
    *w = s.wi;
    return true;
  };
  test::SphereChi2Config cfg;
  cfg.name = name;
  cfg.forced_cos = {0};
  cfg.seed = seed;
  cfg.samples = 300000;
  cfg.pilot = 20000;
  EXPECT_TRUE(test::sphere_chi2(sample, [&](Vec3 w) { return double(lobe.pdf(wo, w)); }, cfg));
  EXPECT_EQ(mismatch, 0) << name;
}

/// Deterministic hemisphere quadrature of ∫ f |cosθ_i| dω_i (midpoint in (μ_i, φ)).
double quad_albedo(const OrenNayarLobe& l, Vec3 wo, int ch, int n = 512) {
  double sum = 0;
  const Float sgn = wo.z < 0 ? -1.0f : 1.0f;
  for (int a = 0; a < n; ++a) {
    double mu = (a + 0.5) / n;
    for (int b = 0; b < 2 * n; ++b) {
      double phi = (b + 0.5) / (2 * n) * 2 * kPi;
      Vec3 wi = dir(Float(mu), Float(phi));
      wi.z *= sgn;
      sum += double(l.eval(wo, wi, TransportMode::Radiance)[ch]) * mu;
    }
  }
  return sum * (1.0 / n) * (2 * kPi / (2 * n));
}

void mc_albedo(const OrenNayarLobe& l, Vec3 wo, uint64_t seed, int n, double* mean, double* sigma) {
  Albedo a = directional_albedo(l, wo, seed, n, TransportMode::Radiance, 7);
  for (int i = 0; i < kSpectrumSamples; ++i) {
    mean[i] = a.mean[i];
    sigma[i] = a.sigma[i];
  }
}

TEST(OrenNayarLobe, SamplingMatchesPdf) {  // 7 chi-square tests
  uint64_t seed = 4100;
  SampledSpectrum rho = spectrum4(0.9f, 0.6f, 0.3f, 1.0f);
  for (Float sigma : {0.3f, 1.0f})
    for (Float c : {1.0f, 0.70710678f, 0.05f})
      check_sampling(OrenNayarLobe::make(rho, sigma), dir(c, 0.7f),
                     "oren_nayar sigma=" + std::to_string(sigma) + " cos_o=" + std::to_string(c), seed++);
  check_sampling(OrenNayarLobe::make(rho, 0.6f), dir(-0.4f, 2.2f), "oren_nayar sigma=0.6 wo below", seed++);
}

TEST(OrenNayarLobe, ClosedFormAlbedoMatchesQuadrature) {
  for (Float sigma : {0.25f, 0.5f, 1.0f}) {
    auto l = OrenNayarLobe::make(SampledSpectrum(1), sigma);
    // Single-scattering albedo E(μ): quadrature of f_ss alone (white, no f_ms).
    OrenNayarLobe ss = l;
    ss.ms_norm = 0;
    double avg = 0;
    const int nmu = 64;
    for (int k = 0; k < nmu; ++k) {
      double mu = (k + 0.5) / nmu;
      double e = quad_albedo(ss, dir(Float(mu), 0.3f), 0, 160);
      EXPECT_NEAR(double(l.E(Float(mu))), e, 2e-4) << "sigma=" << sigma << " mu=" << mu;
      avg += 2 * e * mu / nmu;
    }
    EXPECT_NEAR(double(l.E_avg), avg, 1e-3) << "sigma=" << sigma;
    for (Float mu : {1.0f, 0.5f, 0.1f, 0.01f}) {
      double e = quad_albedo(ss, dir(mu, 1.1f), 0);
      EXPECT_NEAR(double(l.E(mu)), e, 1e-4) << "sigma=" << sigma << " mu=" << mu;
    }
  }
  // End points of G: G(1) = 0, G(0) = π/2 − 2/3.
  EXPECT_NEAR(double(fon_g(1)), 0, 1e-6);
  EXPECT_NEAR(double(fon_g(0)), kPi / 2 - 2.0 / 3, 1e-6);
}

TEST(OrenNayarLobe, WhiteFurnace) {
  uint64_t seed = 4200;
  for (Float sigma : {0.0f, 0.5f, 1.0f})
    for (Float mu : {1.0f, 0.5f, 0.1f}) {
      auto l = OrenNayarLobe::make(SampledSpectrum(1), sigma);
      Vec3 wo = dir(mu, 0.4f);
      double m[kSpectrumSamples], s[kSpectrumSamples];
      mc_albedo(l, wo, seed++, 200000, m, s);
      double q = quad_albedo(l, wo, 0);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        EXPECT_NEAR(m[i], 1.0, 0.01) << "sigma=" << sigma << " mu=" << mu << " (MC ±" << s[i] << ")";
        EXPECT_NEAR(double(l.albedo_r(wo)[i]), 1.0, 1e-5) << "sigma=" << sigma << " mu=" << mu;
      }
      EXPECT_NEAR(q, 1.0, 2e-3) << "quadrature, sigma=" << sigma << " mu=" << mu;
      // Same from below (two-sided).
      EXPECT_NEAR(double(l.albedo_r(-wo)[0]), 1.0, 1e-5);
      EXPECT_NEAR(quad_albedo(l, -wo, 0), 1.0, 2e-3);
    }
}

TEST(OrenNayarLobe, ColouredAlbedoBoundedAndMatchesMonteCarlo) {
  SampledSpectrum rho = spectrum4(0.1f, 0.4f, 0.75f, 0.98f);
  uint64_t seed = 4300;
  for (Float sigma : {0.2f, 0.5f, 1.0f})
    for (Float mu : {1.0f, 0.6f, 0.2f, 0.03f}) {
      auto l = OrenNayarLobe::make(rho, sigma);
      Vec3 wo = dir(mu, 2.0f);
      SampledSpectrum a = l.albedo_r(wo);
      double m[kSpectrumSamples], s[kSpectrumSamples];
      mc_albedo(l, wo, seed++, 200000, m, s);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        EXPECT_LE(a[i], rho[i] * (1 + 1e-6f)) << "sigma=" << sigma << " mu=" << mu << " ch=" << i;
        EXPECT_GE(a[i], 0);
        EXPECT_NEAR(m[i], double(a[i]), 0.01 * double(a[i])) << "sigma=" << sigma << " mu=" << mu << " ch=" << i;
        EXPECT_NEAR(quad_albedo(l, wo, i, 256), double(a[i]), 3e-3 * double(a[i]))
            << "sigma=" << sigma << " mu=" << mu << " ch=" << i;
      }
      EXPECT_TRUE(l.albedo_t(wo).is_black());
    }
}

TEST(OrenNayarLobe, ReciprocalAndNonNegative) {
  PCG32 rng(4400, 1);
  for (Float sigma : {0.3f, 1.0f}) {
    auto l = OrenNayarLobe::make(spectrum4(0.2f, 0.5f, 0.8f, 1.0f), sigma);
    int nonzero = 0;
    for (int k = 0; k < 20000; ++k) {
      Vec3 a = sample_uniform_sphere(next_2d(rng)), b = sample_uniform_sphere(next_2d(rng));
      if (k % 2) b.z = std::copysign(b.z, a.z);
      SampledSpectrum fab = l.eval(a, b, TransportMode::Radiance), fba = l.eval(b, a, TransportMode::Importance);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        ASSERT_GE(fab[i], 0);
        ASSERT_NEAR(fab[i], fba[i], 1e-5f * std::max(Float(1), fab[i])) << "sigma=" << sigma;
      }
      if (!fab.is_black()) ++nonzero;
      if (!same_hemisphere(a, b)) {
        EXPECT_TRUE(fab.is_black());
      }
      EXPECT_EQ(l.pdf(a, b), l.pdf(-a, -b));
    }
    EXPECT_GT(nonzero, 9000);
  }
}

TEST(OrenNayarLobe, ZeroRoughnessIsLambert) {
  SampledSpectrum rho = spectrum4(0.1f, 0.4f, 0.75f, 0.98f);
  auto on = OrenNayarLobe::make(rho, 0);
  LambertLobe lam{rho};
  PCG32 rng(4500, 1);
  for (int k = 0; k < 2000; ++k) {
    Vec3 a = sample_uniform_sphere(next_2d(rng)), b = sample_uniform_sphere(next_2d(rng));
    if (k % 2) b.z = std::copysign(b.z, a.z);
    SampledSpectrum f0 = on.eval(a, b, TransportMode::Radiance), f1 = lam.eval(a, b, TransportMode::Radiance);
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_FLOAT_EQ(f0[i], f1[i]);
    EXPECT_FLOAT_EQ(on.pdf(a, b), lam.pdf(a, b));
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_FLOAT_EQ(on.albedo_r(a)[i], rho[i]);
  }
  EXPECT_EQ(on.roughness(), 0);
  // Roughness flattens: at σ = 1 back-scattering exceeds forward scattering at grazing light.
  auto rough = OrenNayarLobe::make(SampledSpectrum(1), 1);
  Vec3 wi = dir(0.2f, 0);
  EXPECT_GT(rough.eval(dir(0.5f, 0), wi, TransportMode::Radiance)[0],
            rough.eval(dir(0.5f, kPi), wi, TransportMode::Radiance)[0]);
}

TEST(OrenNayarLobe, LobeDispatchAndClamping) {
  auto l = OrenNayarLobe::make(spectrum4(-0.5f, 0.5f, 1.5f, 1), 2.0f);
  EXPECT_EQ(l.albedo[0], 0);
  EXPECT_EQ(l.albedo[2], 1);
  EXPECT_EQ(l.sigma, 1);
  Lobe lobe(l);
  EXPECT_EQ(lobe.type, LobeType::OrenNayar);
  EXPECT_STREQ(lobe.name(), "oren_nayar@1");
  EXPECT_EQ(lobe.scattering(), Scattering::Diffuse);
  EXPECT_EQ(lobe.lobe_class(), LobeClass::BRDF);
  Vec3 wo = dir(0.3f, 0.2f), wi = dir(0.8f, 2.0f);
  EXPECT_EQ(lobe.eval(wo, wi, TransportMode::Radiance)[1], l.eval(wo, wi, TransportMode::Radiance)[1]);
  EXPECT_EQ(lobe.pdf(wo, wi), l.pdf(wo, wi));
  EXPECT_EQ(lobe.albedo_r(wo)[1], l.albedo_r(wo)[1]);
  EXPECT_EQ(lobe.ior(0), 0);
  EXPECT_EQ(lobe.roughness(), 1);
  EXPECT_EQ(lobe.mean_direction(-wo).z, -1);
}

}  // namespace
}  // namespace kauri
