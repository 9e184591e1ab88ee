// The path lanes' vector GGX conductor and rough dielectric (integrator/
// path_lanes_conductor.inl) against the scalar lobes they restate, lane by lane: the value
// and density (conductor_eval_pdf, dielectric_eval_pdf against eval_pdf) and the sampled
// direction (conductor_sample, dielectric_sample against sample) on random directions and
// samples, 8 different lobes side by side in a vector (gold-like spectral η and κ,
// isotropic and anisotropic α, with and without the multiple-scattering compensation,
// glass and water from outside and inside). A finer check than the whole-image equality of
// test_path_lanes.cpp: it names the quantity and the configuration that differ. The
// scalar lobes keep their own chi-square, reciprocity and white-furnace tests
// (test_bsdf.cpp, test_conductor_energy.cpp, test_rough_dielectric_energy.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <type_traits>
#include <vector>

#include "kauri/integrator/path_lanes.h"
#include "kauri/sampler/rng.h"

#if KAURI_PATH_LANES
namespace kauri {
namespace {
using namespace path_lanes_detail;

constexpr int W = kPathLanes;

Vec3 random_direction(PCG32& rng) {
  const Float z = 1 - 2 * rng.next_float(), phi = 2 * kPi * rng.next_float();
  const Float r = std::sqrt(std::fmax(0.0f, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

SampledSpectrum spectrum4(Float a, Float b, Float c, Float d) {
  SampledSpectrum s;
  s[0] = a, s[1] = b, s[2] = c, s[3] = d;
  return s;
}

/// The 8 lanes' directions as vectors.
struct LaneDirs {
  Vec3 d[W];
  V3 vec() const {
    V3 v;
    for (int k = 0; k < W; ++k) v.x[k] = d[k].x, v.y[k] = d[k].y, v.z[k] = d[k].z;
    return v;
  }
};

LF random_lanes(PCG32& rng) {
  LF v;
  for (int k = 0; k < W; ++k) v[k] = rng.next_float();
  return v;
}

/// |a − b| within `rel` of their size (or 1e-6 absolute near 0).
bool close(Float a, Float b, Float rel) {
  return std::fabs(a - b) <= rel * std::fmax(std::fabs(a), std::fabs(b)) + 1e-6f;
}

std::vector<GGXConductorLobe> conductor_lobes() {
  std::vector<GGXConductorLobe> lobes;
  const Float alphas[][2] = {{0.05f, 0.05f}, {0.3f, 0.3f}, {0.1f, 0.45f}, {0.7f, 0.2f}};
  for (bool comp : {false, true})
    for (const auto& a : alphas) {
      GGXConductorLobe l;
      l.compensate = comp;
      l.mf = {a[0], a[1]};
      l.eta = spectrum4(0.2f, 0.45f, 1.1f, 0.3f);  // gold-like: η and κ differ per wavelength
      l.k = spectrum4(3.5f, 2.4f, 1.9f, 3.0f);
      l.cache_multiple_scattering();               // as instantiate() leaves it
      lobes.push_back(l);
    }
  return lobes;
}

std::vector<RoughDielectricLobe> dielectric_lobes() {
  std::vector<RoughDielectricLobe> lobes;
  const Float alphas[][2] = {{0.15f, 0.15f}, {0.4f, 0.4f}, {0.08f, 0.3f}, {0.6f, 0.25f}};
  int i = 0;
  for (bool comp : {false, true})
    for (const auto& a : alphas) {
      const Float eta = (i++ % 2) ? 1.33f : 1.5f;
      lobes.push_back(RoughDielectricLobe::make(SampledSpectrum(eta), a[0], a[1], comp));
    }
  return lobes;
}

constexpr int kRounds = 4000;  // × 8 lanes
const LI kAll = ~LI{};

TEST(PathLanesLobes, ConductorValueAndDensityAsTheScalarLobe) {
  const std::vector<GGXConductorLobe> lobes = conductor_lobes();
  PCG32 rng(7, 11);
  int compared = 0, nonzero = 0;
  for (int round = 0; round < kRounds; ++round) {
    ConductorVertices C;
    int which[W];
    LaneDirs wo, wi;
    for (int k = 0; k < W; ++k) {
      which[k] = (round + k) % int(lobes.size());
      C.set(k, Lobe(lobes[size_t(which[k])]), 1, which[k]);
      wo.d[k] = random_direction(rng);
      // Half the lanes on ω_o's side, so that most pairs have a value.
      wi.d[k] = random_direction(rng);
      if (k % 2 == 0 && wi.d[k].z * wo.d[k].z < 0) wi.d[k].z = -wi.d[k].z;
    }
    LF f[kSpectrumSamples], pdf;
    conductor_eval_pdf(C, wo.vec(), wi.vec(), kAll, kAll, f, &pdf);
    for (int k = 0; k < W; ++k) {
      const GGXConductorLobe& l = lobes[size_t(which[k])];
      Float p = 0;
      const SampledSpectrum fs = l.eval_pdf(wo.d[k], wi.d[k], TransportMode::Radiance, &p);
      ASSERT_TRUE(close(pdf[k], p, 1e-3f)) << "lobe " << which[k] << " lane " << k << ": pdf " << pdf[k] << " vs " << p;
      for (int i = 0; i < kSpectrumSamples; ++i)
        ASSERT_TRUE(close(f[i][k], fs[i], 1e-3f))
            << "lobe " << which[k] << " lane " << k << " wavelength " << i << ": f " << f[i][k] << " vs " << fs[i];
      ++compared;
      nonzero += p > 0 ? 1 : 0;
    }
  }
  EXPECT_GT(nonzero, compared / 3);  // most comparisons are of values, not of zeros
}

/// Samples of the vector lobes (`lane_sample(vertices, wo, uc, ux, uy, &wi, &through)`: the
/// valid lanes) against each lane's scalar lobe.sample, over kRounds groups of 8 random
/// ω_o and samples: the same validity (but for rounding at ω_i.z = 0, where the scalar
/// lobe also drops a density of 0: at most 0.1% apart), direction and refraction.
template <class Vertices, class LobeT, class LaneSample>
void check_samples(const std::vector<LobeT>& lobes, Vertices proto, uint64_t seed, LaneSample lane_sample) {
  PCG32 rng(9, seed);
  int valid = 0, refracted = 0, disagree = 0, total = 0;
  for (int round = 0; round < kRounds; ++round) {
    Vertices V = proto;
    int which[W];
    LaneDirs wo;
    for (int k = 0; k < W; ++k) {
      which[k] = (round + k) % int(lobes.size());
      V.set(k, Lobe(lobes[size_t(which[k])]), 1, which[k]);
      wo.d[k] = random_direction(rng);
    }
    const LF uc = random_lanes(rng), ux = random_lanes(rng), uy = random_lanes(rng);
    V3 wi;
    LI through{};
    const LI ok = lane_sample(V, wo.vec(), uc, ux, uy, &wi, &through);
    for (int k = 0; k < W; ++k) {
      SampledWavelengths lambda = SampledWavelengths::sample_visible(0.3f);
      const BSDFSample s = lobes[size_t(which[k])].sample(wo.d[k], uc[k], {ux[k], uy[k]}, lambda,
                                                          TransportMode::Radiance);
      ++total;
      if (bool(ok[k]) != s.valid()) {
        ++disagree;
        continue;
      }
      if (!s.valid()) continue;
      ++valid;
      refracted += s.transmission ? 1 : 0;
      ASSERT_EQ(bool(through[k]), s.transmission) << "lobe " << which[k] << " lane " << k;
      ASSERT_NEAR(wi.x[k], s.wi.x, 1e-4f) << "lobe " << which[k] << " wo.z " << wo.d[k].z;
      ASSERT_NEAR(wi.y[k], s.wi.y, 1e-4f) << "lobe " << which[k] << " wo.z " << wo.d[k].z;
      ASSERT_NEAR(wi.z[k], s.wi.z, 1e-4f) << "lobe " << which[k] << " wo.z " << wo.d[k].z;
    }
  }
  EXPECT_LE(disagree, total / 1000) << disagree << " of " << total << " samples valid on one side only";
  EXPECT_GT(valid, total / 2);
  if (std::is_same_v<LobeT, RoughDielectricLobe>) {
    EXPECT_GT(refracted, valid / 5);
  }
}

TEST(PathLanesLobes, ConductorSampleAsTheScalarLobe) {
  check_samples(conductor_lobes(), ConductorVertices{}, 12,
                [](const ConductorVertices& C, const V3& wo, LF uc, LF ux, LF uy, V3* wi, LI*) {
                  return conductor_sample(C, wo, uc, ux, uy, kAll, wi);
                });
}

/// A DielectricVertices over `lobes`, with the compensation terms as build_lane_triangles
/// computes them (per lobe and side).
struct DielectricLanes {
  std::vector<RoughDielectricLobe::MS> terms;
  explicit DielectricLanes(const std::vector<RoughDielectricLobe>& lobes) {
    terms.resize(2 * lobes.size());
    for (size_t i = 0; i < lobes.size(); ++i)
      for (int side = 0; side < 2; ++side) terms[2 * i + size_t(side)] = lobes[i].ms_terms(lobes[i].eta[0], side == 0);
  }
};

TEST(PathLanesLobes, DielectricValueAndDensityAsTheScalarLobe) {
  const std::vector<RoughDielectricLobe> lobes = dielectric_lobes();
  const DielectricLanes tables(lobes);
  PCG32 rng(8, 11);
  int compared = 0, reflect = 0, refract = 0;
  for (int round = 0; round < kRounds; ++round) {
    DielectricVertices Dv;
    Dv.terms = tables.terms.data();
    int which[W];
    LaneDirs wo, wi;
    for (int k = 0; k < W; ++k) {
      which[k] = (round + k) % int(lobes.size());
      Dv.set(k, Lobe(lobes[size_t(which[k])]), 1, which[k]);
      wo.d[k] = random_direction(rng);
      wi.d[k] = random_direction(rng);
    }
    LF f, pdf;
    dielectric_eval_pdf(Dv, wo.vec(), wi.vec(), kAll, kAll, &f, &pdf);
    for (int k = 0; k < W; ++k) {
      const RoughDielectricLobe& l = lobes[size_t(which[k])];
      Float p = 0;
      const SampledSpectrum fs = l.eval_pdf(wo.d[k], wi.d[k], TransportMode::Radiance, &p);
      ASSERT_TRUE(close(pdf[k], p, 1e-3f)) << "lobe " << which[k] << " lane " << k << " wo.z " << wo.d[k].z
                                           << " wi.z " << wi.d[k].z << ": pdf " << pdf[k] << " vs " << p;
      ASSERT_TRUE(close(f[k], fs[0], 1e-3f)) << "lobe " << which[k] << " lane " << k << " wo.z " << wo.d[k].z
                                             << " wi.z " << wi.d[k].z << ": f " << f[k] << " vs " << fs[0];
      ++compared;
      if (p > 0) (wo.d[k].z * wi.d[k].z > 0 ? reflect : refract) += 1;
    }
  }
  EXPECT_GT(reflect, compared / 10);
  EXPECT_GT(refract, compared / 10);
}

TEST(PathLanesLobes, DielectricSampleAsTheScalarLobe) {
  const std::vector<RoughDielectricLobe> lobes = dielectric_lobes();
  const DielectricLanes tables(lobes);
  DielectricVertices proto;
  proto.terms = tables.terms.data();
  check_samples(lobes, proto, 13,
                [](const DielectricVertices& Dv, const V3& wo, LF uc, LF ux, LF uy, V3* wi, LI* through) {
                  return dielectric_sample(Dv, wo, uc, ux, uy, kAll, wi, through);
                });
}

}  // namespace
}  // namespace kauri
#endif  // KAURI_PATH_LANES
