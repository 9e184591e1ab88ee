// Statistical tests of the sampling routines (sampler/sampling.h, distribution.h,
// sampler.h, sobol.h) and the pixel filter (film/film.h). Every warp is checked
// against its own density with the chi-square helper of chi2.h; seeds are fixed
// so a failure reproduces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "chi2.h"
#include "kauri/film/film.h"
#include "kauri/sampler/distribution.h"
#include "kauri/sampler/sampler.h"
#include "kauri/sampler/sampling.h"

namespace kauri {
namespace {

using test::Chi2Options;
using test::RectChi2Config;
using test::SphereChi2Config;
using test::kPiD;

Vec2 next_2d(PCG32& rng) {
  Float a = rng.next_float();
  return {a, rng.next_float()};
}

// ---------------------------------------------------------------- the helper itself

TEST(Chi2Helper, IncompleteGammaMatchesReference) {
  // Reference values from scipy.stats.chi2.sf / scipy.special.gammaincc.
  EXPECT_NEAR(test::chi2_sf(3.841458820694124, 1), 0.05, 1e-12);
  EXPECT_NEAR(test::chi2_sf(18.307038053275146, 10), 0.05, 1e-12);
  EXPECT_NEAR(test::chi2_sf(1000, 1000), 0.49405285382923964, 1e-10);
  EXPECT_NEAR(test::chi2_sf(1200, 1000) / 1.2255942330622893e-05, 1, 1e-8);
  EXPECT_NEAR(test::chi2_sf(0.5, 3), 0.9188914116546758, 1e-12);
  EXPECT_NEAR(test::chi2_sf(50, 7) / 1.4444852779215397e-08, 1, 1e-8);
  EXPECT_NEAR(test::gamma_q(0.5, 0.1), 0.6547208460185768, 1e-12);
  EXPECT_NEAR(test::gamma_q(30, 10), 0.9999997490048799, 1e-12);
  EXPECT_NEAR(test::gamma_q(30, 60) / 6.876264968732136e-06, 1, 1e-8);
  double a = test::chi2_alpha();
  EXPECT_GT(a, 0.01 / test::kChi2TestCount);  // Šidák is slightly less strict than Bonferroni
  EXPECT_LT(a, 0.01 / test::kChi2TestCount * 1.01);
}

// Negative controls: the helper must reject a wrong density, a sample where the
// density is zero, and a density that does not integrate to the success rate.
TEST(Chi2Helper, RejectsWrongDensities) {
  Chi2Options neg;
  neg.counted = false;
  auto uniform = [](PCG32& r, double* x, double* y) {
    *x = double(r.next_float());
    *y = double(r.next_float());
    return true;
  };
  RectChi2Config cfg{"negative control", 0, 1, 0, 1, 16, 16, 100000, 7, neg};
  // Tilted density (±10%).
  EXPECT_FALSE(test::rect_chi2(uniform, [](double x, double) { return 0.9 + 0.2 * x; }, cfg));
  // Zero on a strip where samples land.
  EXPECT_FALSE(test::rect_chi2(uniform, [](double x, double) { return x < 0.25 ? 0.0 : 4.0 / 3.0; }, cfg));
  // Right shape, wrong normalisation.
  EXPECT_FALSE(test::rect_chi2(uniform, [](double, double) { return 0.9; }, cfg));
  // And accepts the right one.
  EXPECT_TRUE(test::rect_chi2(uniform, [](double, double) { return 1.0; }, cfg));
}

// ---------------------------------------------------------------- warps

TEST(Sampling, UniformDisk) {
  // (r², φ/2π) is uniform on [0,1)² for a uniform disk.
  auto sample = [](PCG32& r, double* x, double* y) {
    Vec2 d = sample_uniform_disk(next_2d(r));
    double r2 = double(d.x) * double(d.x) + double(d.y) * double(d.y);
    if (r2 > 1 + 1e-6) return false;
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0) phi += 2 * kPiD;
    *x = r2;
    *y = phi / (2 * kPiD);
    return true;
  };
  RectChi2Config cfg{"uniform disk", 0, 1, 0, 1, 32, 32, 1000000, 11};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
  EXPECT_EQ(sample_uniform_disk({0.5f, 0.5f}).x, 0);
  // The polynomial cosine and sine match the exact ones to float rounding over the
  // quarter turn, and the mapping matches the trigonometric one.
  for (int i = -1000; i <= 1000; ++i) {
    const double phi = kPiD / 4 * i / 1000;
    const Vec2 cs = cos_sin_quarter(Float(phi));
    ASSERT_NEAR(double(cs.x), std::cos(double(Float(phi))), 1.2e-7) << phi;
    ASSERT_NEAR(double(cs.y), std::sin(double(Float(phi))), 1.2e-7) << phi;
  }
  PCG32 rng(3, 5);
  for (int i = 0; i < 100000; ++i) {
    const Vec2 u = next_2d(rng), d = sample_uniform_disk(u);
    const double a = 2 * double(u.x) - 1, b = 2 * double(u.y) - 1;
    const bool wide = std::fabs(a) > std::fabs(b);
    const double r = wide ? a : b, th = wide ? kPiD / 4 * (b / a) : kPiD / 2 - kPiD / 4 * (a / b);
    ASSERT_NEAR(double(d.x), r * std::cos(th), 3e-7);
    ASSERT_NEAR(double(d.y), r * std::sin(th), 3e-7);
  }
}

// cos_sin_turns against double precision over the whole turn: every quarter's swap and
// signs, the quarter boundaries themselves (t = k/8 and k/4, where the nearest quarter
// changes) and the ends 0 and 1; and the sphere and cone samplers built on it stay unit
// (the lat-long map's round trip is in test_lights.cpp).
TEST(Sampling, CosSinTurnsMatchesTheExactFunctionsOverTheTurn) {
  auto check = [](Float t) {
    const Vec2 cs = cos_sin_turns(t);
    const double phi = 2 * kPiD * double(t);
    ASSERT_NEAR(double(cs.x), std::cos(phi), 2.5e-7) << t;
    ASSERT_NEAR(double(cs.y), std::sin(phi), 2.5e-7) << t;
  };
  for (int i = 0; i <= 100000; ++i) check(Float(i) / 100000);
  for (int k = 0; k <= 8; ++k) {
    const Float b = Float(k) / 8;
    check(b);
    check(std::nextafter(b, Float(0)));
    check(std::nextafter(b, Float(1)));
  }
  EXPECT_EQ(cos_sin_turns(0).x, 1);
  EXPECT_EQ(cos_sin_turns(0.25f).y, 1);
  EXPECT_EQ(cos_sin_turns(0.5f).x, -1);
  EXPECT_EQ(cos_sin_turns(0.75f).y, -1);
  // Near θ = π (v → 1) sin θ keeps its relative precision: the reduction is in v, not π v.
  const Float v = 1 - 0x1p-20f;
  EXPECT_NEAR(double(cos_sin_turns(0.5f * v).y) / std::sin(kPiD * double(v)), 1.0, 1e-6);
  PCG32 rng(17, 4);
  for (int i = 0; i < 10000; ++i) {
    const Vec2 u = next_2d(rng);
    ASSERT_NEAR(double(length(sample_uniform_sphere(u))), 1.0, 1e-6);
    ASSERT_NEAR(double(length(sample_uniform_cone(u, 0.3f))), 1.0, 1e-6);
  }
}

// atan2_poly and acos_poly (the lat-long and sphere uv mappings) against double-precision
// atan2 and acos: every octant and quadrant, both signs of zero, the fold at tan(π/8),
// angles near ±π (where the result changes sign) and arguments of very different scales.
// Within 4e-7 absolute: about an ulp of the result near π.
// The disk and triangle maps select their operands instead of branching on the half of the
// square (select_if_less); the values must be those of the two-branch definitions, bit for
// bit, on both sides of the diagonals and on them.
TEST(Sampling, SelectFormsOfTheDiskAndTriangleMapsMatchTheBranches) {
  auto disk_branches = [](Vec2 u) -> Vec2 {
    Float a = 2 * u.x - 1, b = 2 * u.y - 1;
    if (a == 0 && b == 0) return {0, 0};
    if (std::fabs(a) > std::fabs(b)) {
      const Vec2 cs = cos_sin_quarter(kPiOver4 * (b / a));
      return {a * cs.x, a * cs.y};
    }
    const Vec2 cs = cos_sin_quarter(kPiOver4 * (a / b));
    return {b * cs.y, b * cs.x};
  };
  auto triangle_branches = [](Vec2 u) -> Vec2 {
    if (u.x < u.y) return {u.x / 2, u.y - u.x / 2};
    return {u.x - u.y / 2, u.y / 2};
  };
  PCG32 rng(31, 2);
  int wide = 0, lower = 0;
  for (int i = 0; i < 200000; ++i) {
    Vec2 u{rng.next_float(), rng.next_float()};
    if (i % 7 == 0) u.y = u.x;          // on the diagonal
    if (i % 11 == 0) u.y = 1 - u.x;     // on the other diagonal (|a| = |b|)
    const Vec2 d = sample_uniform_disk(u), dw = disk_branches(u);
    ASSERT_EQ(float_as_bits(d.x), float_as_bits(dw.x)) << u.x << " " << u.y;
    ASSERT_EQ(float_as_bits(d.y), float_as_bits(dw.y)) << u.x << " " << u.y;
    const Vec2 t = sample_uniform_triangle(u), tw = triangle_branches(u);
    ASSERT_EQ(float_as_bits(t.x), float_as_bits(tw.x)) << u.x << " " << u.y;
    ASSERT_EQ(float_as_bits(t.y), float_as_bits(tw.y)) << u.x << " " << u.y;
    wide += std::fabs(2 * u.x - 1) > std::fabs(2 * u.y - 1);
    lower += u.x < u.y;
  }
  EXPECT_GT(wide, 50000);  // both sides of each choice were compared
  EXPECT_GT(lower, 50000);
  EXPECT_EQ(select_if_less(1, 2, 3, 4), 3);
  EXPECT_EQ(select_if_less(2, 1, 3, 4), 4);
  EXPECT_EQ(select_if_less(1, 1, 3, 4), 4);
  EXPECT_EQ(select_if_less(std::nanf(""), 1, 3, 4), 4);  // as x < y: false for NaN
}

// rsqrt (the SSE estimate and one Newton step, core/math.h) against double precision over
// the whole range of normal floats, at every power of two and between; normalize() from it
// gives unit vectors for lengths from 2^-60 to 2^60; subnormals, 0 and ∞ take 1/√x. 5e-7 relative: a few ulps, well inside what a direction or normal needs.
TEST(Sampling, ReciprocalSquareRootIsAccurateOverTheFloatRange) {
  double worst = 0;
  auto check = [&](Float x) {
    const double want = 1 / std::sqrt(double(x)), got = double(rsqrt(x));
    worst = std::max(worst, std::fabs(got / want - 1));
    ASSERT_NEAR(got / want, 1.0, 5e-7) << "rsqrt(" << x << ")";
  };
  PCG32 rng(23, 8);
  for (int e = -125; e <= 126; ++e) {
    check(std::ldexp(1.0f, e));
    for (int i = 0; i < 400; ++i) check(std::ldexp(1 + rng.next_float(), e));
  }
  check(1.17549435e-38f);  // the smallest normal
  check(3.4028235e38f);    // the largest float
  EXPECT_LT(worst, 5e-7);
  std::printf("rsqrt: worst relative error %.3g\n", worst);
  EXPECT_NEAR(double(rsqrt(1e-40f)) * std::sqrt(double(1e-40f)), 1.0, 1e-6);  // subnormal: 1/√x
  EXPECT_EQ(rsqrt(0.0f), INFINITY);
  EXPECT_EQ(rsqrt(INFINITY), 0);
  EXPECT_TRUE(std::isnan(rsqrt(std::nanf(""))));
  for (int i = 0; i < 100000; ++i) {
    const Float scale = std::ldexp(1.0f, int(rng.next_u32() % 120) - 60);
    const Vec3 v{(2 * rng.next_float() - 1) * scale, (2 * rng.next_float() - 1) * scale,
                 (2 * rng.next_float() - 1) * scale};
    if (!(length_squared(v) > 0)) continue;
    ASSERT_NEAR(double(length(normalize(v))), 1.0, 1e-6) << v.x << " " << v.y << " " << v.z;
  }
}

TEST(Sampling, PolynomialAtan2AndAcosMatchTheLibrary) {
  PCG32 rng(9, 4);
  double worst = 0;
  auto check = [&](Float y, Float x) {
    const double want = std::atan2(double(y), double(x)), got = double(atan2_poly(y, x));
    worst = std::max(worst, std::fabs(got - want));
    ASSERT_NEAR(got, want, 4e-7) << "atan2(" << y << ", " << x << ")";
  };
  for (int i = 0; i <= 4096; ++i) {
    const double t = -kPiD + 2 * kPiD * i / 4096;
    check(Float(std::sin(t)), Float(std::cos(t)));
    check(Float(1e-20 * std::sin(t)), Float(1e-20 * std::cos(t)));
    check(Float(3e18 * std::sin(t)), Float(3e18 * std::cos(t)));
  }
  for (int i = 0; i < 200000; ++i) check(2 * rng.next_float() - 1, 2 * rng.next_float() - 1);
  for (Float r : {0.41421354f, 0.41421356f, 0.41421358f}) {  // both sides of the fold
    check(r, 1);
    check(1, r);
    check(-r, -1);
  }
  check(0.0f, 1.0f);
  check(-0.0f, -1.0f);  // −π
  check(0.0f, -1.0f);   // +π
  check(1e-30f, -1.0f);
  EXPECT_EQ(atan2_poly(0, 0), 0);
  EXPECT_LT(worst, 4e-7);  // ~1.5 ulp of π: the folds π/2 − a and π − a round once more
  std::printf("atan2_poly: worst absolute error %.3g\n", worst);
  for (int i = -20000; i <= 20000; ++i) {
    const Float x = Float(i) / 20000;
    ASSERT_NEAR(double(acos_poly(x)), std::acos(double(x)), 4e-7) << x;
  }
  EXPECT_EQ(acos_poly(1.5f), 0);  // clamped
  EXPECT_NEAR(double(acos_poly(-1.5f)), kPiD, 4e-7);
}

TEST(Sampling, CosineHemisphere) {
  SphereChi2Config cfg;
  cfg.name = "cosine hemisphere";
  cfg.forced_cos = {0};
  cfg.seed = 12;
  auto sample = [](PCG32& r, Vec3* w) {
    *w = sample_cosine_hemisphere(next_2d(r));
    return true;
  };
  EXPECT_TRUE(test::sphere_chi2(sample, [](Vec3 w) { return double(w.z > 0 ? w.z : 0) / kPiD; }, cfg));
  // The density function itself.
  EXPECT_FLOAT_EQ(cosine_hemisphere_pdf(0.5f), 0.5f * kInvPi);
  EXPECT_EQ(cosine_hemisphere_pdf(-0.5f), 0);
  PCG32 rng(3, 4);
  for (int i = 0; i < 1000; ++i) {
    Vec3 w = sample_cosine_hemisphere(next_2d(rng));
    ASSERT_NEAR(length(w), 1, 1e-5);
    ASSERT_GE(w.z, 0);
  }
}

TEST(Sampling, UniformSphere) {
  SphereChi2Config cfg;
  cfg.name = "uniform sphere";
  cfg.adaptive = false;
  cfg.seed = 13;
  auto sample = [](PCG32& r, Vec3* w) {
    *w = sample_uniform_sphere(next_2d(r));
    return true;
  };
  EXPECT_TRUE(test::sphere_chi2(sample, [](Vec3) { return double(uniform_sphere_pdf()); }, cfg));
  EXPECT_NEAR(double(uniform_sphere_pdf()), 1 / (4 * kPiD), 1e-8);
}

TEST(Sampling, UniformCone) {
  for (Float cos_max : {0.999f, 0.9f, 0.5f, 0.0f, -0.6f}) {
    SphereChi2Config cfg;
    cfg.name = "uniform cone cos_max=" + std::to_string(cos_max);
    cfg.forced_cos = {double(cos_max)};
    cfg.seed = 14 + uint64_t(100 * (cos_max + 1));
    cfg.samples = 500000;
    auto sample = [&](PCG32& r, Vec3* w) {
      *w = sample_uniform_cone(next_2d(r), cos_max);
      return true;
    };
    auto pdf = [&](Vec3 w) { return w.z >= cos_max ? double(uniform_cone_pdf(cos_max)) : 0.0; };
    EXPECT_TRUE(test::sphere_chi2(sample, pdf, cfg));
  }
}

TEST(Sampling, UniformTriangle) {
  // Barycentrics (b0, b1) uniform on the triangle ⇔ (1 − (1 − b0)², b1/(1 − b0)) uniform on [0,1)².
  int outside = 0;
  auto sample = [&](PCG32& r, double* x, double* y) {
    Vec2 b = sample_uniform_triangle(next_2d(r));
    double b0 = double(b.x), b1 = double(b.y);
    if (b0 < 0 || b1 < 0 || b0 + b1 > 1 + 1e-6) ++outside;
    *x = 1 - (1 - b0) * (1 - b0);
    *y = b0 < 1 ? b1 / (1 - b0) : 0.5;
    return true;
  };
  RectChi2Config cfg{"uniform triangle", 0, 1, 0, 1, 32, 32, 1000000, 15};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
  EXPECT_EQ(outside, 0);

  // Uniform in area: each of the 4 midpoint sub-triangles receives a quarter.
  PCG32 rng(16, 1);
  int counts[4] = {0, 0, 0, 0};
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    Vec2 b = sample_uniform_triangle(next_2d(rng));
    Float b2 = 1 - b.x - b.y;
    // Sub-triangle: corner k if its barycentric > 1/2, else the middle one.
    int k = b.x > 0.5f ? 0 : (b.y > 0.5f ? 1 : (b2 > 0.5f ? 2 : 3));
    ++counts[k];
  }
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(double(counts[k]) / n, 0.25, 5 * std::sqrt(0.25 * 0.75 / n)) << k;
}

