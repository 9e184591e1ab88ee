// Statistical tests of light sampling (light/light.h, light_sampling.inl): the
// directions sample_light() produces from a reference point follow light_pdf()
// (chi-square over the sphere; for area lights the density is evaluated where
// each direction meets the light, found here by independent ray intersection in
// double precision), the estimators L/pdf integrate to analytic values (solid
// angles, irradiance of polygons, disks and spheres), and the delta lights'
// falloffs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "chi2.h"
#include "kauri/bsdf/cosine_sampling.h"
#include "kauri/light/env_importance.h"
#include "kauri/integrator/path_tracer.h"
#include "kauri/light/light.h"
#include "kauri/sampler/distribution.h"
#include "kauri/scene/scene.h"
#include "kauri/spectral/color_space.h"
#include "kauri/spectral/spectral_tables.h"

namespace kauri {
namespace {

using test::kPiD;
using test::SphereChi2Config;

Vec2 next_2d(PCG32& rng) {
  Float a = rng.next_float();
  return {a, rng.next_float()};
}

SampledWavelengths test_wavelengths() { return SampledWavelengths::sample_visible(0.3f); }

DenselySampled d65() { return {tables::kCieD65, tables::kCieLambdaMin, 1, tables::kCieSamples}; }

// ---------------------------------------------------------------- lights, built as scene_compile.cpp does

Light triangle_light(Point3 p0, Point3 p1, Point3 p2, bool two_sided = false) {
  Light l;
  l.type = LightType::Triangle;
  l.Le = Spectrum::make_constant(1);
  l.two_sided = two_sided;
  l.p0 = p0;
  l.p1 = p1;
  l.p2 = p2;
  Vec3 c = cross(p1 - p0, p2 - p0);
  l.area = length(c) / 2;
  l.n = normalize(c);
  return l;
}

Light disk_light(Point3 c, Normal3 n, Float radius) {
  Light l;
  l.type = LightType::Disk;
  l.Le = Spectrum::make_constant(1);
  l.p0 = c;
  l.n = normalize(n);
  l.radius = radius;
  l.area = kPi * radius * radius;
  l.frame = Frame::from_z(l.n);
  return l;
}

Light sphere_light(Point3 c, Float radius, bool two_sided = false) {
  Light l;
  l.type = LightType::Sphere;
  l.Le = Spectrum::make_constant(1);
  l.two_sided = two_sided;
  l.p0 = c;
  l.radius = radius;
  l.area = 4 * kPi * radius * radius;
  return l;
}

Light distant_light(Vec3 n, Float cos_max) {
  Light l;
  l.type = LightType::Distant;
  l.Le = Spectrum::make_constant(1);
  l.n = normalize(n);
  l.cos_max = cos_max;
  l.frame = Frame::from_z(-l.n);
  return l;
}

/// A small lat-long environment map with random texels (some black), its
/// Distribution2D built by env_importance() as scene_compile.cpp does.
struct EnvMapFixture {
  int w = 16, h = 8;
  std::vector<EnvTexel> texels;
  std::unique_ptr<Distribution2DStorage> dist, compensated;
  Light light;

  EnvMapFixture(const Frame& frame, uint64_t seed) {
    PCG32 rng(seed, 1);
    texels.resize(size_t(w * h));
    std::vector<Float> lum(texels.size());
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        size_t i = size_t(y * w + x);
        Float scale = rng.next_float() < 0.2f ? 0 : 2 * rng.next_float();
        if (y == 2) scale = 0;  // a whole black row
        // Constant sigmoid (c0 = c1 = 0): radiance = scale · s(c2) · D65(λ).
        Float c2 = 4 * rng.next_float() - 2;
        texels[i] = {scale, 0, 0, c2};
        lum[i] = scale * (0.5f + c2 / (2 * std::sqrt(1 + c2 * c2)));
      }
    }
    dist = std::make_unique<Distribution2DStorage>(env_importance(lum, w, h), w, h);
    compensated = std::make_unique<Distribution2DStorage>(env_importance_compensated(lum, w, h), w, h);
    light.type = LightType::EnvMap;
    light.frame = frame;
    light.distribution = dist->view();
    light.compensated = compensated->view();
    light.width = w;
    light.height = h;
    light.illuminant = d65();
    light.texels = texels.data();
    light.scene_radius = 10;
  }
  /// ∫ L dω over the sphere at wavelength `lambda` for the bilinear reconstruction, by an
  /// independent quadrature in double: in u the interpolation between texel centres keeps
  /// each row's sum exactly (u wraps around); in v, radiance is linear between row centres
  /// and clamped above the first and below the last, integrated against sinθ with 64
  /// midpoints per row.
  double radiance_integral(Float lambda) const {
    std::vector<double> row(size_t(h), 0.0);  // per row: Σ_x L(x, y) · Δu
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const EnvTexel& t = texels[size_t(y * w + x)];
        double sig = 0.5 + double(t.c2) / (2 * std::sqrt(1 + double(t.c2) * double(t.c2)));
        row[size_t(y)] += double(t.scale) * sig * double(d65()(lambda)) / w;
      }
    double sum = 0;
    const int n = 64 * h;
    for (int k = 0; k < n; ++k) {
      double v = (k + 0.5) / n, fy = v * h - 0.5;
      int y0 = int(std::floor(fy));
      double dy = fy - y0;
      double a = row[size_t(std::clamp(y0, 0, h - 1))], b = row[size_t(std::clamp(y0 + 1, 0, h - 1))];
      // dω = 2π² sin(πv) du dv
      sum += ((1 - dy) * a + dy * b) * 2 * kPiD * kPiD * std::sin(kPiD * v) / n;
    }
    return sum;
  }
};

/// Rotation by `angle` about unit `axis` as a Frame (columns = images of x, y, z).
Frame rotation_frame(Vec3 axis, double angle) {
  axis = normalize(axis);
  auto rot = [&](Vec3 v) {
    double c = std::cos(angle), s = std::sin(angle);
    Vec3 k = axis;
    Vec3 kxv = cross(k, v);
    double kv = double(dot(k, v));
    return Vec3{Float(double(v.x) * c + double(kxv.x) * s + double(k.x) * kv * (1 - c)),
                Float(double(v.y) * c + double(kxv.y) * s + double(k.y) * kv * (1 - c)),
                Float(double(v.z) * c + double(kxv.z) * s + double(k.z) * kv * (1 - c))};
  };
  Frame f;
  f.x = rot({1, 0, 0});
  f.y = rot({0, 1, 0});
  f.z = rot({0, 0, 1});
  return f;
}

// ---------------------------------------------------------------- independent ray intersection (double)

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {double(v.x), double(v.y), double(v.z)}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double ddot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 dcross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dlen(D3 a) { return std::sqrt(ddot(a, a)); }
D3 dnorm(D3 a) { return a * (1 / dlen(a)); }
Vec3 f3(D3 a) { return {Float(a.x), Float(a.y), Float(a.z)}; }

