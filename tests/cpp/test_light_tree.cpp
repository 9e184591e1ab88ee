// Light tree (light/light_tree.h): a proper distribution over the finite lights at every
// point, sampled as its pmf says, unbiased for every light with power (the defensive
// mixture), and preferring lights that contribute more.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "chi2.h"
#include "kauri/light/light.h"
#include "kauri/light/light_tree.h"
#include "kauri/sampler/rng.h"

namespace kauri {
namespace {

Light triangle_light(Point3 c, Vec3 n, Float size, bool two_sided) {
  Light l;
  l.type = LightType::Triangle;
  const Frame f = Frame::from_z(n);
  l.p0 = c + f.to_world(Vec3{-size, -size, 0});
  l.p1 = c + f.to_world(Vec3{size, -size, 0});
  l.p2 = c + f.to_world(Vec3{0, size, 0});
  l.n = n;
  l.two_sided = two_sided;
  l.area = size * size * 2;
  return l;
}

/// `count` small lamps facing down-ish, scattered over a 20-unit cube (a third two-sided),
/// of power 0.5–1.5, from PCG32(seed, stream).
struct ScatteredLamps {
  std::vector<Light> lights;
  std::vector<Float> power;
  ScatteredLamps(int count, uint64_t seed, uint64_t stream) {
    PCG32 rng(seed, stream);
    for (int i = 0; i < count; ++i) {
      const Point3 c{20 * rng.next_float() - 10, 20 * rng.next_float() - 10, 20 * rng.next_float() - 10};
      lights.push_back(triangle_light(c, normalize(Vec3{rng.next_float() - 0.5f, -1, rng.next_float() - 0.5f}),
                                      0.05f, i % 3 == 0));
      power.push_back(0.5f + rng.next_float());
    }
  }
};

/// 60 small lights of random position, orientation, sidedness and power (one without
/// power), two spheres, a point light and an environment (which stays outside the tree).
struct RandomLights {
  std::vector<Light> lights;
  std::vector<Float> power;
  RandomLights() {
    PCG32 rng(11, 5);
    auto u = [&] { return Float(rng.next_float()); };
    for (int i = 0; i < 60; ++i) {
      const Point3 c{10 * u() - 5, 10 * u() - 5, 10 * u() - 5};
      const Vec3 n = normalize(Vec3{2 * u() - 1, 2 * u() - 1, 2 * u() - 1 + 1e-3f});
      lights.push_back(triangle_light(c, n, 0.05f + 0.3f * u(), i % 5 == 0));
      power.push_back(i == 7 ? Float(0) : 0.1f + 10 * u());
    }
    for (int i = 0; i < 2; ++i) {
      Light s;
      s.type = LightType::Sphere;
      s.p0 = {Float(3 * i - 1), 2, 0};
      s.radius = 0.4f;
      lights.push_back(s);
      power.push_back(5);
    }
    Light pt;
    pt.type = LightType::Point;
    pt.p0 = {0, -3, 1};
    lights.push_back(pt);
    power.push_back(3);
    Light env;
    env.type = LightType::EnvConstant;
    lights.push_back(env);
    power.push_back(100);
  }
};

TEST(LightTree, PmfIsADistributionThatKeepsEveryLightWithPower) {
  RandomLights r;
  LightTreeStorage t = build_light_tree(r.lights, r.power);
  const LightTreeView v = t.view();
  ASSERT_GT(v.n_nodes, 0);
  PCG32 rng(3, 9);
  for (int k = 0; k < 50; ++k) {
    const Point3 p{12 * rng.next_float() - 6, 12 * rng.next_float() - 6, 12 * rng.next_float() - 6};
    // Every other point on a surface (a random shading normal), the others without one.
    const Normal3 n = k % 2 ? normalize(Vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.3f}) : Normal3{};
    double sum = 0;
    for (int i = 0; i < int(r.lights.size()); ++i) {
      const Float pmf = v.pmf(i, p, n);
      sum += double(pmf);
      if (r.lights[size_t(i)].is_infinite() || !(r.power[size_t(i)] > 0))
        EXPECT_EQ(pmf, 0) << "light " << i << " is not in the tree";
      else  // at least the power share of the defensive mixture at every level
        EXPECT_GT(pmf, 0) << "light " << i << " at point " << k;
    }
    EXPECT_NEAR(sum, 1.0, 1e-5) << "point " << k;
  }
}

TEST(LightTree, SamplesFollowThePmfChiSquare) {
  RandomLights r;
  LightTreeStorage t = build_light_tree(r.lights, r.power);
  const LightTreeView v = t.view();
  const int n = int(r.lights.size());
  const Point3 points[] = {{0, 0, 0}, {4.5f, -4.5f, 2}, {-6, 5, -1}};
  const Normal3 normals[] = {{0, 1, 0}, {}, normalize(Vec3{1, 1, 0})};  // {}: no surface
  PCG32 rng(test::chi2_seed(21), 2);
  for (int q = 0; q < 3; ++q) {
    const Point3 p = points[q];
    const Normal3 ns = normals[q];
    test::Chi2Table table(test::uniform_edges(0, n, n), test::uniform_edges(0, 1, 1));
    for (int s = 0; s < 200000; ++s) {
      Float pmf;
      const int li = v.sample(rng.next_float(), p, ns, &pmf);
      ASSERT_GE(li, 0);
      ASSERT_NEAR(pmf, v.pmf(li, p, ns), 1e-5f * v.pmf(li, p, ns)) << "sample() and pmf() disagree on light " << li;
      table.add(li + 0.5, 0.5);
    }
    auto pdf = [&](double x, double) { return double(v.pmf(int(x), p, ns)); };
    EXPECT_TRUE(table.test(pdf, "light tree"));
  }
}

// Next-event estimation picks the light with u.x and places the point with u.x rescaled
// within the light's share (path_tracer.h), so that one stratified 2D sample covers all
// the lights. Each light owns one interval of u; evenly spaced u must come back evenly
// spaced over [0, 1) for every light, and the choice must not depend on asking for it.
TEST(LightTree, RemappedUIsUniformWithinEachLight) {
  RandomLights r;
  LightTreeStorage t = build_light_tree(r.lights, r.power);
  const LightTreeView v = t.view();
  const int n = int(r.lights.size()), N = 1 << 17;
  const Point3 points[] = {{0, 0, 0}, {4.5f, -4.5f, 2}};
  const Normal3 normals[] = {{}, {0, 0, 1}};
  for (int q = 0; q < 2; ++q) {
    const Point3 p = points[q];
    std::vector<std::vector<Float>> remapped{size_t(n)};
    for (int k = 0; k < N; ++k) {
      const Float u = (Float(k) + 0.5f) / Float(N);
      Float pmf, pmf2, ur = -1;
      const int li = v.sample(u, p, normals[q], &pmf, &ur);
      ASSERT_EQ(li, v.sample(u, p, normals[q], &pmf2));
      ASSERT_GE(ur, 0);
      ASSERT_LT(ur, 1);
      remapped[size_t(li)].push_back(ur);
    }
    int checked = 0;
    for (std::vector<Float>& rs : remapped) {
      if (rs.size() < 64) continue;
      ++checked;
      const double m = double(rs.size());
      for (size_t j = 0; j < rs.size(); ++j) {  // in u order: increasing, evenly spaced
        if (j > 0) {
          ASSERT_GT(rs[j], rs[j - 1]);
        }
        ASSERT_NEAR(rs[j], (double(j) + 0.5) / m, 1.5 / m + 1e-4);
      }
    }
    EXPECT_GT(checked, 10);
  }
}

/// A hangar ceiling: 16 × 16 equal lamps facing down at height 5, one unit apart, lamp
/// 16 i + j at (i − 7.5, 5, j − 7.5).
struct Ceiling {
  std::vector<Light> lights;
  std::vector<Float> power;
  Ceiling() {
    for (int i = 0; i < 16; ++i)
      for (int j = 0; j < 16; ++j) {
        lights.push_back(triangle_light(Point3{Float(i) - 7.5f, 5, Float(j) - 7.5f}, Vec3{0, -1, 0}, 0.1f, false));
        power.push_back(1);
      }
  }
};

// Below one lamp of the ceiling, the tree picks it far more often than a lamp in the far
// corner, where power alone would pick both alike.
TEST(LightTree, PrefersTheLampsThatContribute) {
  const Ceiling c;
  LightTreeStorage t = build_light_tree(c.lights, c.power);
  const LightTreeView v = t.view();
  const Point3 below_first{-7.5f, 0, -7.5f};
  const Normal3 up{0, 1, 0};
  const Float near = v.pmf(0, below_first, up), far = v.pmf(255, below_first, up);
  EXPECT_GT(near, 10 * far);
  EXPECT_GT(near, 5.0f / 256);
  // Above the ceiling every lamp faces away: only the power share is left, spread evenly.
  const Point3 above{0, 9, 0};
  EXPECT_NEAR(v.pmf(0, above, up), 1.0f / 256, 1e-5f);
}

// The receiver's cosine: on a wall below the ceiling's edge (normal +x), the lamp just above
// it lies near the wall's horizon (cos θ_i = 0.10) and one further in faces it (cos θ_i =
// 0.94). What each contributes, cos θ cos θ_i / d², is 2.7 times more for the lamp above;
// the bound without the surface favours it 9.4 times (distance and the lamp's own cosine),
// with the surface less than half that (the clusters above the leaves subtend wide angles,
// which loosen the receiver's factor there).
TEST(LightTree, TheReceiversCosineWeighsLightsNearItsHorizonDown) {
  const Ceiling c;
  const std::vector<Light>& lights = c.lights;
  LightTreeStorage t = build_light_tree(c.lights, c.power);
  const LightTreeView v = t.view();
  const Point3 wall{-7.8f, 2, 0.5f};
  const int above = 7, inward = 8 * 16 + 8;  // lamps at (−7.5, 5, 0.5) and (0.5, 5, 0.5)
  const Float ratio_bare = v.pmf(above, wall, Normal3{}) / v.pmf(inward, wall, Normal3{});
  const Float ratio_wall = v.pmf(above, wall, Normal3{1, 0, 0}) / v.pmf(inward, wall, Normal3{1, 0, 0});
  EXPECT_GT(ratio_bare, 8.0f);
  EXPECT_LT(ratio_wall, ratio_bare / 2);
  EXPECT_GT(ratio_wall, 2.7f);  // still a bound: no lower than the contributions' ratio
  double sum = 0;
  for (int i = 0; i < int(lights.size()); ++i) sum += double(v.pmf(i, wall, Normal3{1, 0, 0}));
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

// 5000 lamps: five levels of 8 lanes, so every trail step (3 bits per level) is used. The
// pmf still sums to one, and sample() returns what pmf() says, for lights on every branch.
TEST(LightTree, DeepTreesKeepTheirTrails) {
  const ScatteredLamps lamps(5000, 17, 3);
  const std::vector<Light>& lights = lamps.lights;
  LightTreeStorage t = build_light_tree(lights, lamps.power);
  const LightTreeView v = t.view();
  uint32_t deepest = 0;
  for (uint32_t bits : t.trail) deepest |= bits;
  EXPECT_NE(deepest >> (4 * kLightTreeTrailBits), 0u) << "a light five levels down";
  const Normal3 ns = normalize(Vec3{0.3f, 1, -0.2f});
  for (const Point3& p : {Point3{0, 0, 0}, Point3{8, -9, 3}}) {
    double sum = 0;
    for (int i = 0; i < int(lights.size()); ++i) sum += double(v.pmf(i, p, ns));
    EXPECT_NEAR(sum, 1.0, 1e-4);
    for (int k = 0; k < 4000; ++k) {
      Float pmf;
      const int li = v.sample((Float(k) + 0.5f) / 4000, p, ns, &pmf);
      ASSERT_GE(li, 0);
      ASSERT_NEAR(pmf, v.pmf(li, p, ns), 1e-5f * pmf) << "light " << li;
    }
  }
}

// sample_many interleaves the descents of up to kLightTreeBatch points level by level: the
// same light, probability and remapped u as sample() one point at a time, bit for bit, for
// batches of every size, on a tree whose leaves lie at different depths.
TEST(LightTree, BatchedDescentsMatchOneAtATime) {
  const ScatteredLamps lamps(700, 23, 9);
  PCG32 rng(5, 1);
  LightTreeStorage t = build_light_tree(lamps.lights, lamps.power);
  const LightTreeView v = t.view();
  int depths = 0;  // the levels at which the batches' descents ended (bit d: depth d)
  for (int n = 0; n <= kLightTreeBatch; ++n)
    for (int trial = 0; trial < 40; ++trial) {
      Float u[kLightTreeBatch], pmf[kLightTreeBatch], ur[kLightTreeBatch];
      Point3 p[kLightTreeBatch];
      Normal3 ns[kLightTreeBatch];
      int light[kLightTreeBatch];
      for (int i = 0; i < n; ++i) {
        u[i] = rng.next_float();
        p[i] = Point3{24 * rng.next_float() - 12, 24 * rng.next_float() - 12, 24 * rng.next_float() - 12};
        ns[i] = i % 5 == 4 ? Normal3{} : normalize(Vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.3f});
      }
      v.sample_many(n, u, p, ns, light, pmf, ur);
      for (int i = 0; i < n; ++i) {
        Float pmf1, ur1;
        ASSERT_EQ(light[i], v.sample(u[i], p[i], ns[i], &pmf1, &ur1)) << "batch of " << n << ", point " << i;
        ASSERT_EQ(pmf[i], pmf1);
        ASSERT_EQ(ur[i], ur1);
        LightTreeDescent d;  // the levels this descent takes
        int levels = 1;
        while (v.step(&d, u[i], p[i], ns[i]) < 0) ++levels;
        depths |= 1 << levels;
      }
    }
  EXPECT_GE(__builtin_popcount(unsigned(depths)), 2) << "leaves at more than one depth";
}

// The vector steps of a node (AVX2 where the build has it) against their lane-by-lane
// definitions, on every node of a tree at random points: the lanes' probabilities, and the
// lane an interval position falls in (the same lane but within rounding of a boundary).
TEST(LightTree, VectorStepsMatchTheLaneByLaneDefinition) {
  RandomLights r;
  LightTreeStorage t = build_light_tree(r.lights, r.power);
  PCG32 rng(23, 1);
  int compared = 0;
  for (const LightTreeNode& node : t.nodes)
    for (int k = 0; k < 200; ++k) {
      const Point3 p{12 * rng.next_float() - 6, 12 * rng.next_float() - 6, 12 * rng.next_float() - 6};
      const Normal3 ns = k % 2 ? normalize(Vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.2f}) : Normal3{};
      Float imp[kLightTreeArity], want[kLightTreeArity], got[kLightTreeArity];
      light_tree_importance(node, p, ns, imp);
#if KAURI_LIGHT_TREE_AVX2
      // The lanes' bound uses the reciprocal square root estimate: within a few 1e-4 of the
      // definition, relative to the bound's distance part Φ / max(d², r²) (where cos θ' is
      // near 0 the cosine's rounding dominates, so relative to the bound itself it is not).
      Float exact[kLightTreeArity];
      for (int j = 0; j < kLightTreeArity; ++j) exact[j] = imp[j];
      light_tree_importance_lanes(node, p, ns, imp);
      for (int j = 0; j < kLightTreeArity; ++j) {
        const Float d2 = sqr(p.x - node.cx[j]) + sqr(p.y - node.cy[j]) + sqr(p.z - node.cz[j]);
        ASSERT_NEAR(imp[j], exact[j], 2e-3f * node.power[j] / std::max(d2, node.radius2[j])) << j;
      }
#endif
      light_tree_probs_scalar(node, imp, want);
      light_tree_child_probs(node, p, ns, got);
      for (int j = 0; j < kLightTreeArity; ++j) ASSERT_NEAR(got[j], want[j], 1e-6f * want[j] + 1e-30f) << j;
      const Float lo = rng.next_float() * 0.5f, width = 0.1f + rng.next_float() * 0.4f;
      const Float u = lo + rng.next_float() * width;
      Float start_v, start_s;
      const int lane_s = light_tree_choose_scalar(got, u, lo, width, &start_s);
#if KAURI_LIGHT_TREE_AVX2
      // sample()'s step: the starts from the bounds' and the power shares' sums; the lane's
      // probability exactly the one pmf() reads.
      Float taken_v;
      const int lane_v = light_tree_step_lanes(node, _mm256_loadu_ps(imp), u, lo, width, &start_v, &taken_v);
      ASSERT_EQ(float_as_bits(taken_v), float_as_bits(got[lane_v]));
#else
      const int lane_v = light_tree_choose_scalar(got, u, lo, width, &start_v);
#endif
#if KAURI_LIGHT_TREE_AVX2
      // Where every bound is 0 the step chooses by the power shares alone (another branch
      // of its comparison).
      {
        Float start_p, taken_p, start_q;
        const int lane_p = light_tree_step_lanes(node, _mm256_setzero_ps(), u, lo, width, &start_p, &taken_p);
        const int lane_q = light_tree_choose_scalar(node.power_share, u, lo, width, &start_q);
        if (lane_p == lane_q) {
          ASSERT_EQ(float_as_bits(taken_p), float_as_bits(node.power_share[lane_p]));
          ASSERT_NEAR(start_p, start_q, 1e-6f);
        } else {
          ASSERT_NEAR(u, lane_p > lane_q ? start_p : start_q, 1e-6f) << "lanes " << lane_p << ", " << lane_q;
        }
      }
#endif
      if (lane_v != lane_s) {  // only where u is a boundary up to rounding
        ASSERT_NEAR(u, lane_v > lane_s ? start_v : start_s, 1e-6f) << "lanes " << lane_v << ", " << lane_s;
        continue;
      }
      ASSERT_GT(got[lane_v], 0);
      ASSERT_NEAR(start_v, start_s, 1e-6f);
      ASSERT_LE(start_v, u + 1e-6f);
      ++compared;
    }
  EXPECT_GT(compared, 1000);
}

TEST(LightTree, FewLightsAreLeftToPowerSelection) {
  std::vector<Light> lights;
  std::vector<Float> power;
  for (int i = 0; i < kLightTreeMinLights - 1; ++i) {
    lights.push_back(triangle_light(Point3{Float(i), 5, 0}, Vec3{0, -1, 0}, 0.1f, false));
    power.push_back(1);
  }
  EXPECT_EQ(build_light_tree(lights, power).view().n_nodes, 0);
  lights.push_back(triangle_light(Point3{-1, 5, 0}, Vec3{0, -1, 0}, 0.1f, false));
  power.push_back(1);
  EXPECT_EQ(build_light_tree(lights, power).view().n_nodes, 1 + 8);  // 16 lights: the root's 8 lanes, 2 lanes each below
}

}  // namespace
}  // namespace kauri