TEST(Sampling, ErfInvAccuracy) {
  // Compare with erf: erf(erf_inv(x)) must give back x, and erf_inv(erf(y)) must
  // give back y up to the conditioning of erf_inv near ±1.
  double max_fwd = 0, max_rel = 0;
  for (int i = -100000; i <= 100000; ++i) {
    Float x = Float(double(i) / 100001.0);
    double y = double(erf_inv(x));
    double back = std::erf(y);
    max_fwd = std::max(max_fwd, std::fabs(back - double(x)));
    // Relative error of y against the exact inverse at x (one Newton step from y in double).
    double exact = y - (std::erf(y) - double(x)) / (2 / std::sqrt(kPiD) * std::exp(-y * y));
    if (exact != 0) max_rel = std::max(max_rel, std::fabs(y - exact) / std::fabs(exact));
  }
  std::cout << "erf_inv: max |erf(erf_inv(x)) - x| = " << max_fwd << ", max rel. error = " << max_rel << "\n";
  ::testing::Test::RecordProperty("erf_inv_max_forward_error", std::to_string(max_fwd));
  ::testing::Test::RecordProperty("erf_inv_max_relative_error", std::to_string(max_rel));
  EXPECT_LT(max_fwd, 3e-7);
  EXPECT_LT(max_rel, 2e-6);
  // Tails: x = ±(1 − 2^-k).
  for (int k = 2; k <= 24; ++k) {
    Float x = 1 - std::ldexp(1.0f, -k);
    double y = double(erf_inv(x));
    double exact = y - (std::erf(y) - double(x)) / (2 / std::sqrt(kPiD) * std::exp(-y * y));
    for (int it = 0; it < 5; ++it)
      exact = exact - (std::erf(exact) - double(x)) / (2 / std::sqrt(kPiD) * std::exp(-exact * exact));
    EXPECT_NEAR(y / exact, 1, 2e-6) << "x = 1 - 2^-" << k;
    EXPECT_EQ(erf_inv(-x), -erf_inv(x));
  }
  EXPECT_EQ(erf_inv(0), 0);
}