double sqr_d(double x) { return x * x; }

struct LightHit {
  bool hit = false;
  D3 p{0, 0, 0};
  D3 n{0, 0, 0};
  double t = 0;
};

/// Where the ray p + t·w (t > 0) first meets an area light.
LightHit intersect_light(const Light& l, Point3 p_, Vec3 w_, double slack = 0) {
  LightHit h;
  D3 p = d3(p_), w = dnorm(d3(w_));
  switch (l.type) {
    case LightType::Triangle: {  // Möller–Trumbore
      D3 p0 = d3(l.p0), e1 = d3(l.p1) - p0, e2 = d3(l.p2) - p0;
      D3 q = dcross(w, e2);
      double det = ddot(e1, q);
      if (std::fabs(det) < 1e-300) return h;
      D3 s = p - p0;
      double u = ddot(s, q) / det;
      D3 r = dcross(s, e1);
      double v = ddot(w, r) / det;
      double t = ddot(e2, r) / det;
      if (u < -slack || v < -slack || u + v > 1 + slack || t <= 0) return h;
      h = {true, p + w * t, dnorm(dcross(e1, e2)), t};
      return h;
    }
    case LightType::Disk: {
      D3 n = dnorm(d3(l.n)), c = d3(l.p0);
      double dn = ddot(w, n);
      if (dn == 0) return h;
      double t = ddot(c - p, n) / dn;
      D3 x = p + w * t;
      if (t <= 0 || ddot(x - c, x - c) > sqr_d(double(l.radius) * (1 + slack))) return h;
      h = {true, x, n, t};
      return h;
    }
    case LightType::Sphere: {
      D3 c = d3(l.p0), to_c = c - p;
      double r = double(l.radius) * (1 + slack), b = ddot(w, to_c);
      D3 perp = to_c - w * b;
      double disc = r * r - ddot(perp, perp);
      if (disc < 0) return h;
      bool inside = ddot(to_c, to_c) < r * r;
      double t = inside ? b + std::sqrt(disc) : b - std::sqrt(disc);
      if (t <= 0) return h;
      D3 x = p + w * t;
      h = {true, x, dnorm(x - c), t};
      return h;
    }
    default: return h;
  }
}

/// Whether point x lies on an area light (to 1e-4 of its size).
bool on_light(const Light& l, D3 x) {
  switch (l.type) {
    case LightType::Sphere: return std::fabs(dlen(x - d3(l.p0)) - double(l.radius)) <= 1e-4 * double(l.radius);
    case LightType::Disk: {
      D3 c = d3(l.p0), n = dnorm(d3(l.n));
      return std::fabs(ddot(x - c, n)) <= 1e-4 * double(l.radius) && dlen(x - c) <= double(l.radius) * (1 + 1e-4);
    }
    case LightType::Triangle: {
      D3 p0 = d3(l.p0), e1 = d3(l.p1) - p0, e2 = d3(l.p2) - p0, n = dcross(e1, e2), q = x - p0;
      double size = std::sqrt(dlen(n));
      if (std::fabs(ddot(q, dnorm(n))) > 1e-4 * size) return false;
      double nn = ddot(n, n), b1 = ddot(dcross(q, e2), n) / nn, b2 = ddot(dcross(e1, q), n) / nn;
      return b1 >= -1e-4 && b2 >= -1e-4 && b1 + b2 <= 1 + 1e-4;
    }
    default: return false;
  }
}

/// light_pdf() in the direction w, evaluated where w meets the light (0 if it misses).
double light_pdf_along(const Light& l, Point3 p, Vec3 w) {
  if (l.is_infinite()) return double(light_pdf(l, p, w, {}, {}));
  LightHit h = intersect_light(l, p, w);
  if (!h.hit) return 0;
  return double(light_pdf(l, p, w, f3(h.p), f3(h.n)));
}

/// Chi-square test of sample_light() from p against light_pdf(), plus per-sample
/// consistency: s.pdf == light_pdf at the sample, the sampled point is where the
/// direction meets the light, and s.L is the light's radiance there.
void check_light_sampling(const Light& l, Point3 p, Vec3 pole, const std::string& name, uint64_t seed,
                          int samples = 500000) {
  const SampledWavelengths lambda = test_wavelengths();
  int pdf_mismatch = 0, point_mismatch = 0;
  auto sample = [&](PCG32& r, Vec3* w) {
    LightSample s = sample_light(l, p, next_2d(r), lambda);
    if (!(s.pdf > 0)) return false;
    *w = s.wi;
    Float ref = light_pdf(l, p, s.wi, s.p_light, s.n_light);
    // A distant light's cone edge: float rounding can put a sampled direction an
    // ulp outside the cone, where light_pdf() is 0 (and its radiance too).
    bool on_cone_edge = l.type == LightType::Distant && std::fabs(dot(s.wi, -l.n) - l.cos_max) < 1e-6f;
    if (std::fabs(ref - s.pdf) > 1e-3f * ref && !on_cone_edge) ++pdf_mismatch;
    if (!l.is_infinite()) {
      // The ray along wi meets the light where the sample says. Float rounding is
      // allowed for at the light's edges (the ray may pass within 1e-5 of a triangle
      // edge or disk rim) and for grazing hits, where the hit distance along the ray
      // is ill-conditioned: then the sampled point must at least lie on the light.
      LightHit h = intersect_light(l, p, s.wi);
      const D3 pl = d3(s.p_light);
      const double tol = 1e-4 * dlen(pl - d3(p)) + 1e-5;
      bool ok = h.hit && dlen(h.p - pl) <= tol;
      if (!ok) {
        LightHit g = intersect_light(l, p, s.wi, 1e-5);
        bool edge_or_grazing = g.hit && (!h.hit || std::fabs(ddot(g.n, dnorm(d3(s.wi)))) < 0.02);
        ok = edge_or_grazing && on_light(l, pl);
      }
      if (!ok) ++point_mismatch;
    }
    return true;
  };
  SphereChi2Config cfg;
  cfg.name = name;
  cfg.frame = Frame::from_z(normalize(pole));
  cfg.seed = seed;
  cfg.samples = samples;
  EXPECT_TRUE(test::sphere_chi2(sample, [&](Vec3 w) { return light_pdf_along(l, p, w); }, cfg));
  EXPECT_EQ(pdf_mismatch, 0) << name << ": sample pdf != light_pdf()";
  EXPECT_EQ(point_mismatch, 0) << name << ": sampled point is not where the direction meets the light";
}

// ---------------------------------------------------------------- chi-square per light type

