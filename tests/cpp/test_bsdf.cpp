// Statistical tests of the BSDF lobes (bsdf/*.h): sampling against the lobes'
// own densities (chi-square over the sphere), consistency of sample() with
// eval()/pdf(), energy conservation (white furnace), reciprocity, and the
// smooth dielectric's Fresnel split, Snell's law and dispersion.
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
#include "kauri/bsdf/bsdf.h"

namespace kauri {
namespace {

using test::SphereChi2Config;
using namespace test;


LambertLobe lambert(SampledSpectrum albedo) {
  LambertLobe l;
  l.albedo = albedo;
  return l;
}

/// A gold-like conductor (η, κ differ per wavelength).
GGXConductorLobe metal(Float ax, Float ay) {
  GGXConductorLobe l;
  l.compensate = false;  // these tests check single scattering (ggx_conductor@1)
  l.mf = {ax, ay};
  l.eta = spectrum4(0.2f, 0.45f, 1.1f, 0.3f);
  l.k = spectrum4(3.5f, 2.4f, 1.9f, 3.0f);
  return l;
}

/// A conductor whose Fresnel term is 1 at every angle (η = 1, κ = 10⁴): a white furnace.
GGXConductorLobe perfect_mirror_metal(Float ax, Float ay) {
  GGXConductorLobe l;
  l.compensate = false;
  l.mf = {ax, ay};
  l.eta = SampledSpectrum(1);
  l.k = SampledSpectrum(1e4f);
  return l;
}

// ---------------------------------------------------------------- sampling vs pdf

TEST(LambertLobe, SamplingMatchesPdf) {
  LambertLobe l = lambert(spectrum4(0.2f, 0.5f, 0.8f, 1.0f));
  check_lobe_sampling(l, dir(0.6f, 0.3f), "lambert wo above", 100);
  check_lobe_sampling(l, dir(-0.4f, 2.0f), "lambert wo below", 101);
}

struct GGXCase {
  Float ax, ay, cos_o;
};

std::string ggx_name(const GGXCase& c) {
  return "ggx ax=" + fmt(double(c.ax)) + " ay=" + fmt(double(c.ay)) + " cos_o=" + fmt(double(c.cos_o));
}

std::vector<GGXCase> ggx_cases() {
  std::vector<GGXCase> cases;
  for (Float a : {0.05f, 0.3f, 1.0f})
    for (Float c : {1.0f, 0.70710678f, 0.1f}) cases.push_back({a, a, c});
  for (Float c : {1.0f, 0.70710678f, 0.1f}) cases.push_back({0.1f, 0.5f, c});  // anisotropic
  cases.push_back({0.3f, 0.3f, -0.70710678f});                                // wo below the surface
  cases.push_back({0.1f, 0.5f, -0.5f});
  return cases;
}

TEST(GGXConductorLobe, SamplingMatchesPdf) {
  uint64_t seed = 200;
  for (const GGXCase& c : ggx_cases()) {
    // φ_o = 0.6 so that anisotropic lobes are not symmetric about the incidence plane.
    check_lobe_sampling(metal(c.ax, c.ay), dir(c.cos_o, 0.6f), ggx_name(c), seed++);
  }
}

TEST(GGXConductorLobe, SmoothLimitIsAMirror) {
  GGXConductorLobe l = metal(1e-4f, 1e-4f);
  SampledWavelengths lambda = test_wavelengths();
  Vec3 wo = dir(0.6f, 1.0f);
  BSDFSample s = l.sample(wo, 0.5f, {0.3f, 0.7f}, lambda, TransportMode::Radiance);
  EXPECT_TRUE(s.is_specular());
  EXPECT_EQ(s.pdf, 1);
  EXPECT_NEAR(s.wi.x, -wo.x, 1e-6);
  EXPECT_NEAR(s.wi.y, -wo.y, 1e-6);
  EXPECT_NEAR(s.wi.z, wo.z, 1e-6);
  SampledSpectrum F = fresnel_conductor(0.6f, l.eta, l.k);
  for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_NEAR(s.f[i] * 0.6f, F[i], 1e-5);
  EXPECT_EQ(l.pdf(wo, s.wi), 0);
  EXPECT_TRUE(l.eval(wo, s.wi, TransportMode::Radiance).is_black());
}

/// Lambert + two conductors in one BSDF (world frame = identity).
BSDF mixed_bsdf(Vec3 wo) {
  BSDF b;
  b.frame = Frame();
  b.ng = {0, 0, 1};
  b.add(Lobe(lambert(spectrum4(0.7f, 0.5f, 0.3f, 0.6f))), 0.5f);
  b.add(Lobe(metal(0.3f, 0.3f)), 0.3f);
  b.add(Lobe(metal(0.08f, 0.4f)), 0.2f);
  b.prepare(wo);
  return b;
}

/// BSDF::sample() against BSDF::pdf() (chi-square over the sphere), its f and pdf against
/// eval() and pdf() at the sampled direction, BSDF::eval_pdf against both
/// (check_lobe_sampling), the selection probabilities summing to 1 and the directional
/// albedo at most 1.
void expect_bsdf_sampling_consistent(const BSDF& b, Vec3 wo, const std::string& name, uint64_t seed) {
  double psum = 0;
  for (int i = 0; i < b.n_lobes; ++i) psum += double(b.select_prob[i]);
  EXPECT_NEAR(psum, 1, 1e-6) << name;
  check_lobe_sampling(b, wo, name + " cos_o=" + fmt(double(wo.z)), seed);
  Albedo a = directional_albedo(b, wo, seed + 50, 200000);
  for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_LE(a.mean[i], 1 + 3 * a.sigma[i]) << name;
}

TEST(BSDF, CombinedSamplingMatchesPdf) {
  uint64_t seed = 300;
  for (Vec3 wo : {dir(0.70710678f, 0.6f), dir(0.15f, 2.5f)})
    expect_bsdf_sampling_consistent(mixed_bsdf(wo), wo, "bsdf lambert+2 conductors", seed++);
}

TEST(BSDF, SingleLobeSampleReturnsEvalAndPdf) {
  // A lone lobe's sample() result is used as is (no second eval()/pdf() pass): with a
  // tinted weight, and for a transmitting lobe with a transmission scale below 1.
  uint64_t seed = 320;
  for (Vec3 wo : {dir(0.70710678f, 0.6f), dir(0.15f, 2.5f)}) {
    BSDF m;
    m.ng = {0, 0, 1};
    m.add(Lobe(metal(0.3f, 0.15f)), spectrum4(0.9f, 0.6f, 0.3f, 0.8f));
    m.prepare(wo);
    expect_bsdf_sampling_consistent(m, wo, "bsdf single tinted conductor", seed++);
    BSDF g;
    g.ng = {0, 0, 1};
    g.add(Lobe(RoughDielectricLobe::make(SampledSpectrum(1.5f), 0.25f, 0.25f)), SampledSpectrum(0.8f), 0.5f);
    g.prepare(wo);
    expect_bsdf_sampling_consistent(g, wo, "bsdf single rough dielectric, transmission x0.5", seed++);
  }
}

// A lone Lambert lobe takes BSDF::eval_pdf's and sample's inline path; the general code
// (eval_pdf_lobes, sample_lobes) must give the same values: weights below 1, tinted; ω_o
// in front and behind; ω_i on either side; a shading normal tilted off the geometric one
// (the leak correction); grazing and sampled directions. The same operations in the same
// order, but GCC may fuse a multiply-add in one inlined copy and not in the other
// (-ffp-contract=fast), so values agree to a few ulps, zeros and sides exactly.
TEST(BSDF, LoneLambertFastPathMatchesTheGeneralCode) {
  const Frame tilted = Frame::from_z(normalize(Vec3{0.3f, -0.2f, 0.9f}));
  PCG32 rng(5, 3);
  int compared = 0;
  for (int f = 0; f < 2; ++f)
    for (SampledSpectrum w : {SampledSpectrum(1.0f), spectrum4(0.9f, 0.6f, 0.3f, 0.05f)}) {
      BSDF b;
      b.frame = f ? tilted : Frame{};
      b.ng = {0, 0, 1};
      b.add(Lobe(lambert(spectrum4(0.2f, 0.5f, 0.8f, 1.0f))), w);
      b.prepare({0, 0, 1});
      ASSERT_TRUE(b.lone_lambert());
      for (int i = 0; i < 400; ++i) {
        const Vec3 wo = sample_uniform_sphere({rng.next_float(), rng.next_float()});
        Vec3 wi = sample_uniform_sphere({rng.next_float(), rng.next_float()});
        if (i % 50 == 0) wi = normalize(Vec3{1, 0, 1e-7f});  // grazing
        Float p_fast, p_general;
        SampledSpectrum e_fast = b.eval_pdf(wo, wi, TransportMode::Radiance, &p_fast);
        SampledSpectrum e_general = b.eval_pdf_lobes(wo, wi, TransportMode::Radiance, &p_general);
        auto close = [](Float a, Float b) { return a == b || std::fabs(a - b) <= 4e-7f * std::fabs(b); };
        ASSERT_PRED2(close, p_fast, p_general) << "pdf, case " << i;
        for (int k = 0; k < kSpectrumSamples; ++k) ASSERT_PRED2(close, e_fast[k], e_general[k]) << "eval, case " << i;
        const Vec2 u{rng.next_float(), rng.next_float()};
        SampledWavelengths lambda = SampledWavelengths::sample_visible(0.5f);
        BSDFSample s_fast = b.sample(wo, 0.5f, u, lambda, TransportMode::Radiance);
        BSDFSample s_general = b.sample_lobes(wo, 0.5f, u, lambda, TransportMode::Radiance);
        ASSERT_PRED2(close, s_fast.pdf, s_general.pdf) << "sample pdf, case " << i;
        ASSERT_EQ(s_fast.scattering, s_general.scattering);
        for (int a = 0; a < 3; ++a)
          ASSERT_NEAR(s_fast.wi[a], s_general.wi[a], 4e-7f) << "sample direction, case " << i;
        for (int k = 0; k < kSpectrumSamples; ++k) ASSERT_PRED2(close, s_fast.f[k], s_general.f[k]) << "sample f, case " << i;
        compared += s_fast.valid() && !s_fast.f.is_black() ? 1 : 0;
      }
    }
  EXPECT_GT(compared, 1000);  // most cases sampled a direction with a non-zero value
}

// ---------------------------------------------------------------- energy

TEST(LambertLobe, AlbedoEqualsRho) {
  SampledSpectrum rho = spectrum4(0.2f, 0.5f, 0.8f, 1.0f);
  LambertLobe l = lambert(rho);
  for (Vec3 wo : {dir(1, 0), dir(0.3f, 1), dir(-0.8f, 2)}) {
    Albedo a = directional_albedo(l, wo, 400, 200000);
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_NEAR(a.mean[i], double(rho[i]), 0.005 * double(rho[i]));
  }
}

TEST(GGXConductorLobe, FresnelOneConfiguration) {
  // η = 1, κ = 10⁴ must give F = 1 at every angle (checked, not assumed).
  for (int i = 0; i <= 1000; ++i) {
    Float c = Float(i) / 1000;
    EXPECT_GE(fresnel_conductor(c, 1.0f, 1e4f), 0.9999f) << "cos " << c;
  }
}

TEST(GGXConductorLobe, EnergyConservation) {
  // No multiple scattering is modelled yet: a rough conductor loses energy at
  // grazing angles and high roughness. The numbers are printed for reference.
  // Reference albedos ∫ D G / (4 cosθ_o) dω_i (F = 1, φ_o = 0.6) by independent adaptive
  // quadrature (scipy.integrate.dblquad over (θ_i, φ_i), tolerance 1e-7), in ggx_cases() order.
  const double reference[] = {0.997295868488617,  0.9958014662928258, 0.911346937308247,  0.8773584157886225,
                              0.8453962136233387, 0.8888036592327879, 0.3068528194400546, 0.37677476021049766,
                              0.7602104727201628, 0.8180702176370573, 0.8063197322242424, 0.8752778383042562,
                              0.8453962136233387, 0.7974627479413636};
  ASSERT_EQ(std::size(reference), ggx_cases().size());
  std::cout << "GGX conductor directional albedo with F = 1 (energy kept by single scattering):\n";
  uint64_t seed = 500;
  size_t case_index = 0;
  for (const GGXCase& c : ggx_cases()) {
    const double ref = reference[case_index++];
    Vec3 wo = dir(c.cos_o, 0.6f);
    Albedo white = directional_albedo(perfect_mirror_metal(c.ax, c.ay), wo, seed++, 200000);
    Albedo gold = directional_albedo(metal(c.ax, c.ay), wo, seed++, 200000);
    std::cout << "  " << ggx_name(c) << ": " << fmt(white.mean[0]) << " ± " << fmt(white.sigma[0], 2)
              << " (reference " << fmt(ref) << ", energy lost " << fmt(100 * (1 - ref), 3) << "%)\n";
    EXPECT_NEAR(white.mean[0], ref, 5 * white.sigma[0] + 1e-3) << ggx_name(c);
    ::testing::Test::RecordProperty("furnace " + ggx_name(c), fmt(white.mean[0]));
    for (int i = 0; i < kSpectrumSamples; ++i) {
      EXPECT_LE(white.mean[i], 1 + 3 * white.sigma[i]) << ggx_name(c);
      EXPECT_LE(gold.mean[i], 1 + 3 * gold.sigma[i]) << ggx_name(c);
      // The metal reflects at most what the white furnace does.
      EXPECT_LE(gold.mean[i], white.mean[i] + 3 * (gold.sigma[i] + white.sigma[i])) << ggx_name(c);
    }
    if (c.ax == 0.05f && c.ay == 0.05f && c.cos_o == 1.0f) {
      EXPECT_GE(white.mean[0], 0.97) << ggx_name(c);
    }
  }
}

TEST(Reciprocity, LambertAndGGX) {
  PCG32 rng(600, 1);
  std::vector<Lobe> lobes = {Lobe(lambert(spectrum4(0.2f, 0.5f, 0.8f, 1.0f))), Lobe(metal(0.05f, 0.05f)),
                             Lobe(metal(0.3f, 0.3f)), Lobe(metal(1.0f, 1.0f)), Lobe(metal(0.1f, 0.5f))};
  for (const Lobe& l : lobes) {
    int checked = 0;
    for (int k = 0; k < 20000; ++k) {
      Vec3 a = sample_uniform_sphere(next_2d(rng)), b = sample_uniform_sphere(next_2d(rng));
      if (k % 2) b.z = std::copysign(b.z, a.z);  // half the pairs in the same hemisphere
      SampledSpectrum fab = l.eval(a, b, TransportMode::Radiance), fba = l.eval(b, a, TransportMode::Radiance);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        ASSERT_TRUE(rel_close(double(fab[i]), double(fba[i]), 1e-4) || std::fabs(fab[i] - fba[i]) < 1e-30f)
            << l.name() << " f(a,b) = " << fab[i] << ", f(b,a) = " << fba[i];
      }
      if (!fab.is_black()) ++checked;
    }
    EXPECT_GT(checked, 5000) << l.name();
  }
}

// ---------------------------------------------------------------- smooth dielectric

SmoothDielectricLobe glass(SampledSpectrum eta, bool dispersive) {
  SmoothDielectricLobe l;
  l.eta = eta;
  l.dispersive = dispersive;
  return l;
}

TEST(SmoothDielectric, ReflectionFrequencyIsFresnel) {
  SmoothDielectricLobe l = glass(SampledSpectrum(1.5f), false);
  const SampledWavelengths lambda0 = test_wavelengths();
  for (Float cos_o : {1.0f, 0.7f, 0.2f, 0.03f, -0.95f, -0.8f, -0.74f, -0.5f}) {
    Vec3 wo = dir(cos_o, 0.4f);
    const double F = double(fresnel_dielectric(cos_o, 1.5f));
    const int n = 200000;
    int refl = 0;
    PCG32 rng(700, uint64_t(1000 * (cos_o + 2)));
    for (int k = 0; k < n; ++k) {
      SampledWavelengths lambda = lambda0;
      BSDFSample s = l.sample(wo, rng.next_float(), next_2d(rng), lambda, TransportMode::Radiance);
      ASSERT_TRUE(s.valid());
      ASSERT_TRUE(s.is_specular());
      if (!s.transmission) {
        ++refl;
        EXPECT_NEAR(double(s.pdf), F, 1e-6);  // FMA contraction may round differently
      } else {
        EXPECT_NEAR(double(s.pdf), 1 - F, 1e-6);
      }
    }
    if (F >= 1) {
      EXPECT_EQ(refl, n) << "total internal reflection at cos_o " << cos_o;
      continue;
    }
    double z = (refl - n * F) / std::sqrt(n * F * (1 - F));
    EXPECT_LT(std::fabs(z), 5) << "cos_o " << cos_o << ": reflected " << refl << " of " << n << ", F = " << F;
  }
  // The critical angle for leaving glass: sinθ_c = 1/1.5.
  Float cos_c = std::sqrt(1 - 1 / (1.5f * 1.5f));
  EXPECT_EQ(fresnel_dielectric(-(cos_c - 1e-3f), 1.5f), 1);
  EXPECT_LT(fresnel_dielectric(-(cos_c + 1e-3f), 1.5f), 1);
  // Normal incidence: ((η − 1)/(η + 1))².
  EXPECT_NEAR(fresnel_dielectric(1, 1.5f), 0.04f, 1e-6);
  EXPECT_NEAR(fresnel_dielectric(-1, 1.5f), 0.04f, 1e-6);
}

TEST(SmoothDielectric, SnellsLawAndMirrorReflection) {
  for (Float eta : {1.5f, 1.33f, 2.4f})
    for (Float cos_o : {1.0f, 0.8f, 0.3f, 0.05f, -0.99f, -0.9f, -0.6f}) {
      SmoothDielectricLobe l = glass(SampledSpectrum(eta), false);
      Vec3 wo = dir(cos_o, 1.3f);
      SampledWavelengths lambda = test_wavelengths();
      // uc = 1−: refraction unless total internal reflection; uc = 0: reflection.
      BSDFSample r = l.sample(wo, 0, {0.5f, 0.5f}, lambda, TransportMode::Radiance);
      ASSERT_FALSE(r.transmission);
      EXPECT_NEAR(r.wi.x, -wo.x, 1e-6);
      EXPECT_NEAR(r.wi.y, -wo.y, 1e-6);
      EXPECT_EQ(r.wi.z, wo.z);
      BSDFSample t = l.sample(wo, kOneMinusEpsilon, {0.5f, 0.5f}, lambda, TransportMode::Radiance);
      if (fresnel_dielectric(cos_o, eta) >= 1) {
        EXPECT_FALSE(t.transmission);
        continue;
      }
      ASSERT_TRUE(t.transmission) << "eta " << eta << " cos_o " << cos_o;
      EXPECT_NEAR(length(t.wi), 1, 1e-5);
      EXPECT_LT(t.wi.z * wo.z, 0) << "refracted ray stays on the incident side";
      // η_i sinθ_i = η_t sinθ_t with η = η_inside/η_outside.
      Float eta_i = cos_o > 0 ? 1 : eta, eta_t = cos_o > 0 ? eta : 1;
      Float sin_i = safe_sqrt(1 - wo.z * wo.z), sin_t = safe_sqrt(1 - t.wi.z * t.wi.z);
      EXPECT_NEAR(eta_i * sin_i, eta_t * sin_t, 2e-5) << "eta " << eta << " cos_o " << cos_o;
      // In the plane of incidence, on the other side of the normal.
      EXPECT_NEAR(wo.x * t.wi.y - wo.y * t.wi.x, 0, 1e-5);
      if (sin_i > 1e-3f) {
        EXPECT_LT(wo.x * t.wi.x + wo.y * t.wi.y, 0);
      }
      EXPECT_NEAR(t.eta, eta_t / eta_i, 1e-6);
    }
}

TEST(SmoothDielectric, EnergyConservation) {
  // Importance transport: every sample's weight f|cosθ|/pdf is exactly 1 (the
  // reflected and transmitted fractions sum to 1). Radiance transport scales the
  // transmitted part by 1/η² (η of the side entered relative to the side left).
  const Float eta = 1.5f;
  SmoothDielectricLobe l = glass(SampledSpectrum(eta), false);
  const SampledWavelengths lambda0 = test_wavelengths();
  for (Float cos_o : {1.0f, 0.5f, 0.1f, -0.9f, -0.5f}) {
    Vec3 wo = dir(cos_o, 0.2f);
    PCG32 rng(800, uint64_t(1000 * (cos_o + 2)));
    const int n = 100000;
    double sum_imp = 0, sum_rad = 0, max_dev = 0;
    for (int k = 0; k < n; ++k) {
      SampledWavelengths lambda = lambda0;
      Float uc = rng.next_float();
      Vec2 u = next_2d(rng);
      BSDFSample s = l.sample(wo, uc, u, lambda, TransportMode::Importance);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        double w = double(s.f[i]) * std::fabs(double(s.wi.z)) / double(s.pdf);
        max_dev = std::max(max_dev, std::fabs(w - 1));
        if (i == 0) sum_imp += w;
      }
      BSDFSample sr = l.sample(wo, uc, u, lambda, TransportMode::Radiance);
      sum_rad += double(sr.f[0]) * std::fabs(double(sr.wi.z)) / double(sr.pdf);
    }
    EXPECT_LT(max_dev, 1e-5) << "cos_o " << cos_o;
    EXPECT_NEAR(sum_imp / n, 1, 1e-5);
    const double F = double(fresnel_dielectric(cos_o, eta));
    const double erel = cos_o > 0 ? double(eta) : 1 / double(eta);
    const double expected_rad = F + (1 - F) / (erel * erel);
    // The radiance weights take two values (1 and 1/η²): binomial error.
    const double sd = std::fabs(1 - 1 / (erel * erel)) * std::sqrt(F * (1 - F) / n);
    EXPECT_NEAR(sum_rad / n, expected_rad, 5 * sd + 1e-6) << "cos_o " << cos_o;
  }
}