TEST(Sampling, TruncatedGaussian) {
  struct Case {
    Float sigma, r;
  };
  int k = 0;
  for (Case c : {Case{0.5f, 1.5f}, Case{0.3f, 0.4f}, Case{1.0f, 3.5f}}) {
    auto sample = [&](PCG32& rng, double* x, double* y) {
      *x = double(sample_truncated_gaussian(rng.next_float(), c.sigma, c.r));
      *y = 0.5;
      return true;
    };
    auto pdf = [&](double x, double) { return double(truncated_gaussian_pdf(Float(x), c.sigma, c.r)); };
    RectChi2Config cfg{"truncated gaussian sigma=" + std::to_string(c.sigma) + " r=" + std::to_string(c.r),
                       -double(c.r), double(c.r), 0, 1, 100, 1, 500000, uint64_t(20 + k++)};
    EXPECT_TRUE(test::rect_chi2(sample, pdf, cfg));
    EXPECT_LE(std::fabs(sample_truncated_gaussian(0, c.sigma, c.r)), c.r);
    EXPECT_LE(std::fabs(sample_truncated_gaussian(kOneMinusEpsilon, c.sigma, c.r)), c.r);
    EXPECT_EQ(truncated_gaussian_pdf(c.r * 1.01f, c.sigma, c.r), 0);
  }
}

TEST(Sampling, PixelFilterGaussianAndBox) {
  for (FilterType type : {FilterType::Gaussian, FilterType::Box}) {
    PixelFilter f;
    f.type = type;
    f.sigma = 0.5f;
    f.radius = type == FilterType::Box ? 0.5f : 1.5f;
    auto sample = [&](PCG32& rng, double* x, double* y) {
      Vec2 p = f.sample(next_2d(rng));
      *x = double(p.x);
      *y = double(p.y);
      return true;
    };
    auto pdf = [&](double x, double y) { return double(f.pdf({Float(x), Float(y)})); };
    double r = double(f.radius);
    RectChi2Config cfg{type == FilterType::Box ? "box filter" : "gaussian filter", -r, r, -r, r, 30, 30, 1000000,
                       uint64_t(type == FilterType::Box ? 31 : 32)};
    EXPECT_TRUE(test::rect_chi2(sample, pdf, cfg));
  }
}

// ---------------------------------------------------------------- distributions

std::vector<Float> random_function(PCG32& rng, int n, double zero_fraction) {
  std::vector<Float> f(static_cast<size_t>(n), Float(0));
  for (Float& v : f) {
    Float u = rng.next_float();
    v = rng.next_float() < Float(zero_fraction) ? 0 : u * u * u * 10;
  }
  return f;
}