TEST(LightSampling, Triangle) {
  Light l = triangle_light({-1, -0.5f, 2}, {0.5f, 1.5f, 2.5f}, {1.5f, -1, 1.5f});
  Point3 p{0.1f, 0.2f, -0.3f};
  Point3 centroid = (l.p0 + l.p1 + l.p2) / 3;
  check_light_sampling(l, p, centroid - p, "triangle light", 1000);
  // Seen nearly edge-on: the area→solid-angle Jacobian varies strongly.
  Light g = triangle_light({-1, 0, 0}, {1, 0, 0}, {0, 2, 0.3f});
  Point3 q{0, -1, 0.15f};
  check_light_sampling(g, q, (g.p0 + g.p1 + g.p2) / 3 - q, "triangle light, grazing", 1001);
}

TEST(LightSampling, Disk) {
  Light l = disk_light({0.5f, 0.3f, 3}, {0.3f, -0.2f, -1}, 1.2f);
  Point3 p{-0.4f, 0.2f, 0.5f};
  check_light_sampling(l, p, l.p0 - p, "disk light", 1100);
}

TEST(LightSampling, SphereOutsideAndInside) {
  Light l = sphere_light({1, 2, 3}, 1.5f);
  Point3 p{0.5f, -0.5f, -0.2f};
  check_light_sampling(l, p, l.p0 - p, "sphere light, outside (cone)", 1200);
  Point3 q{1, 2.1f, 4.6f};  // 0.07 r from the surface: nearly a hemisphere
  check_light_sampling(l, q, l.p0 - q, "sphere light, outside close", 1201);
  Point3 in{1.4f, 2.3f, 2.5f};
  check_light_sampling(l, in, {0, 0, 1}, "sphere light, inside (area sampling)", 1202);
}

TEST(LightSampling, DistantCone) {
  Light l = distant_light({0.3f, -0.5f, -0.8f}, 0.95f);
  check_light_sampling(l, {1, 2, 3}, -l.n, "distant light cone", 1300);
}

TEST(LightSampling, EnvConstant) {
  Light l;
  l.type = LightType::EnvConstant;
  l.Le = Spectrum::make_constant(1);
  check_light_sampling(l, {0, 0, 0}, {0, 0, 1}, "constant environment", 1400);
}

/// Environment maps are tested in their own lat-long square (u, v): the
/// solid-angle density is pdf_uv / (2π² sinθ), singular at the poles, which
/// midpoint quadrature over (cosθ, φ) cells cannot integrate accurately; in (u, v)
/// the density is piecewise constant and the cells are aligned with the texels.
/// Within sinθ < 0.05 of a pole, u of a float direction is ill-conditioned (a
/// rotated frame moves it by ~1e-7/sinθ, across texel edges): those polar caps are
/// left out of the chi-square test (as "no sample", and the density there as 0).
constexpr double kPolarCap = 0.05;

void check_envmap_sampling(const EnvMapFixture& env, Point3 p, const std::string& name, uint64_t seed,
                           LightDensity density = LightDensity::Complete) {
  const Light& l = env.light;
  const SampledWavelengths lambda = test_wavelengths();
  int pdf_mismatch = 0, near_pole = 0, near_texel_edge = 0, radiance_mismatch = 0;
  auto sample = [&](PCG32& r, double* x, double* y) {
    LightSample s = sample_light(l, p, next_2d(r), lambda, density);
    if (!(s.pdf > 0)) return false;
    D3 loc{double(dot(s.wi, l.frame.x)), double(dot(s.wi, l.frame.y)), double(dot(s.wi, l.frame.z))};
    loc = dnorm(loc);
    double u = std::atan2(loc.x, -loc.z) / (2 * kPiD);
    if (u < 0) u += 1;
    *x = u;
    *y = std::acos(std::clamp(loc.y, -1.0, 1.0)) / kPiD;
    const bool polar_cap = std::sin(kPiD * *y) < kPolarCap;
    // The density light_pdf() reports for the sampled direction. Near the poles the
    // direction ↔ (u, v) round trip loses precision in float (acos near ±1), and the
    // density ∝ 1/sinθ is steep there: those samples are counted apart.
    Float ref = light_pdf(l, p, s.wi, s.p_light, s.n_light, density);
    // Likewise, a direction within float rounding of a texel edge may come back in
    // the neighbouring texel after the frame rotation.
    auto near_edge = [](double t) { return std::fabs(t - std::round(t)) < 1e-4; };
    if (std::fabs(ref - s.pdf) > 1e-3f * ref) {
      if (std::sin(kPiD * *y) < 0.05)
        ++near_pole;
      else if (near_edge(*x * env.w) || near_edge(*y * env.h))
        ++near_texel_edge;
      else
        ++pdf_mismatch;
    }
    // s.L is the radiance at the sampled (u, v), which the direction s.wi carries to float
    // precision: it must match the lookup at the (u, v) of s.wi found in double precision
    // (outside the polar caps, where u is ill-conditioned). Relative to the radiance, or to
    // ~1% of the brightest texels (~2 · D65, ~100) where it is darker: the fixture's black
    // row, where the interpolated radiance tends to 0.
    if (!polar_cap) {
      SampledSpectrum L = env_texel_radiance(l, {Float(*x), Float(*y)}, lambda);
      for (int i = 0; i < kSpectrumSamples; ++i)
        if (std::fabs(double(L[i] - s.L[i])) > 1e-3 * std::max(double(L[i]), 1.0)) ++radiance_mismatch;
    }
    return !polar_cap;
  };
  auto pdf_uv = [&](double u, double v) {
    if (std::sin(kPiD * v) < kPolarCap) return 0.0;
    Vec3 w = l.frame.to_world(latlong_to_direction({Float(u), Float(v)}));
    return double(light_pdf(l, p, w, {}, {}, density)) * 2 * kPiD * kPiD * std::sin(kPiD * v);
  };
  test::RectChi2Config cfg(name, 0, 1, 0, 1, 4 * env.w, 4 * env.h, 1000000, seed);
  const double v_cap = std::asin(kPolarCap) / kPiD;
  cfg.extra_y = {v_cap, 1 - v_cap};
  EXPECT_TRUE(test::rect_chi2(sample, pdf_uv, cfg));
  EXPECT_EQ(pdf_mismatch, 0) << name << ": sample pdf != light_pdf() away from the poles";
  EXPECT_LT(near_pole, 2000) << name;
  EXPECT_LT(near_texel_edge, 20) << name;
  EXPECT_EQ(radiance_mismatch, 0) << name;
  std::cout << name << ": samples within sinθ < 0.05 of a pole whose pdf round trip differs by > 1e-3: "
            << near_pole << " of 1e6; at a texel edge: " << near_texel_edge << "\n";
}

