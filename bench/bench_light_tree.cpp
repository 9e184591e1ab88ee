// Benchmark: the cost of choosing a light by the light tree (light/light_tree.h), without
// a scene or rays.
//
// The lights are a hangar ceiling like bench/scenes/hangar.py: 12 × 12 one-sided square
// lamps facing down (two triangle lights each, 288 in all, three powers), a tree of three
// levels. Shading points lie on the floor below and on the back wall. Timed with
// std::chrono, mean ns per call, best of 15 repetitions:
//   sample, independent   LightTreeView::sample for independent points: what the CPU
//                         reaches when it can overlap one descent with the next
//   sample, dependent     each point depends on the previous call's result: the latency
//                         of one descent, which a path's next-event estimate waits on
//   pmf                   LightTreeView::pmf (the MIS weight of a BSDF-sampled emitter hit)
//   power, independent    choosing by power alone (Distribution1D::sample_discrete over
//                         the 288 lights): the cheaper proposal the tree is measured against
// Inputs come from a fixed-seed PCG32 and are generated before timing; results go into a
// volatile sink so that nothing is optimised away.
//
//   kauri_bench_light_tree [--iterations N]     N: calls per measurement (default 1048576)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "kauri/light/light.h"
#include "kauri/light/light_tree.h"
#include "kauri/sampler/distribution.h"
#include "kauri/sampler/rng.h"

using namespace kauri;

namespace {

volatile double g_sink = 0;

struct Ceiling {
  std::vector<Light> lights;
  std::vector<Float> power;
};

/// 12 × 12 lamps of half-width 0.12 at height 5.5 over [−7, 7]², facing down.
Ceiling hangar_ceiling() {
  Ceiling c;
  const int n = 12;
  const Float step = 14.0f / n, half = 0.12f;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Float x = -7 + step * (Float(i) + 0.5f), z = -7 + step * (Float(j) + 0.5f);
      const Point3 q[4] = {{x - half, 5.5f, z - half}, {x + half, 5.5f, z - half}, {x + half, 5.5f, z + half},
                           {x - half, 5.5f, z + half}};
      for (int t = 0; t < 2; ++t) {
        Light l;
        l.type = LightType::Triangle;
        l.p0 = q[0];
        l.p1 = q[t + 1];
        l.p2 = q[t + 2];
        l.n = Normal3{0, -1, 0};
        l.area = 2 * half * half;
        c.lights.push_back(l);
        c.power.push_back(Float(1 + (i + j) % 3));
      }
    }
  return c;
}

template <class F>
double best_ns_per_call(int iterations, F&& run) {
  double best = 1e30;
  for (int rep = 0; rep < 15; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    g_sink = g_sink + run();
    const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
    best = std::min(best, ns / iterations);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int iterations = 1 << 20;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--iterations") && i + 1 < argc) {
      iterations = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--iterations N]\n", argv[0]);
      return 2;
    }
  }
  if (iterations < 1) {
    std::fprintf(stderr, "--iterations: expected a positive count\n");
    return 2;
  }
  const Ceiling c = hangar_ceiling();
  const LightTreeStorage tree = build_light_tree(c.lights, c.power);
  const LightTreeView view = tree.view();
  const Distribution1DStorage power_storage(c.power);
  const Distribution1D by_power = power_storage.view();

  // Half the points on the floor, half on the back wall (z = −8), as the camera sees them.
  PCG32 rng(7, 3);
  std::vector<Point3> points(static_cast<size_t>(iterations));
  std::vector<Normal3> normals(static_cast<size_t>(iterations));
  std::vector<Float> us(static_cast<size_t>(iterations));
  for (int i = 0; i < iterations; ++i) {
    const Float a = 16 * rng.next_float() - 8, b = rng.next_float();
    points[size_t(i)] = (i & 1) ? Point3{a, 6 * b, -8} : Point3{a, 0, 16 * b - 8};
    normals[size_t(i)] = (i & 1) ? Normal3{0, 0, 1} : Normal3{0, 1, 0};
    us[size_t(i)] = rng.next_float();
  }

  const double independent = best_ns_per_call(iterations, [&] {
    long sum = 0;
    for (int i = 0; i < iterations; ++i) {
      Float pmf;
      sum += view.sample(us[size_t(i)], points[size_t(i)], normals[size_t(i)], &pmf);
    }
    return double(sum);
  });
  const double dependent = best_ns_per_call(iterations, [&] {
    int prev = 0;
    long sum = 0;
    for (int i = 0; i < iterations; ++i) {
      Point3 p = points[size_t(i)];
      p.x += Float(prev) * 1e-30f;  // the next query waits on this one's result
      Float pmf;
      prev = view.sample(us[size_t(i)], p, normals[size_t(i)], &pmf);
      sum += prev;
    }
    return double(sum);
  });
  const double pmf = best_ns_per_call(iterations, [&] {
    double sum = 0;
    for (int i = 0; i < iterations; ++i)
      sum += double(view.pmf(i % int(c.lights.size()), points[size_t(i)], normals[size_t(i)]));
    return sum;
  });
  const double power = best_ns_per_call(iterations, [&] {
    long sum = 0;
    for (int i = 0; i < iterations; ++i) {
      Float pmf;
      sum += by_power.sample_discrete(us[size_t(i)], &pmf);
    }
    return double(sum);
  });

  std::printf("light choice among %zu triangle lights (a hangar ceiling; tree of %d nodes), ns per call,\n"
              "best of 15 x %d calls:\n",
              c.lights.size(), view.n_nodes, iterations);
  std::printf("  %-24s %7.1f\n", "tree sample, independent", independent);
  std::printf("  %-24s %7.1f\n", "tree sample, dependent", dependent);
  std::printf("  %-24s %7.1f\n", "tree pmf", pmf);
  std::printf("  %-24s %7.1f\n", "power, independent", power);
  return 0;
}