// The branch-free search against its definition, the last i in [0, n) with cdf[i] <= u, on
// cdfs with flat runs (zero-probability bins), u on the knots and between them.
TEST(Distribution, FindIntervalIsTheLastKnotAtOrBelowU) {
  PCG32 rng(347, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + int(rng.next_u32() % 70);
    std::vector<Float> cdf(size_t(n) + 1, 0);
    for (int i = 1; i <= n; ++i) cdf[size_t(i)] = cdf[size_t(i) - 1] + (rng.next_float() < 0.3f ? 0 : rng.next_float());
    if (cdf[size_t(n)] == 0) cdf[size_t(n)] = 1;
    for (Float& c : cdf) c /= cdf[size_t(n)];
    cdf[size_t(n)] = 1;
    for (int k = 0; k < 50; ++k) {
      const Float u = k % 3 == 0 ? cdf[rng.next_u32() % uint32_t(n)] : rng.next_float();
      int want = 0;
      for (int i = 0; i < n; ++i)
        if (cdf[size_t(i)] <= u) want = i;
      ASSERT_EQ(find_interval(cdf.data(), n, u), want) << "n " << n << " u " << u;
    }
  }
}

TEST(Distribution, Continuous1D) {
  PCG32 rng(40, 1);
  std::vector<std::vector<Float>> funcs;
  funcs.push_back(random_function(rng, 37, 0.25));
  // Leading, trailing and consecutive zero bins.
  std::vector<Float> g = random_function(rng, 24, 0.1);
  g[0] = g[1] = g[22] = g[23] = g[10] = g[11] = g[12] = 0;
  g[5] = 1e-4f;
  funcs.push_back(g);
  int k = 0;
  for (const auto& f : funcs) {
    Distribution1DStorage storage(f);
    Distribution1D d = storage.view();
    const int n = d.n;
    double integral = 0;
    for (Float v : f) integral += double(v) / n;
    EXPECT_NEAR(double(d.integral), integral, 1e-6 * integral);
    int mismatches = 0;
    auto sample = [&](PCG32& r, double* x, double* y) {
      Float pdf;
      int bin;
      Float xs = d.sample_continuous(r.next_float(), &pdf, &bin);
      if (bin != std::min(n - 1, int(xs * Float(n))) || pdf != d.pdf(xs)) ++mismatches;
      *x = double(xs);
      *y = 0.5;
      return true;
    };
    // Three cells per bin, aligned with the bins, so zero bins are zero cells.
    RectChi2Config cfg{"distribution1d continuous #" + std::to_string(k), 0, 1, 0, 1, 3 * n, 1, 500000,
                       uint64_t(41 + k)};
    EXPECT_TRUE(test::rect_chi2(sample, [&](double x, double) { return double(d.pdf(Float(x))); }, cfg));
    EXPECT_EQ(mismatches, 0);
    ++k;
  }
}

TEST(Distribution, Discrete1D) {
  PCG32 rng(50, 1);
  std::vector<Float> f = random_function(rng, 29, 0.3);
  f[0] = 0;
  f[28] = 0;
  Distribution1DStorage storage(f);
  Distribution1D d = storage.view();
  const int n = d.n;
  double sum = 0;
  for (Float v : f) sum += double(v);
  for (int i = 0; i < n; ++i) EXPECT_NEAR(double(d.discrete_pmf(i)), double(f[size_t(i)]) / sum, 1e-6);
  // The stored table (built with the storage) holds what the view without it computes,
  // bit for bit: the light choice's pmf and the emitter MIS weight read the same value.
  ASSERT_NE(d.pmf, nullptr);
  Distribution1D bare = d;
  bare.pmf = nullptr;
  for (int i = 0; i < n; ++i) EXPECT_EQ(float_as_bits(d.discrete_pmf(i)), float_as_bits(bare.discrete_pmf(i))) << i;
  // The bin (as a cell) and the remapped u within it: x = (i + u')/n must have the
  // continuous density, i.e. the bin is chosen with probability pmf and u' is uniform.
  int pmf_mismatch = 0;
  auto sample = [&](PCG32& r, double* x, double* y) {
    Float pmf, ur;
    int i = d.sample_discrete(r.next_float(), &pmf, &ur);
    if (pmf != d.discrete_pmf(i) || !(ur >= 0 && ur < 1)) ++pmf_mismatch;
    *x = (double(i) + double(ur)) / n;
    *y = 0.5;
    return true;
  };
  RectChi2Config cfg{"distribution1d discrete + remapped u", 0, 1, 0, 1, 4 * n, 1, 500000, 51};
  EXPECT_TRUE(test::rect_chi2(sample, [&](double x, double) { return double(d.pdf(Float(x))); }, cfg));
  EXPECT_EQ(pmf_mismatch, 0);
  // Bin frequencies alone, against the pmf.
  auto sample_bin = [&](PCG32& r, double* x, double* y) {
    Float pmf;
    *x = (double(d.sample_discrete(r.next_float(), &pmf)) + 0.5) / n;
    *y = 0.5;
    return true;
  };
  RectChi2Config cfg2{"distribution1d discrete pmf", 0, 1, 0, 1, n, 1, 500000, 52};
  EXPECT_TRUE(test::rect_chi2(sample_bin, [&](double x, double) { return double(d.pdf(Float(x))); }, cfg2));

  // A function that is all zero: the integral is 0 and sampling still returns a valid bin.
  Distribution1DStorage zero(std::vector<Float>(5, 0));
  Float pmf = -1;
  int i = zero.view().sample_discrete(0.3f, &pmf);
  EXPECT_GE(i, 0);
  EXPECT_LT(i, 5);
  EXPECT_EQ(pmf, 0);
  // An empty distribution (a scene without finite lights: no arrays) answers 0 without
  // reading them, with or without its storage.
  EXPECT_EQ(Distribution1D{}.discrete_pmf(0), 0);
  EXPECT_EQ(Distribution1DStorage().view().discrete_pmf(3), 0);
}

TEST(Distribution, Continuous2D) {
  PCG32 rng(60, 1);
  const int nu = 13, nv = 9;
  std::vector<Float> f = random_function(rng, nu * nv, 0.2);
  for (int u = 0; u < nu; ++u) f[size_t(4 * nu + u)] = 0;  // a whole zero row
  for (int v = 0; v < nv; ++v) f[size_t(v * nu + 7)] = 0;  // a whole zero column
  Distribution2DStorage storage(f, nu, nv);
  Distribution2D d = storage.view();
  // The rows lie one after another (read flat by the path lanes); the marginal's values are
  // the rows' integrals.
  for (int v = 0; v < nv; ++v) {
    EXPECT_EQ(d.conditional[v].func, d.conditional[0].func + v * nu);
    EXPECT_EQ(d.conditional[v].cdf, d.conditional[0].cdf + v * (nu + 1));
    EXPECT_EQ(d.marginal.func[v], d.conditional[v].integral);
  }
  int mismatches = 0;
  auto sample = [&](PCG32& r, double* x, double* y) {
    Float pdf;
    Vec2 p = d.sample(next_2d(r), &pdf);
    Float ref = d.pdf(p);
    if (std::fabs(pdf - ref) > 1e-5f * ref) ++mismatches;
    *x = double(p.x);
    *y = double(p.y);
    return true;
  };
  RectChi2Config cfg{"distribution2d", 0, 1, 0, 1, 2 * nu, 2 * nv, 1000000, 61};
  EXPECT_TRUE(test::rect_chi2(sample, [&](double x, double y) { return double(d.pdf({Float(x), Float(y)})); }, cfg));
  EXPECT_EQ(mismatches, 0);
  // pdf is func / ∫func.
  double integral = 0;
  for (Float v : f) integral += double(v);
  integral /= nu * nv;
  EXPECT_NEAR(double(d.pdf({(2 + 0.5f) / nu, (3 + 0.5f) / nv})), double(f[size_t(3 * nu + 2)]) / integral, 1e-5);
}