TEST(LightSampling, EnvMap) {
  EnvMapFixture env(Frame(), 7);
  check_envmap_sampling(env, {0, 0, 0}, "environment map (lat-long)", 1500);
  EnvMapFixture rot(rotation_frame({1, 1, 0.3f}, 0.7), 8);
  check_envmap_sampling(rot, {1, 2, 3}, "environment map, rotated (lat-long)", 1501);
  check_envmap_sampling(env, {0, 0, 0}, "environment map, MIS-compensated", 1503, LightDensity::Compensated);
  check_envmap_sampling(rot, {1, 2, 3}, "environment map, rotated, MIS-compensated", 1504,
                        LightDensity::Compensated);
  // Lat-long mapping round trip and its convention (+Y up, u = atan2(x, −z)/2π).
  PCG32 rng(1502, 1);
  for (int i = 0; i < 1000; ++i) {
    Vec3 d = sample_uniform_sphere(next_2d(rng));
    Vec3 back = latlong_to_direction(direction_to_latlong(d));
    ASSERT_NEAR(double(length(back - d)), 0, 1e-5);
  }
  Vec2 up = direction_to_latlong({0, 1, 0});
  EXPECT_NEAR(up.y, 0, 1e-6);
  Vec2 fwd = direction_to_latlong({0, 0, -1});
  EXPECT_NEAR(fwd.x, 0, 1e-6);
  EXPECT_NEAR(fwd.y, 0.5f, 1e-6);
}

// An escaped ray's emission and density in one lookup (the path tracer's) against the
// two functions it stands for, for every kind of infinite light and both NEE densities.
TEST(LightSampling, InfiniteLightRadianceAndDensityTogether) {
  EnvMapFixture env(rotation_frame({1, 1, 0.3f}, 0.7), 9);
  Light constant;
  constant.type = LightType::EnvConstant;
  constant.Le = Spectrum::make_constant(2);
  const Light sun = distant_light({0.3f, -0.5f, -0.8f}, 0.95f);
  const SampledWavelengths lambda = test_wavelengths();
  PCG32 rng(1506, 1);
  const Light* lights[] = {&env.light, &constant, &sun};
  for (const Light* l : lights) {
    for (LightDensity density : {LightDensity::Complete, LightDensity::Compensated}) {
      for (int i = 0; i < 2000; ++i) {
        const Vec3 w = i % 2 ? sample_uniform_sphere(next_2d(rng)) : -sun.n;  // half of them inside the sun
        Float pdf = -1;
        const SampledSpectrum Le = infinite_light_Le_pdf(*l, w, lambda, density, &pdf);
        const SampledSpectrum ref = infinite_light_Le(*l, w, lambda);
        for (int k = 0; k < kSpectrumSamples; ++k) ASSERT_EQ(Le[k], ref[k]);
        ASSERT_EQ(pdf, light_pdf(*l, {}, w, {}, {}, density));
        const SampledSpectrum no_pdf = infinite_light_Le_pdf(*l, w, lambda, density, nullptr);
        for (int k = 0; k < kSpectrumSamples; ++k) ASSERT_EQ(no_pdf[k], ref[k]);
      }
    }
  }
  // The map's density takes sin θ from the direction: the lat-long Jacobian at v (θ = π v).
  // Near a pole v = acos(y)/π is ill-conditioned: a rounding δ of the float y moves θ by
  // δ / sin θ, so the bound grows there by a few float ulps of 1 over sin θ (the square root
  // is the accurate one). The last bits of a rotated direction vary with the CPU (rsqrt()'s
  // SSE estimate differs between Intel and AMD): a fixed 2e-6 failed on a Xeon, not a Zen 4.
  for (int i = 0; i < 2000; ++i) {
    const Vec3 w = sample_uniform_sphere(next_2d(rng));
    const EnvDirection e = env_direction(env.light, w);
    const double bound = 2e-6 + 4 * 0x1p-24 / std::max(double(e.sin_theta), 1e-3);
    ASSERT_NEAR(e.sin_theta, std::sin(kPiD * double(e.uv.y)), bound);
  }
}

#if KAURI_LANES_AVX2
// The AVX2 blend of four texels (env_texel_radiance's host path) against the texel-by-texel
// sum it replaces, with general quadratics (c0, c1 ≠ 0), sigmoid arguments far past the
// clamp, zero scales and zero weights (a texel edge).
TEST(EnvMapLookup, LaneBlendMatchesTheTexelByTexelSum) {
  PCG32 rng(1505, 1);
  Light l;
  l.width = 4;
  l.height = 1;
  l.illuminant = d65();
  EnvTexel texels[4];
  l.texels = texels;
  const Float big[4] = {1, 1e3f, 1e20f, 1e36f};
  for (int trial = 0; trial < 20000; ++trial) {
    for (int k = 0; k < 4; ++k) {
      const Float m = big[trial % 4];
      texels[k] = {rng.next_float() < 0.2f ? 0 : 3 * rng.next_float(), m * 1e-4f * (rng.next_float() - 0.5f),
                   m * 0.1f * (rng.next_float() - 0.5f), m * 20 * (rng.next_float() - 0.5f)};
    }
    Float w[4];
    for (Float& x : w) x = rng.next_float() < 0.1f ? 0 : rng.next_float();
    const SampledWavelengths lambda = SampledWavelengths::sample_visible(rng.next_float());
    const EnvTexel* t[4] = {&texels[0], &texels[1], &texels[2], &texels[3]};
    const SampledSpectrum got = light_detail::env_blend_lanes(t, w, lambda);
    const SampledSpectrum one(1);
    for (int i = 0; i < kSpectrumSamples; ++i) {
      double want = 0, mag = 0;
      for (int k = 0; k < 4; ++k) {
        if (!(w[k] > 0)) continue;
        const double term = double(light_detail::env_texel_spectrum(l, k, lambda, one)[i]) * double(w[k]);
        want += term;
        mag += std::fabs(term);
      }
      ASSERT_NEAR(double(got[i]), want, 1e-6 * mag + 1e-30) << "trial " << trial << ", wavelength " << i;
    }
  }
}
#endif

// ---------------------------------------------------------------- estimators vs analytic values

struct Estimate {
  double mean, sigma;
};

/// Mean of L[0]·g(ω)/pdf over n light samples from p, with g = 1 or max(0, N·ω).
Estimate light_estimate(const Light& l, Point3 p, const Vec3* N, uint64_t seed, int n) {
  PCG32 rng(seed, 5);
  const SampledWavelengths lambda = test_wavelengths();
  double sum = 0, sum2 = 0;
  for (int k = 0; k < n; ++k) {
    LightSample s = sample_light(l, p, next_2d(rng), lambda);
    if (!(s.pdf > 0)) continue;
    double g = N ? std::max(0.0, double(dot(*N, s.wi))) : 1.0;
    double v = double(s.L[0]) * g / double(s.pdf);
    sum += v;
    sum2 += v * v;
  }
  double m = sum / n;
  return {m, std::sqrt(std::max(0.0, sum2 / n - m * m) / n)};
}

/// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983).
double triangle_solid_angle(D3 a, D3 b, D3 c) {
  double la = dlen(a), lb = dlen(b), lc = dlen(c);
  double num = std::fabs(ddot(a, dcross(b, c)));
  double den = la * lb * lc + ddot(a, b) * lc + ddot(a, c) * lb + ddot(b, c) * la;
  return 2 * std::atan2(num, den);
}

/// Irradiance at the origin with normal N from a polygon of unit radiance lying
/// entirely above the receiver's plane (Lambert's formula, vector irradiance).
double polygon_irradiance(const std::vector<D3>& v, D3 N) {
  double e = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    D3 a = dnorm(v[i]), b = dnorm(v[(i + 1) % v.size()]);
    double theta = std::acos(std::clamp(ddot(a, b), -1.0, 1.0));
    e += theta * ddot(dnorm(dcross(a, b)), N);
  }
  return std::fabs(e) / 2;
}

// A camera ray that escapes into an environment image adds the texels' colours
// (add_seen_directly, PathOutput::rgb_exact): at a texel's centre that texel's RGB ×
// intensity, elsewhere the
// blend of the texels and weights env_texel_radiance blends as spectra. Those colours are
// the expected colours of the texels' spectra up to the RGB-to-spectrum fit, which is
// what a sky seen directly and the light it casts may differ by: over random linear-sRGB
// colours 0.04% of the brightest component at worst. (Over random ACEScg colours it was
// 8%: part of that gamut lies beyond the spectral locus, where no reflectance-shaped
// spectrum has the colour; the backdrop then shows the colour as given.)
TEST(EnvMapSeenDirectly, TexelColoursAndTheSpectraTheyStandFor) {
  Scene scene;
  scene.set_color_space(ColorSpaceId::LinearSRGB);  // random colours inside its gamut
  LightDesc env;
  env.name = "sky";
  env.type = LightType::EnvMap;
  env.width = 16, env.height = 8;
  env.emission.intensity = 2.5f;
  PCG32 rng(41, 3);
  for (int i = 0; i < env.width * env.height; ++i) {
    const Float bright = 3 * rng.next_float();
    for (int c = 0; c < 3; ++c) env.image.push_back(bright * rng.next_float());
  }
  env.image[3 * 9] = env.image[3 * 9 + 1] = env.image[3 * 9 + 2] = 0;  // a black texel
  scene.add_light(env);
  scene.set_camera(CameraDesc{});
  const auto compiled = scene.compile(8, 8);
  const SceneView& v = compiled->view();
  ASSERT_EQ(v.n_infinite_lights, 1);
  const Light& l = v.lights[v.infinite_lights[0]];
  ASSERT_EQ(l.type, LightType::EnvMap);
  double worst_fit = 0;
  for (int y = 0; y < env.height; ++y)
    for (int x = 0; x < env.width; ++x) {
      const int i = y * env.width + x;
      const Vec2 uv{(Float(x) + 0.5f) / Float(env.width), (Float(y) + 0.5f) / Float(env.height)};
      Vec3 rgb{0, 0, 0};
      EXPECT_TRUE(path_detail::add_seen_directly(l, l.frame.to_world(latlong_to_direction(uv)), &rgb));
      for (int c = 0; c < 3; ++c) {
        const Float want = env.image[3 * i + c] * env.emission.intensity;
        EXPECT_NEAR(rgb[c], want, 2e-4f * (1 + want)) << "texel " << x << "," << y;
      }
      const EnvTexel& t = l.texels[i];
      const Spectrum s = Spectrum::make_rgb_illuminant({t.c0, t.c1, t.c2}, t.scale, l.illuminant);
      const Vec3 expected = t.scale > 0 ? v.to_rgb(spectrum_to_xyz_expected(s)) : Vec3{0, 0, 0};
      const Float m = std::fmax(max_component(l.texel_rgb[i]), 1e-6f);
      for (int c = 0; c < 3; ++c) worst_fit = std::fmax(worst_fit, std::fabs(expected[c] - l.texel_rgb[i][c]) / m);
    }
  std::cout << "[ info ] worst RGB-to-spectrum fit error over the texels: " << worst_fit << " of the brightest component\n";
  EXPECT_LT(worst_fit, 0.002);
  // Between centres: the bilinear blend of the same four texels, with the same weights.
  for (int n = 0; n < 200; ++n) {
    const Vec2 uv{rng.next_float(), rng.next_float()};
    const EnvBilinear b = env_bilinear(l, uv);
    Vec3 want{0, 0, 0};
    for (int k = 0; k < 4; ++k) want += l.texel_rgb[b.index[k]] * b.w[k];
    const Vec3 got = env_texel_rgb(l, uv);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-6f * (1 + want[c]));
    Float wsum = 0;
    for (int k = 0; k < 4; ++k) wsum += b.w[k];
    EXPECT_NEAR(wsum, 1, 1e-5f);
  }
}

TEST(LightEstimators, TriangleSolidAngleAndIrradiance) {
  // A large triangle above the receiver at the origin (normal +z), facing it.
  Light l = triangle_light({-1, -1, 1}, {-1, 2, 1.2f}, {2, -1, 0.8f});
  ASSERT_LT(l.n.z, 0);  // emits downwards, towards the receiver
  Point3 p{0, 0, 0};
  Vec3 N{0, 0, 1};
  std::vector<D3> verts = {d3(l.p0), d3(l.p1), d3(l.p2)};
  const double omega = triangle_solid_angle(verts[0], verts[1], verts[2]);
  const double E = polygon_irradiance(verts, d3(N));
  const int n = 1000000;
  Estimate so = light_estimate(l, p, nullptr, 1600, n);
  Estimate ir = light_estimate(l, p, &N, 1601, n);
  std::cout << "triangle: solid angle " << omega << " estimated " << so.mean << " ± " << so.sigma << "; irradiance "
            << E << " estimated " << ir.mean << " ± " << ir.sigma << "\n";
  EXPECT_NEAR(so.mean, omega, std::max(5 * so.sigma, 0.0));
  EXPECT_NEAR(ir.mean, E, std::max(5 * ir.sigma, 0.0));
  EXPECT_LT(5 * so.sigma, 0.01 * omega);
  EXPECT_LT(5 * ir.sigma, 0.01 * E);

  // Brute force: uniform directions over the sphere, ray-cast against the triangle,
  // ∫ L |cosθ| dω. Agrees with the light-sampling estimate within 1%.
  PCG32 rng(1602, 1);
  const int nb = 4000000;
  double sum = 0, sum2 = 0;
  for (int k = 0; k < nb; ++k) {
    Vec3 w = sample_uniform_sphere(next_2d(rng));
    LightHit h = intersect_light(l, p, w);
    if (!h.hit || ddot(h.n, d3(w)) >= 0) continue;  // one-sided: emits along l.n
    double v = std::fabs(double(w.z)) * 4 * kPiD;
    sum += v;
    sum2 += v * v;
  }
  double bf = sum / nb, bf_sigma = std::sqrt((sum2 / nb - bf * bf) / nb);
  std::cout << "triangle irradiance by uniform sphere sampling: " << bf << " ± " << bf_sigma << "\n";
  EXPECT_NEAR(bf, E, 5 * bf_sigma);
  EXPECT_NEAR(ir.mean / bf, 1, 0.01);
  EXPECT_LT(5 * bf_sigma, 0.01 * E);

  // Behind the triangle a one-sided light gives nothing; a two-sided one the same solid angle.
  Point3 behind{0.2f, 0.1f, 3};
  EXPECT_EQ(light_estimate(l, behind, nullptr, 1603, 1000).mean, 0);
  Light l2 = triangle_light(l.p0, l.p1, l.p2, true);
  Estimate so2 = light_estimate(l2, behind, nullptr, 1604, n);
  double omega2 = triangle_solid_angle(d3(l.p0) - d3(behind), d3(l.p1) - d3(behind), d3(l.p2) - d3(behind));
  EXPECT_NEAR(so2.mean, omega2, 5 * so2.sigma);
}