TEST(SmoothDielectric, DispersionTerminatesSecondaryWavelengths) {
  // Cauchy glass: η differs per wavelength.
  CauchyIOR ior = CauchyIOR::from_abbe(1.5f, 30);
  ASSERT_TRUE(ior.dispersive());
  SampledWavelengths lambda0 = test_wavelengths();
  SampledSpectrum eta;
  for (int i = 0; i < kSpectrumSamples; ++i) eta[i] = ior(lambda0.lambda[i]);
  EXPECT_NE(eta[0], eta[1]);
  SmoothDielectricLobe disp = glass(eta, true), plain = glass(eta, false);
  Vec3 wo = dir(0.6f, 0.9f);
  for (Float uc : {0.0f, 0.5f, kOneMinusEpsilon}) {
    SampledWavelengths lambda = lambda0;
    BSDFSample s = disp.sample(wo, uc, {0.5f, 0.5f}, lambda, TransportMode::Radiance);
    ASSERT_TRUE(s.valid());
    EXPECT_TRUE(lambda.secondary_terminated()) << "uc " << uc;
    EXPECT_FLOAT_EQ(lambda.pdf[0], lambda0.pdf[0] / kSpectrumSamples);
    for (int i = 1; i < kSpectrumSamples; ++i) EXPECT_EQ(lambda.pdf[i], 0);
    if (s.transmission) {
      // The refracted direction is the hero wavelength's.
      Float sin_t = safe_sqrt(1 - s.wi.z * s.wi.z);
      EXPECT_NEAR(eta[0] * sin_t, safe_sqrt(1 - wo.z * wo.z), 2e-5);
      EXPECT_NEAR(s.eta, eta[0], 1e-6);
    }
    // Terminating twice is harmless.
    SampledWavelengths again = lambda;
    disp.sample(wo, uc, {0.5f, 0.5f}, again, TransportMode::Radiance);
    EXPECT_EQ(again.pdf[0], lambda.pdf[0]);
    // Without the dispersive flag the wavelengths are left alone.
    SampledWavelengths keep = lambda0;
    plain.sample(wo, uc, {0.5f, 0.5f}, keep, TransportMode::Radiance);
    EXPECT_FALSE(keep.secondary_terminated());
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_EQ(keep.pdf[i], lambda0.pdf[i]);
  }
  // A dispersive hero path still conserves energy in importance mode.
  PCG32 rng(900, 1);
  double sum = 0;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    SampledWavelengths lambda = lambda0;
    BSDFSample s = disp.sample(wo, rng.next_float(), next_2d(rng), lambda, TransportMode::Importance);
    sum += double(s.f[0]) * std::fabs(double(s.wi.z)) / double(s.pdf);
  }
  EXPECT_NEAR(sum / n, 1, 1e-5);
}

TEST(BSDF, SpecularLobeInMixture) {
  // A delta lobe contributes nothing to eval/pdf and, when chosen, returns its own
  // estimator scaled by weight and selection probability.
  BSDF b;
  b.ng = {0, 0, 1};
  b.add(Lobe(lambert(SampledSpectrum(0.5f))), 0.5f);
  b.add(Lobe(glass(SampledSpectrum(1.5f), false)), 0.5f);
  Vec3 wo = dir(0.8f, 0.1f);
  b.prepare(wo);
  EXPECT_TRUE(b.has_non_specular());
  SampledWavelengths lambda = test_wavelengths();
  const Float p_glass = b.select_prob[1];
  BSDFSample s = b.sample(wo, 1 - 0.5f * p_glass, {0.3f, 0.3f}, lambda, TransportMode::Radiance);
  ASSERT_TRUE(s.valid());
  EXPECT_TRUE(s.is_specular());
  Vec3 mirror = reflect_z(wo);
  EXPECT_FLOAT_EQ(b.pdf(wo, mirror), b.select_prob[0] * cosine_hemisphere_pdf(mirror.z));
}

}  // namespace
}  // namespace kauri