// ---------------------------------------------------------------- samplers

Sampler sobol_sampler() {
  Sampler s;
  s.type = SamplerType::Sobol;
  return s;
}

/// Points of `count` consecutive sample indices starting at `first` for one pixel,
/// from the 2D pair that starts at dimension `dim` (even).
std::vector<Vec2> sobol_points(int px, int py, uint32_t first, uint32_t count, uint32_t dim, uint64_t seed) {
  Sampler s = sobol_sampler();
  std::vector<Vec2> pts;
  for (uint32_t i = first; i < first + count; ++i) {
    s.start_pixel_sample(px, py, i, seed);
    for (uint32_t k = 0; k < dim / 2; ++k) s.get_2d();
    pts.push_back(s.get_2d());
  }
  return pts;
}

/// True if every elementary interval 2^-a × 2^-b (a + b = m) holds exactly one point.
::testing::AssertionResult is_02_net(const std::vector<Vec2>& pts, int m) {
  const uint32_t n = 1u << m;
  if (pts.size() != n) return ::testing::AssertionFailure() << "wrong count";
  for (int a = 0; a <= m; ++a) {
    const int b = m - a;
    std::vector<int> cnt(n, 0);
    for (Vec2 p : pts) {
      uint32_t ix = uint32_t(double(p.x) * double(1u << a)), iy = uint32_t(double(p.y) * double(1u << b));
      ++cnt[(iy << a) | ix];
    }
    for (uint32_t c = 0; c < n; ++c)
      if (cnt[c] != 1)
        return ::testing::AssertionFailure() << "elementary interval " << (1u << a) << "x" << (1u << b) << " cell "
                                             << c << " has " << cnt[c] << " points";
  }
  return ::testing::AssertionSuccess();
}

TEST(Sobol, FirstPointsOfEveryPairAreA02Net) {
  // 256 points in 16×16 cells: exactly one each; and the finer statement that the
  // first 2^m points (and every aligned block of 2^m) are a (0,m,2)-net.
  for (int px : {0, 17, 1023})
    for (uint32_t dim : {0u, 2u, 6u, 30u}) {
      std::vector<Vec2> pts = sobol_points(px, 5, 0, 256, dim, 1234);
      std::vector<int> grid(256, 0);
      for (Vec2 p : pts) ++grid[size_t(int(p.y * 16) * 16 + int(p.x * 16))];
      EXPECT_TRUE(std::all_of(grid.begin(), grid.end(), [](int c) { return c == 1; }))
          << "pixel " << px << " dims " << dim << "," << dim + 1;
      for (int m = 1; m <= 10; ++m)
        EXPECT_TRUE(is_02_net(sobol_points(px, 5, 0, 1u << m, dim, 1234), m)) << "m=" << m << " dim " << dim;
      EXPECT_TRUE(is_02_net(sobol_points(px, 5, 256 * 3, 256, dim, 1234), 8)) << "block 3, dim " << dim;
    }
}

TEST(Sobol, OneDimensionalStratification) {
  Sampler s = sobol_sampler();
  for (uint32_t dim : {0u, 1u, 5u}) {
    std::vector<int> cnt(64, 0);
    for (uint32_t i = 0; i < 64; ++i) {
      s.start_pixel_sample(3, 4, i, 99);
      Float v = 0;
      for (uint32_t k = 0; k <= dim; ++k) v = s.get_1d();
      ++cnt[size_t(v * 64)];
    }
    EXPECT_TRUE(std::all_of(cnt.begin(), cnt.end(), [](int c) { return c == 1; })) << "dim " << dim;
  }
}

TEST(Sobol, UniformAcrossPixels) {
  // One point per pixel, random index and pair: points of different pixels are
  // independent, so the chi-square test is exact here.
  PCG32 pick(70, 1);
  auto sample = [&](PCG32& r, double* x, double* y) {
    Sampler s = sobol_sampler();
    s.start_pixel_sample(int(r.next_u32() % 4096), int(r.next_u32() % 4096), r.next_u32() % 4096, 5);
    uint32_t skip = r.next_u32() % 8;
    for (uint32_t k = 0; k < skip; ++k) s.get_2d();
    Vec2 p = s.get_2d();
    *x = double(p.x);
    *y = double(p.y);
    return true;
  };
  RectChi2Config cfg{"sobol across pixels", 0, 1, 0, 1, 32, 32, 1000000, 71};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
}

TEST(Sobol, UniformWithinOnePixel) {
  // Random sample indices of one pixel and pair: a random subset of one pixel's
  // scrambled sequence must be uniform (consecutive indices are stratified, which
  // FirstPointsOfEveryPairAreA02Net checks exactly).
  auto sample = [&](PCG32& r, double* x, double* y) {
    Sampler s = sobol_sampler();
    s.start_pixel_sample(12, 34, r.next_u32(), 5);
    s.get_2d();
    Vec2 p = s.get_2d();
    *x = double(p.x);
    *y = double(p.y);
    return true;
  };
  RectChi2Config cfg{"sobol one pixel, random indices", 0, 1, 0, 1, 32, 32, 1000000, 72};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
  // And the first 2^20 consecutive indices fill every cell of a 32×32 grid equally.
  std::vector<int> grid(1024, 0);
  Sampler s = sobol_sampler();
  for (uint32_t i = 0; i < (1u << 20); ++i) {
    s.start_pixel_sample(12, 34, i, 5);
    Vec2 p = s.get_2d();
    ++grid[size_t(int(p.y * 32) * 32 + int(p.x * 32))];
  }
  EXPECT_TRUE(std::all_of(grid.begin(), grid.end(), [](int c) { return c == 1024; }));
}

TEST(Sobol, PairsAreDecorrelated) {
  // Coordinates from two different pairs of the same pixel and index must be
  // jointly uniform (the padding: each pair shuffles the index independently).
  // Random indices (not consecutive ones) keep the samples independent.
  auto sample = [&](PCG32& r, double* x, double* y) {
    Sampler s = sobol_sampler();
    s.start_pixel_sample(7, 8, r.next_u32(), 5);
    Vec2 a = s.get_2d();
    Vec2 b = s.get_2d();
    *x = double(a.x);
    *y = double(b.y);
    return true;
  };
  RectChi2Config cfg{"sobol pair 0.x vs pair 1.y", 0, 1, 0, 1, 32, 32, 1000000, 73};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
}