TEST(LightEstimators, DiskOnAxis) {
  // Irradiance on the axis of a disk: π L R²/(h² + R²); solid angle 2π(1 − h/√(h² + R²)).
  const double h = 2, R = 1.5;
  Light l = disk_light({0, 0, Float(h)}, {0, 0, -1}, Float(R));
  Vec3 N{0, 0, 1};
  Estimate ir = light_estimate(l, {0, 0, 0}, &N, 1700, 1000000);
  Estimate so = light_estimate(l, {0, 0, 0}, nullptr, 1701, 1000000);
  EXPECT_NEAR(ir.mean, kPiD * R * R / (h * h + R * R), 5 * ir.sigma + 1e-6);
  EXPECT_NEAR(so.mean, 2 * kPiD * (1 - h / std::sqrt(h * h + R * R)), 5 * so.sigma + 1e-6);
}

TEST(LightEstimators, SphereSolidAngleAtAllDistances) {
  // ∫ L dω = L · 2π(1 − cosθ_max) from outside; irradiance π L (r/d)² cosθ for a
  // receiver tilted by θ (sphere entirely above its horizon). Small distant spheres
  // stress the precision of the cone (1 − cosθ_max ≈ (r/d)²/2 is below float
  // resolution of cosθ_max when r/d < ~1e-3).
  for (double rd : {0.5, 0.1, 0.01, 0.003, 1e-3, 3e-4}) {
    const double d = 10;
    Light l = sphere_light({0.3f, -0.2f, Float(d)}, Float(rd * d));
    Point3 p{0.3f, -0.2f, 0};
    const double r = double(l.radius) / d;  // the radius as stored
    const double omega = 2 * kPiD * r * r / (1 + std::sqrt(1 - r * r));
    Estimate so = light_estimate(l, p, nullptr, 1800, 200000);
    const double tilt = 0.5;
    Vec3 N{Float(std::sin(tilt)), 0, Float(std::cos(tilt))};
    Estimate ir = light_estimate(l, p, &N, 1801, 200000);
    const double E = kPiD * r * r * std::cos(tilt);
    std::cout << "sphere r/d = " << rd << ": solid angle ratio " << so.mean / omega << ", irradiance ratio "
              << ir.mean / E << "\n";
    EXPECT_NEAR(so.mean / omega, 1, 5 * so.sigma / omega + 1e-4) << "r/d = " << rd;
    EXPECT_NEAR(ir.mean / E, 1, 5 * ir.sigma / E + 1e-3) << "r/d = " << rd;
    // The sampled points lie on the sphere, on its near side.
    PCG32 rng(1802, 1);
    const SampledWavelengths lambda = test_wavelengths();
    int off_surface = 0;
    for (int k = 0; k < 20000; ++k) {
      LightSample s = sample_light(l, p, next_2d(rng), lambda);
      double dist_c = dlen(d3(s.p_light) - d3(l.p0));
      if (std::fabs(dist_c - double(l.radius)) > 1e-3 * double(l.radius) || s.L[0] == 0) ++off_surface;
    }
    EXPECT_EQ(off_surface, 0) << "r/d = " << rd;
  }
  // Inside a two-sided sphere light every direction sees it: ∫ L dω = 4π.
  Light l = sphere_light({0, 0, 0}, 2, true);
  Estimate in = light_estimate(l, {0.5f, -0.7f, 0.9f}, nullptr, 1803, 200000);
  EXPECT_NEAR(in.mean, 4 * kPiD, 5 * in.sigma + 1e-5);
}

TEST(LightEstimators, DistantConeIrradiance) {
  // A distant light's Le is the irradiance at normal incidence, whatever its angle.
  for (double angle_deg : {20.0, 2.0, 0.53, 0.1}) {
    Float cos_max = std::cos(Float(angle_deg * kPiD / 360));
    Light l = distant_light({0.2f, 0.3f, -1}, cos_max);
    Vec3 N = -l.n;
    Estimate ir = light_estimate(l, {0, 0, 0}, &N, 1900, 100000);
    std::cout << "distant light, angle " << angle_deg << " deg: irradiance " << ir.mean << " ± " << ir.sigma << "\n";
    EXPECT_NEAR(ir.mean, 1, 5 * ir.sigma + 2e-3) << "angle " << angle_deg;
  }
  // The radiance that BSDF-sampled directions see (infinite_light_Le) must integrate
  // to the same irradiance: directions drawn uniformly (in double precision) from a
  // cone twice as wide as the light's.
  for (double angle_deg : {2.0, 0.53, 0.1, 0.05}) {
    Float cos_max = std::cos(Float(angle_deg * kPiD / 360));
    Light l = distant_light({0.2f, 0.3f, -1}, cos_max);
    const double one_minus_c2 = 4 * (1 - double(cos_max));  // ≈ twice the angle
    D3 z = dnorm(d3(-l.n)), x = dnorm(dcross(std::fabs(z.x) < 0.9 ? D3{1, 0, 0} : D3{0, 1, 0}, z)),
       y = dcross(z, x);
    PCG32 rng(1901, uint64_t(angle_deg * 100));
    const SampledWavelengths lambda = test_wavelengths();
    const int n = 1000000;
    double sum = 0, sum2 = 0;
    for (int k = 0; k < n; ++k) {
      double omc = double(rng.next_float()) * one_minus_c2, phi = 2 * kPiD * double(rng.next_float());
      double st = std::sqrt(omc * (2 - omc)), ct = 1 - omc;
      D3 w = x * (st * std::cos(phi)) + y * (st * std::sin(phi)) + z * ct;
      double v = double(infinite_light_Le(l, f3(w), lambda)[0]) * ct * 2 * kPiD * one_minus_c2;
      sum += v;
      sum2 += v * v;
    }
    double m = sum / n, sd = std::sqrt((sum2 / n - m * m) / n);
    std::cout << "distant light, angle " << angle_deg << " deg, seen by uniform cone sampling: " << m << " ± " << sd
              << "\n";
    EXPECT_NEAR(m, 1, 5 * sd) << "angle " << angle_deg;
  }
  // The delta limit.
  Light d = distant_light({0, 0, -1}, 1);
  EXPECT_TRUE(d.is_delta());
  LightSample s = sample_light(d, {0, 0, 0}, {0.3f, 0.6f}, test_wavelengths());
  EXPECT_TRUE(s.delta);
  EXPECT_EQ(s.pdf, 1);
  EXPECT_NEAR(s.wi.z, 1, 1e-6);
  EXPECT_EQ(s.L[0], 1);
}

TEST(LightEstimators, Environments) {
  Light c;
  c.type = LightType::EnvConstant;
  c.Le = Spectrum::make_constant(1);
  Estimate e = light_estimate(c, {0, 0, 0}, nullptr, 2000, 10000);
  EXPECT_NEAR(e.mean, 4 * kPiD, 1e-4);  // constant L/pdf
  for (uint64_t seed : {7, 8}) {
    EnvMapFixture env(seed == 7 ? Frame() : rotation_frame({1, 1, 0.3f}, 0.7), seed);
    Estimate m = light_estimate(env.light, {1, 2, 3}, nullptr, 2001, 1000000);
    const double ref = env.radiance_integral(test_wavelengths().lambda[0]);
    std::cout << "env map: ∫L dω = " << ref << ", estimated " << m.mean << " ± " << m.sigma << "\n";
    EXPECT_NEAR(m.mean, ref, 5 * m.sigma + 1e-4 * ref);
    EXPECT_LT(m.sigma, 0.01 * ref);
  }
}

/// The MIS-compensated environment density (Karlík et al. 2019): zero wherever the
/// dilated luminance is at or below its solid-angle mean, (m − m̄) sinθ above it; none
/// for a constant image or a constant environment.
TEST(LightSampling, CompensatedEnvironmentDensity) {
  const int w = 16, h = 8;
  std::vector<Float> lum(size_t(w * h), 1);
  lum[size_t(3 * w + 5)] = 10;  // one bright texel on a constant sky
  std::vector<Float> c = env_importance_compensated(lum, w, h);
  // Independent mean of the dilated image: 10 on the 3 × 3 block around (5, 3), else 1.
  double num = 0, den = 0;
  for (int y = 0; y < h; ++y) {
    const double st = std::sin(kPiD * (y + 0.5) / h);
    for (int x = 0; x < w; ++x) {
      const bool block = std::abs(x - 5) <= 1 && std::abs(y - 3) <= 1;
      num += (block ? 10.0 : 1.0) * st;
      den += st;
    }
  }
  const double mean = num / den;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool block = std::abs(x - 5) <= 1 && std::abs(y - 3) <= 1;
      const double expect = block ? (10 - mean) * std::sin(kPiD * (y + 0.5) / h) : 0.0;
      EXPECT_NEAR(double(c[size_t(y * w + x)]), expect, 1e-5 * (1 + expect)) << x << ", " << y;
    }
  // A constant image: nothing stands out, so NEE has no density and never samples it.
  std::vector<Float> flat(size_t(w * h), 3);
  for (Float v : env_importance_compensated(flat, w, h)) EXPECT_EQ(v, 0);
  Distribution2DStorage none(env_importance_compensated(flat, w, h), w, h), all(env_importance(flat, w, h), w, h);
  Light l;
  l.type = LightType::EnvMap;
  l.distribution = all.view();
  l.compensated = none.view();
  EXPECT_TRUE(has_light_density(l, LightDensity::Complete));
  EXPECT_FALSE(has_light_density(l, LightDensity::Compensated));
  Light k;
  k.type = LightType::EnvConstant;
  k.Le = Spectrum::make_constant(1);
  EXPECT_TRUE(has_light_density(k, LightDensity::Complete));
  EXPECT_FALSE(has_light_density(k, LightDensity::Compensated));
  PCG32 rng(1510, 1);
  for (int i = 0; i < 100; ++i) {
    Vec2 u = next_2d(rng);
    EXPECT_EQ(sample_light(k, {0, 0, 0}, u, test_wavelengths(), LightDensity::Compensated).pdf, 0);
    Vec3 d = sample_uniform_sphere(u);
    EXPECT_EQ(light_pdf(k, {0, 0, 0}, d, {}, {}, LightDensity::Compensated), 0);
    EXPECT_GT(light_pdf(k, {0, 0, 0}, d, {}, {}, LightDensity::Complete), 0);
  }
}

/// One-sample-per-technique MIS (power heuristic) of NEE with `density` and cosine
/// sampling on a Lambertian receiver with normal N, as the path tracer combines them:
/// estimates (1/π)∫ L max(0, N·ω) dω.
Estimate lambert_mis_estimate(const Light& l, Point3 p, Vec3 N, LightDensity density, uint64_t seed, int n) {
  PCG32 rng(seed, 9);
  const SampledWavelengths lambda = test_wavelengths();
  const Frame f = Frame::from_z(N);
  double sum = 0, sum2 = 0;
  for (int k = 0; k < n; ++k) {
    double v = 0;
    LightSample s = sample_light(l, p, next_2d(rng), lambda, density);
    const double cos_l = s.pdf > 0 ? double(dot(N, s.wi)) : 0.0;
    if (cos_l > 0) {
      const double pl = s.pdf, pb = cos_l / kPiD;
      v += double(s.L[0]) * cos_l / kPiD / pl * (pl * pl / (pl * pl + pb * pb));
    }
    Vec3 wi = f.to_world(sample_cosine_hemisphere(next_2d(rng)));
    const double cos_b = double(dot(N, wi));
    if (cos_b > 0) {
      const double pb = cos_b / kPiD, pl = light_pdf(l, p, wi, {}, {}, density);
      v += double(infinite_light_Le(l, wi, lambda)[0]) * (pb * pb / (pl * pl + pb * pb));  // f cos / pb = 1 · L
    }
    sum += v;
    sum2 += v * v;
  }
  const double m = sum / n;
  return {m, std::sqrt(std::max(0.0, sum2 / n - m * m) / n)};
}