TEST(Sobol, Deterministic) {
  Sampler a = sobol_sampler(), b = sobol_sampler();
  for (uint32_t i = 0; i < 64; ++i) {
    a.start_pixel_sample(9, 10, i, 77);
    b.start_pixel_sample(9, 10, i, 77);
    for (int d = 0; d < 12; ++d) {
      Float x = a.get_1d();
      EXPECT_EQ(float_as_bits(x), float_as_bits(b.get_1d()));
      EXPECT_EQ(float_as_bits(x), float_as_bits(owen_sobol_sample(i, uint32_t(d), a.pixel_seed)));
    }
    Vec2 p = a.get_2d(), q = b.get_2d();
    EXPECT_EQ(float_as_bits(p.x), float_as_bits(q.x));
    EXPECT_EQ(float_as_bits(p.y), float_as_bits(q.y));
    EXPECT_EQ(a.dimension, 14u);
  }
  // Different pixels and seeds give different streams.
  a.start_pixel_sample(9, 10, 3, 77);
  b.start_pixel_sample(10, 9, 3, 77);
  Float x = a.get_1d(), y = b.get_1d();
  EXPECT_NE(x, y);
  b.start_pixel_sample(9, 10, 3, 78);
  EXPECT_NE(x, b.get_1d());
  // get_2d aligns to an even dimension.
  a.start_pixel_sample(1, 1, 0, 0);
  a.get_1d();
  Vec2 p = a.get_2d();
  EXPECT_EQ(a.dimension, 4u);
  EXPECT_EQ(p.x, owen_sobol_sample(0, 2, a.pixel_seed));
  // Values lie in [0,1).
  for (uint32_t i = 0; i < 4096; ++i) {
    Float v = owen_sobol_sample(i, i % 7, 0x1234);
    ASSERT_GE(v, 0);
    ASSERT_LT(v, 1);
  }
}

TEST(Sobol, FastPathMatchesTheDefinitionBitForBit) {
  // owen_sobol_2d/1d rewrite the scramble composition with fewer bit reversals; they must
  // equal the definition N(S_d(N(index, s0)), s_{d+1}) exactly.
  PCG32 rng;
  rng.set_sequence(11, 3);
  for (int k = 0; k < 1000; ++k) {
    uint32_t v = k < 32 ? 1u << k : rng.next_u32();
    ASSERT_EQ(reverse_bits32(v), sobol_detail::reverse_bits32_constexpr(v)) << v;
    uint32_t x = v, y = ~v * 0x9e3779b9u;
    const uint32_t want_y = sobol_detail::reverse_bits32_constexpr(y);
    reverse_bits32_pair(&x, &y);
    ASSERT_EQ(x, sobol_detail::reverse_bits32_constexpr(v)) << v;
    ASSERT_EQ(y, want_y) << v;
  }
  for (int k = 0; k < 20000; ++k) {
    uint32_t index = k < 4096 ? uint32_t(k) : rng.next_u32();
    uint32_t pair = rng.next_u32() % 64, seed = rng.next_u32();
    SobolPairSeeds s(pair, seed);
    uint32_t shuffled = nested_uniform_scramble(index, s.shuffle);
    uint32_t x = nested_uniform_scramble(sobol_u32(shuffled, 0), s.x);
    uint32_t y = nested_uniform_scramble(sobol_u32(shuffled, 1), s.y);
    Vec2 p = owen_sobol_2d(index, pair, seed);
    ASSERT_EQ(float_as_bits(p.x), float_as_bits(u32_to_unit(x))) << index;
    ASSERT_EQ(float_as_bits(p.y), float_as_bits(u32_to_unit(y))) << index;
  }
}

TEST(Sobol, SupersetXorIsTheReversedDimensionOneMatrix) {
  // Z(c) = R(S1(c)): the dimension-1 generator matrix (byte tables from its direction
  // numbers) seen through bit reversal, as 15 word operations. Every single bit checks
  // one column of the matrix; random words check linearity.
  PCG32 rng;
  rng.set_sequence(2, 8);
  for (int k = 0; k < 100000; ++k) {
    uint32_t c = k < 32 ? 1u << k : rng.next_u32();
    ASSERT_EQ(sobol_detail::superset_xor(c), reverse_bits32(sobol_u32(c, 1))) << c;
  }
}

#if KAURI_SOBOL_VECTORS
TEST(Sobol, VectorBitReversalIsPerLane) {
  // The batch reverses words in vector lanes (byte shuffles with AVX2, shifts and masks
  // otherwise): every lane must be reverse_bits32 of its word, single bits included.
  PCG32 rng;
  rng.set_sequence(8, 3);
  for (int k = 0; k < 20000; ++k) {
    sobol_detail::U32x8 v;
    for (int i = 0; i < 8; ++i) v[i] = k < 4 ? 1u << (8 * k + 3 * i % 8) : rng.next_u32();
    const sobol_detail::U32x8 r8 = sobol_detail::reverse_words(v);
    const sobol_detail::U32x4 r4 = sobol_detail::reverse_words(sobol_detail::U32x4{v[0], v[1], v[2], v[3]});
    for (int i = 0; i < 8; ++i) ASSERT_EQ(r8[i], reverse_bits32(v[i])) << v[i];
    for (int i = 0; i < 4; ++i) ASSERT_EQ(r4[i], reverse_bits32(v[i])) << v[i];
  }
}
#endif

TEST(Sobol, BatchMatchesOwenSobol2dBitForBit) {
  // owen_sobol_batch computes four pairs in vector lanes (GCC/Clang) or by a loop
  // (elsewhere); both must be owen_sobol_2d exactly, at any batch start and seed.
  PCG32 rng;
  rng.set_sequence(4, 6);
  Float out[2 * kSobolBatch];
  for (int k = 0; k < 20000; ++k) {
    uint32_t index = k < 4096 ? uint32_t(k) : rng.next_u32();
    uint32_t first = k % 3 == 0 ? rng.next_u32() : kSobolBatch * (rng.next_u32() % 32);
    uint32_t seed = rng.next_u32();
    owen_sobol_batch(reverse_bits32(index), first, seed, out);
    for (uint32_t i = 0; i < kSobolBatch; ++i) {
      Vec2 p = owen_sobol_2d(index, first + i, seed);
      ASSERT_EQ(float_as_bits(out[i]), float_as_bits(p.x)) << index << " pair " << first + i;
      ASSERT_EQ(float_as_bits(out[kSobolBatch + i]), float_as_bits(p.y)) << index << " pair " << first + i;
      ASSERT_GE(out[i], 0);
      ASSERT_LT(out[kSobolBatch + i], 1);
    }
  }
}

// A sampler reading its pair seeds from a SobolSeedCache must draw what one hashing its
// own draws, bit for bit: past the table's pairs, after the pixel seed changes (the cache
// refills), with the cache shared by samplers of different seeds in turn.
TEST(Sobol, SeedCacheLeavesEverySampleAsItWas) {
  SobolSeedCache cache;
  for (SamplerType type : {SamplerType::Sobol, SamplerType::ZSobol})
    for (int px = 0; px < 6; ++px) {
      Sampler plain, cached;
      plain.type = cached.type = type;
      plain.set_samples_per_pixel(64);
      cached.set_samples_per_pixel(64);
      cached.seeds = &cache;
      for (uint32_t i = 0; i < 70; i += 3) {  // 64 … 69: ZSobol's per-pixel fallback seed
        plain.start_pixel_sample(px, 2 * px + 1, i, 99);
        cached.start_pixel_sample(px, 2 * px + 1, i, 99);
        for (uint32_t d = 0; d < 2 * (SobolSeedCache::kBatches + 2) * kSobolBatch; ++d) {
          const Vec2 a = plain.get_2d(), b = cached.get_2d();
          ASSERT_EQ(float_as_bits(a.x), float_as_bits(b.x)) << int(type) << " px " << px << " i " << i << " d " << d;
          ASSERT_EQ(float_as_bits(a.y), float_as_bits(b.y)) << int(type) << " px " << px << " i " << i << " d " << d;
        }
      }
    }
  // The cache is used: its seed is the last pixel's, some batches filled, none past it.
  EXPECT_NE(cache.filled, 0u);
  EXPECT_EQ(cache.filled >> SobolSeedCache::kBatches, 0u);
}

// get_2d_n (the path lanes' three pairs a bounce) must be n calls of get_2d: the same
// values and the same state after, from odd and even dimensions, within a batch and
// across a batch's end, for every sampler type, including right after a sample starts
// (no batch computed yet).
TEST(Sobol, SeveralPairsAtOnceAreConsecutiveGet2d) {
  PCG32 rng;
  rng.set_sequence(12, 3);
  for (SamplerType type : {SamplerType::Sobol, SamplerType::ZSobol, SamplerType::Independent})
    for (int trial = 0; trial < 3000; ++trial) {
      Sampler a;
      a.type = type;
      a.set_samples_per_pixel(64);
      a.start_pixel_sample(int(rng.next_u32() % 32), int(rng.next_u32() % 32), rng.next_u32() % 64, 77);
      const int skip = int(rng.next_u32() % 21);  // 1D requests: an odd dimension half the time
      for (int i = 0; i < skip; ++i) a.get_1d();
      Sampler b = a;
      const int n = 1 + int(rng.next_u32() % 4);
      Vec2 u[4];
      b.get_2d_n(u, n);
      for (int i = 0; i < n; ++i) {
        const Vec2 v = a.get_2d();
        ASSERT_EQ(float_as_bits(u[i].x), float_as_bits(v.x)) << int(type) << " trial " << trial << " pair " << i;
        ASSERT_EQ(float_as_bits(u[i].y), float_as_bits(v.y)) << int(type) << " trial " << trial << " pair " << i;
      }
      ASSERT_EQ(a.dimension, b.dimension);
      const Vec2 va = a.get_2d(), vb = b.get_2d();  // and the stream goes on alike
      ASSERT_EQ(float_as_bits(va.x), float_as_bits(vb.x));
      ASSERT_EQ(float_as_bits(va.y), float_as_bits(vb.y));
    }
}

// The Sampler's request stream (1D requests share a pair, 2D requests start on an even
// dimension) must be exactly the padded sequence: 1D values are coordinates of
// owen_sobol_2d, whatever mix of 1D and 2D requests and skips a path makes.
TEST(Sobol, SamplerRequestsFollowTheDimensionLayout) {
  PCG32 rng;
  rng.set_sequence(5, 9);
  // One Sampler throughout, as the render loop keeps one per pixel: a new sample or pixel
  // must drop the cached batch of pairs; 40 requests cross several batches.
  Sampler s;
  int px = 0, py = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    uint32_t index = rng.next_u32() % 1024;
    if (trial % 3 == 0) {
      px = int(rng.next_u32() % 64);
      py = int(rng.next_u32() % 64);
    }
    s.start_pixel_sample(px, py, index, 17);
    uint32_t dim = 0;
    for (int r = 0; r < 40; ++r) {
      const uint32_t op = rng.next_u32() % 4;
      if (op == 2) {  // skips move the dimension exactly as the request would
        s.skip_1d();
        ++dim;
      } else if (op == 3) {
        s.skip_2d();
        dim += (dim & 1) + 2;
      } else if (op == 1) {
        Float v = s.get_1d();
        Vec2 p = owen_sobol_2d(index, dim >> 1, s.pixel_seed);
        ASSERT_EQ(float_as_bits(v), float_as_bits(dim & 1 ? p.y : p.x)) << trial << " " << r;
        ++dim;
      } else {
        dim += dim & 1;
        Vec2 v = s.get_2d(), p = owen_sobol_2d(index, dim >> 1, s.pixel_seed);
        ASSERT_EQ(float_as_bits(v.x), float_as_bits(p.x));
        ASSERT_EQ(float_as_bits(v.y), float_as_bits(p.y));
        dim += 2;
      }
    }
  }
}

// ---------------------------------------------------------------- ZSobol

/// Points of pair `pair` of every sample of the pixels in [x0, x0 + w) × [y0, y0 + h)
/// under a ZSobol (or Sobol) sampler told the render takes `spp` samples per pixel.
std::vector<Vec2> pixel_block_points(SamplerType type, int x0, int y0, int w, int h, uint32_t spp, uint32_t pair,
                                     uint64_t seed) {
  Sampler s;
  s.type = type;
  s.set_samples_per_pixel(spp);
  std::vector<Vec2> pts;
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x)
      for (uint32_t i = 0; i < spp; ++i) {
        s.start_pixel_sample(x, y, i, seed);
        for (uint32_t k = 0; k < pair; ++k) s.get_2d();
        pts.push_back(s.get_2d());
      }
  return pts;
}

TEST(ZSobol, PixelOrderIsAHierarchicalBijection) {
  // Every pixel of a 64×64 super-tile gets its own position, and every aligned
  // 2^k × 2^k block a contiguous run of 4^k positions (the quadtree the nets rest on).
  for (uint32_t seed : {0u, 7u, 0xdeadbeefu}) {
    std::vector<uint32_t> z(64 * 64);
    std::vector<int> seen(64 * 64, 0);
    for (uint32_t y = 0; y < 64; ++y)
      for (uint32_t x = 0; x < 64; ++x) {
        z[y * 64 + x] = zsobol_pixel_index(x, y, 6, seed);
        ASSERT_LT(z[y * 64 + x], 4096u);
        ++seen[z[y * 64 + x]];
      }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
    for (uint32_t k = 1; k <= 5; ++k) {
      const uint32_t side = 1u << k;
      for (uint32_t by = 0; by < 64; by += side)
        for (uint32_t bx = 0; bx < 64; bx += side) {
          const uint32_t run = z[by * 64 + bx] >> (2 * k);
          for (uint32_t y = by; y < by + side; ++y)
            for (uint32_t x = bx; x < bx + side; ++x) ASSERT_EQ(z[y * 64 + x] >> (2 * k), run);
        }
    }
    // Skipping the levels above a pixel's highest bit is exact: the same as running
    // every level of the b-bit tree (their digits are 0 whatever the partner).
    auto every_level = [&](uint32_t x, uint32_t y, uint32_t b) {
      uint32_t zz = 0;
      for (uint32_t l = b; l-- > 0;) {
        const uint32_t h = hash_u32((zz | (1u << (2 * (b - 1 - l)))) ^ seed);
        const uint32_t partner = uint32_t((uint64_t(h) * 3) >> 32);
        const uint32_t xb = (x >> l) & 1, yb = (y >> l) & 1;
        zz = (zz << 2) | ((partner == 0 ? yb : partner == 1 ? xb : xb ^ yb) << 1) | (partner == 1 ? yb : xb);
      }
      return zz;
    };
    for (uint32_t b : {6u, 12u})
      for (uint32_t y = 0; y < 64; y += 3)
        for (uint32_t x = 0; x < 64; x += 5) ASSERT_EQ(zsobol_pixel_index(x, y, b, seed), every_level(x, y, b));
  }
}

TEST(ZSobol, PartnersAreHorizontalVerticalAndDiagonalAlike) {
  // The pixel whose position differs in the last bit (its block completes a (0,m+1,2)-net
  // with this one) is the horizontal, vertical or diagonal neighbour, 1/3 each; a plain
  // Morton order (or bit flips alone) would always make it the horizontal one.
  int count[3] = {0, 0, 0};
  PCG32 rng(91, 2);
  const int n = 30000;
  for (int t = 0; t < n; ++t) {
    const uint32_t seed = rng.next_u32(), qx = 2 * (rng.next_u32() % 512), qy = 2 * (rng.next_u32() % 512);
    const uint32_t z0 = zsobol_pixel_index(qx, qy, 10, seed);
    int found = -1;
    for (uint32_t d = 1; d < 4; ++d)
      if (zsobol_pixel_index(qx + (d & 1), qy + (d >> 1), 10, seed) == (z0 ^ 1u)) found = int(d);
    ASSERT_GE(found, 1);
    ++count[found == 1 ? 0 : found == 2 ? 1 : 2];  // d = 1: +x, 2: +y, 3: diagonal
  }
  double chi2 = 0;
  for (int c : count) chi2 += (c - n / 3.0) * (c - n / 3.0) / (n / 3.0);
  EXPECT_LT(chi2, 18.4) << count[0] << " " << count[1] << " " << count[2];  // 2 dof, p = 1e-4
}