/// (1/π)∫ L max(0, N·ω) dω by midpoint quadrature in the light's (u, v) square.
double lambert_irradiance_quadrature(const Light& l, Vec3 N) {
  const SampledWavelengths lambda = test_wavelengths();
  const int nu = 2048, nv = 1024;
  double sum = 0;
  for (int j = 0; j < nv; ++j) {
    const double v = (j + 0.5) / nv;
    for (int i = 0; i < nu; ++i) {
      Vec3 w = l.frame.to_world(latlong_to_direction({Float((i + 0.5) / nu), Float(v)}));
      const double c = double(dot(N, w));
      if (c > 0) sum += double(infinite_light_Le(l, w, lambda)[0]) * c * std::sin(kPiD * v);
    }
  }
  return sum * 2 * kPiD * kPiD / (double(nu) * nv) / kPiD;
}

/// The compensated density loses no direction that cosine sampling covers (the MIS
/// estimate matches quadrature), and on a sky with a sun its variance is below MIS with
/// the complete density.
TEST(LightEstimators, CompensatedEnvironmentMIS) {
  const Vec3 N = normalize(Vec3{0.2f, 0.9f, -0.3f});
  for (uint64_t seed : {7, 8}) {
    EnvMapFixture env(seed == 7 ? Frame() : rotation_frame({1, 1, 0.3f}, 0.7), seed);
    const double ref = lambert_irradiance_quadrature(env.light, N);
    Estimate comp = lambert_mis_estimate(env.light, {1, 2, 3}, N, LightDensity::Compensated, 2110 + seed, 400000);
    std::cout << "env map, Lambert receiver: (1/π)∫L cos dω = " << ref << " (quadrature); MIS with the compensated "
              << "density " << comp.mean << " ± " << comp.sigma << "\n";
    EXPECT_NEAR(comp.mean, ref, 5 * comp.sigma + 1e-4 * ref);
  }
  // A uniform sky with a small sun (20× brighter, one texel of 32 × 16): the compensated
  // density leaves the sky to cosine sampling and spends NEE on the sun.
  const int w = 32, h = 16;
  std::vector<EnvTexel> texels(size_t(w * h), EnvTexel{1, 0, 0, 0});  // s(0) = 1/2: radiance D65/2
  std::vector<Float> lum(texels.size(), 0.5f);
  texels[size_t(4 * w + 9)].scale = 20;
  lum[size_t(4 * w + 9)] = 10;
  Distribution2DStorage dist(env_importance(lum, w, h), w, h), comp_dist(env_importance_compensated(lum, w, h), w, h);
  Light sky;
  sky.type = LightType::EnvMap;
  sky.distribution = dist.view();
  sky.compensated = comp_dist.view();
  sky.width = w;
  sky.height = h;
  sky.illuminant = d65();
  sky.texels = texels.data();
  sky.scene_radius = 10;
  const Vec3 up{0, 1, 0};
  const double ref = lambert_irradiance_quadrature(sky, up);
  Estimate full = lambert_mis_estimate(sky, {0, 0, 0}, up, LightDensity::Complete, 2120, 400000);
  Estimate comp = lambert_mis_estimate(sky, {0, 0, 0}, up, LightDensity::Compensated, 2121, 400000);
  std::cout << "sky with a sun, Lambert receiver: " << ref << " (quadrature); MIS with the complete density "
            << full.mean << " ± " << full.sigma << ", with the compensated density " << comp.mean << " ± "
            << comp.sigma << "\n";
  EXPECT_NEAR(full.mean, ref, 5 * full.sigma + 1e-4 * ref);
  EXPECT_NEAR(comp.mean, ref, 5 * comp.sigma + 1e-4 * ref);
  EXPECT_LT(comp.sigma, 0.8 * full.sigma);
}

// ---------------------------------------------------------------- delta lights

TEST(DeltaLights, PointInverseSquare) {
  Light l;
  l.type = LightType::Point;
  l.Le = Spectrum::make_dense(d65());
  l.p0 = {1, 2, 3};
  const SampledWavelengths lambda = test_wavelengths();
  for (double d : {0.5, 1.0, 2.0, 10.0}) {
    Vec3 dirn = normalize(Vec3{0.3f, -0.4f, 0.5f});
    Point3 p = l.p0 - dirn * Float(d);
    LightSample s = sample_light(l, p, {0.1f, 0.9f}, lambda);
    EXPECT_TRUE(s.delta);
    EXPECT_EQ(s.pdf, 1);
    EXPECT_NEAR(double(length(s.wi - dirn)), 0, 1e-5);
    for (int i = 0; i < kSpectrumSamples; ++i)
      EXPECT_NEAR(double(s.L[i]) * d * d / double(l.Le(lambda.lambda[i])), 1, 1e-5) << "d " << d;
    EXPECT_EQ(light_pdf(l, p, s.wi, s.p_light, s.n_light), 0);  // never hit by chance
  }
}

TEST(DeltaLights, SpotSmoothstep) {
  Light l;
  l.type = LightType::Spot;
  l.Le = Spectrum::make_constant(2);
  l.p0 = {0, 0, 5};
  l.n = {0, 0, -1};
  const double inner = 20, outer = 30;  // degrees
  l.cos_inner = std::cos(Float(inner * kPiD / 180));
  l.cos_outer = std::cos(Float(outer * kPiD / 180));
  l.frame = Frame::from_z(l.n);
  const SampledWavelengths lambda = test_wavelengths();
  for (double a : {0.0, 10.0, 19.9, 20.1, 22.0, 25.0, 28.0, 29.9, 30.1, 45.0, 120.0}) {
    const double r = 3;
    double rad = a * kPiD / 180;
    Point3 p = l.p0 + Vec3{Float(r * std::sin(rad)), 0, Float(-r * std::cos(rad))};
    LightSample s = sample_light(l, p, {0.5f, 0.5f}, lambda);
    double c = std::cos(rad);
    double t = std::clamp((c - double(l.cos_outer)) / (double(l.cos_inner) - double(l.cos_outer)), 0.0, 1.0);
    double falloff = t * t * (3 - 2 * t);
    if (a <= inner) {
      EXPECT_EQ(falloff, 1);
    }
    if (a >= outer) {
      EXPECT_EQ(falloff, 0);
    }
    EXPECT_NEAR(double(s.L[0]), 2 * falloff / (r * r), 2e-5) << "angle " << a;
  }
  // Monotone between the cones.
  double prev = 1e9;
  for (double a = 19; a <= 31; a += 0.25) {
    double rad = a * kPiD / 180;
    Point3 p = l.p0 + Vec3{Float(std::sin(rad)), 0, Float(-std::cos(rad))};
    double v = double(sample_light(l, p, {0.5f, 0.5f}, lambda).L[0]);
    EXPECT_LE(v, prev + 1e-6) << a;
    prev = v;
  }
}

}  // namespace
}  // namespace kauri