TEST(ZSobol, EveryPixelIsANetAndSoIsEveryAlignedBlock) {
  // spp 64 (m = 6): a pixel's 64 points, an aligned 2×2 quad's 256 and an aligned 4×4
  // block's 1024 are (0,6,2)-, (0,8,2)- and (0,10,2)-nets in every dimension pair.
  for (uint32_t pair : {0u, 1u, 3u, 7u}) {
    EXPECT_TRUE(is_02_net(pixel_block_points(SamplerType::ZSobol, 5, 9, 1, 1, 64, pair, 3), 6)) << pair;
    EXPECT_TRUE(is_02_net(pixel_block_points(SamplerType::ZSobol, 4, 8, 2, 2, 64, pair, 3), 8)) << pair;
    EXPECT_TRUE(is_02_net(pixel_block_points(SamplerType::ZSobol, 12, 8, 4, 4, 64, pair, 3), 10)) << pair;
    // Per-pixel Sobol' keeps the pixel's net but not the quad's: the test can tell.
    EXPECT_TRUE(is_02_net(pixel_block_points(SamplerType::Sobol, 5, 9, 1, 1, 64, pair, 3), 6)) << pair;
    EXPECT_FALSE(is_02_net(pixel_block_points(SamplerType::Sobol, 4, 8, 2, 2, 64, pair, 3), 8)) << pair;
  }
  // spp 100 (blocks of 128): a pixel's first 64 points are still a (0,6,2)-net.
  std::vector<Vec2> p = pixel_block_points(SamplerType::ZSobol, 3, 3, 1, 1, 100, 2, 5);
  p.resize(64);
  EXPECT_TRUE(is_02_net(p, 6));
}

TEST(ZSobol, SuperTilesAndSeedsAreIndependentAndOverflowFallsBack) {
  Sampler a, b;
  a.type = b.type = SamplerType::ZSobol;
  a.set_samples_per_pixel(256);  // b = 12: super-tiles of 4096 × 4096
  b.set_samples_per_pixel(256);
  ASSERT_EQ(zsobol_tile_bits(8), 12u);
  a.start_pixel_sample(5, 6, 3, 1);
  b.start_pixel_sample(5 + 4096, 6, 3, 1);  // same place in the next super-tile
  EXPECT_NE(float_as_bits(a.get_1d()), float_as_bits(b.get_1d()));
  b.start_pixel_sample(5, 6, 3, 2);  // another render seed
  a.start_pixel_sample(5, 6, 3, 1);
  EXPECT_NE(float_as_bits(a.get_1d()), float_as_bits(b.get_1d()));
  // An index past the announced block would run into the next pixel's points: it takes
  // the pixel's own Sobol' sequence instead.
  Sampler sob;
  sob.type = SamplerType::Sobol;
  a.start_pixel_sample(5, 6, 256, 1);
  sob.start_pixel_sample(5, 6, 256, 1);
  for (int d = 0; d < 8; ++d) EXPECT_EQ(float_as_bits(a.get_1d()), float_as_bits(sob.get_1d()));
  // No room for pixel bits (2^31 spp): the sampler is the per-pixel one.
  EXPECT_EQ(zsobol_tile_bits(31), 0u);
  EXPECT_EQ(ceil_log2(1), 0u);
  EXPECT_EQ(ceil_log2(100), 7u);
  EXPECT_EQ(ceil_log2(256), 8u);
}

TEST(ZSobol, KeptPixelStateMatchesAFreshSampler) {
  // The sampler keeps the last pixel's block and seed: reused in any order of pixels,
  // seeds and indices, it gives what a fresh sampler gives, bit for bit.
  PCG32 rng(17, 4);
  Sampler kept;
  kept.type = SamplerType::ZSobol;
  kept.set_samples_per_pixel(64);
  for (int t = 0; t < 3000; ++t) {
    const int px = int(rng.next_u32() % 6), py = int(rng.next_u32() % 6);
    const uint32_t index = rng.next_u32() % 80;  // some beyond the block of 64
    const uint64_t seed = rng.next_u32() % 3;
    Sampler fresh;
    fresh.type = SamplerType::ZSobol;
    fresh.set_samples_per_pixel(64);
    kept.start_pixel_sample(px, py, index, seed);
    fresh.start_pixel_sample(px, py, index, seed);
    for (int d = 0; d < 6; ++d) ASSERT_EQ(float_as_bits(kept.get_1d()), float_as_bits(fresh.get_1d())) << t;
  }
}

TEST(ZSobol, UniformAcrossPixelsAndPairs) {
  // One point per draw from a random render seed, pixel, index and pair: uniform. And two
  // pairs of one sample (pair 0.x against pair 1.y) jointly uniform: the padding holds.
  // Each draw takes its own render seed, so draws are independent and the chi-square
  // exact (a million draws from one render's 4M points would also see that finite set's
  // own chance departures, which for the joint of two pairs are as large as random's).
  auto one = [&](PCG32& r, double* x, double* y) {
    Sampler s;
    s.type = SamplerType::ZSobol;
    s.set_samples_per_pixel(64);
    s.start_pixel_sample(int(r.next_u32() % 2048), int(r.next_u32() % 2048), r.next_u32() % 64, r.next_u32());
    for (uint32_t k = r.next_u32() % 8; k > 0; --k) s.get_2d();
    Vec2 p = s.get_2d();
    *x = double(p.x);
    *y = double(p.y);
    return true;
  };
  RectChi2Config cfg{"zsobol across pixels", 0, 1, 0, 1, 32, 32, 1000000, 74};
  EXPECT_TRUE(test::rect_chi2(one, [](double, double) { return 1.0; }, cfg));
  auto two = [&](PCG32& r, double* x, double* y) {
    Sampler s;
    s.type = SamplerType::ZSobol;
    s.set_samples_per_pixel(1024);
    s.start_pixel_sample(int(r.next_u32() % 64), int(r.next_u32() % 64), r.next_u32() % 1024, r.next_u32());
    Vec2 a = s.get_2d();
    Vec2 b = s.get_2d();
    *x = double(a.x);
    *y = double(b.y);
    return true;
  };
  RectChi2Config cfg2{"zsobol pair 0.x vs pair 1.y", 0, 1, 0, 1, 32, 32, 1000000, 75};
  EXPECT_TRUE(test::rect_chi2(two, [](double, double) { return 1.0; }, cfg2));
}

TEST(IndependentSampler, Uniform) {
  auto sample = [&](PCG32& r, double* x, double* y) {
    Sampler s;
    s.type = SamplerType::Independent;
    s.start_pixel_sample(int(r.next_u32() % 4096), 3, r.next_u32(), 9);
    s.get_1d();
    Vec2 p = s.get_2d();
    *x = double(p.x);
    *y = double(p.y);
    return true;
  };
  RectChi2Config cfg{"independent sampler", 0, 1, 0, 1, 32, 32, 500000, 80};
  EXPECT_TRUE(test::rect_chi2(sample, [](double, double) { return 1.0; }, cfg));
  Sampler a, b;
  a.type = b.type = SamplerType::Independent;
  a.start_pixel_sample(1, 2, 3, 4);
  b.start_pixel_sample(1, 2, 3, 4);
  EXPECT_EQ(a.get_1d(), b.get_1d());
}

}  // namespace
}  // namespace kauri
