// Benchmark: the per-hit cost of layered materials, without a scene.
//
// Three stacks (1, 3 and 6 lobes; the last two also with IOR + roughness
// accumulation) are compiled from MaterialDescs, as the scene compiler would, and
// timed with std::chrono: mean ns per call of
//   build   build_bsdf(): instantiate the lobes at 4 wavelengths, (accumulation),
//           the weight program for ω_o, BSDF::prepare
//   eval    BSDF::eval for a random (ω_o, ω_i) pair
//   sample  BSDF::sample (lobe selection + the lobe's sample + one-sample MIS sums)
//   pdf     BSDF::pdf for a random pair
// Inputs (ω_o on the front hemisphere, ω_i over the whole sphere, wavelengths,
// sample values) come from a fixed-seed PCG32 and are generated before timing.
// Each figure is the best of 5 repetitions, interleaved across stacks. Results
// are accumulated into a volatile sink so that nothing is optimised away.
//
//   kauri_bench_layers [--iterations N] [--per-lobe]
//     N: calls per measurement (default 100000); --per-lobe adds one 1-lobe row per lobe type.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "kauri/bsdf/material.h"
#include "kauri/geometry/shapes.h"
#include "kauri/layer/layer_compiler.h"
#include "kauri/scene/scene.h"
#include "kauri/sampler/rng.h"
#include "kauri/sampler/sampling.h"
#include "kauri/spectral/color_space.h"

using namespace kauri;

namespace {

volatile double g_sink = 0;

// ---- MaterialDesc → runnable stack (the scene's own lobe-parameter mapping)

struct Stack {
  std::string name;
  StandaloneMaterial material;
};

Stack* make_stack(const std::string& name, const MaterialDesc& m) {
  return new Stack{name, StandaloneMaterial(m, ColorSpaceId::ACEScg)};
}

LobeDesc lobe(const std::string& name, LobeType type, Float weight = 1) {
  LobeDesc l;
  l.name = name;
  l.type = type;
  l.weight.value = weight;
  return l;
}
LayerDesc layer(const std::string& name, LayerOp op, std::vector<std::string> inputs, Float weight = 1) {
  LayerDesc l;
  l.name = name;
  l.op = op;
  l.inputs = std::move(inputs);
  l.weight.value = weight;
  return l;
}

MaterialDesc one_lobe() {
  MaterialDesc m;
  m.name = "lambert";
  m.lobes = {lobe("base", LobeType::Lambert)};
  m.lobes[0].albedo = {0.6f, 0.4f, 0.3f};
  return m;
}

// coat(clear dielectric, mix(lambert 0.6, rough conductor 0.4))
MaterialDesc three_lobes(bool accumulate) {
  MaterialDesc m;
  m.name = accumulate ? "coat3+acc" : "coat3";
  LobeDesc clear = lobe("clear", LobeType::SmoothDielectric);
  clear.ior = 1.5f;
  LobeDesc diffuse = lobe("diffuse", LobeType::Lambert, 0.6f);
  diffuse.albedo = {0.5f, 0.1f, 0.1f};
  LobeDesc metal = lobe("metal", LobeType::GGXConductor, 0.4f);
  metal.eta_rgb = {0.18f, 0.42f, 1.37f};  // gold-like
  metal.k_rgb = {3.42f, 2.35f, 1.77f};
  metal.roughness = 0.35f;
  m.lobes = {clear, diffuse, metal};
  m.layers = {layer("base", LayerOp::Mix, {"diffuse", "metal"}), layer("stack", LayerOp::Coat, {"clear", "base"})};
  m.ior_accumulation = m.roughness_accumulation = accumulate;
  return m;
}

// coat(sheen 0.5, coat(clear dielectric, blend(rough conductor 0.3,
//                                             mix(lambert, diffuse transmission, rough dielectric))))
MaterialDesc six_lobes(bool accumulate) {
  MaterialDesc m;
  m.name = accumulate ? "stack6+acc" : "stack6";
  LobeDesc sheen = lobe("fuzz", LobeType::Sheen, 0.5f);
  sheen.albedo = {0.9f, 0.9f, 0.8f};
  sheen.roughness = 0.4f;
  LobeDesc clear = lobe("clear", LobeType::SmoothDielectric);
  clear.ior = 1.45f;
  LobeDesc metal = lobe("metal", LobeType::GGXConductor, 0.3f);
  metal.eta_rgb = {0.27f, 0.68f, 1.32f};  // copper-like
  metal.k_rgb = {3.61f, 2.62f, 2.29f};
  metal.roughness = 0.3f;
  LobeDesc diffuse = lobe("diffuse", LobeType::Lambert, 0.5f);
  diffuse.albedo = {0.3f, 0.5f, 0.2f};
  LobeDesc translucent = lobe("translucent", LobeType::DiffuseTransmission, 0.3f);
  translucent.albedo = {0.4f, 0.6f, 0.2f};
  LobeDesc frosted = lobe("frosted", LobeType::RoughDielectric, 0.2f);
  frosted.ior = 1.33f;
  frosted.roughness = 0.25f;
  m.lobes = {sheen, clear, metal, diffuse, translucent, frosted};
  m.layers = {layer("body", LayerOp::Mix, {"diffuse", "translucent", "frosted"}),
              layer("base", LayerOp::Blend, {"metal", "body"}),
              layer("varnished", LayerOp::Coat, {"clear", "base"}),
              layer("stack", LayerOp::Coat, {"fuzz", "varnished"})};
  m.ior_accumulation = m.roughness_accumulation = accumulate;
  return m;
}

// One lobe of each type, for --per-lobe.
MaterialDesc single(LobeType type, const char* name) {
  MaterialDesc m;
  m.name = name;
  LobeDesc l = lobe(name, type);
  if (type == LobeType::GGXConductor) {
    l.eta_rgb = {0.18f, 0.42f, 1.37f};
    l.k_rgb = {3.42f, 2.35f, 1.77f};
  }
  m.lobes = {l};
  return m;
}

// ---- inputs

constexpr int kInputs = 4096;  // distinct random inputs (power of two), cycled through
constexpr int kBsdfs = 256;    // distinct prebuilt BSDFs for eval/sample/pdf

struct Inputs {
  std::vector<Vec3> wo, wi;
  std::vector<SampledWavelengths> lambda;
  std::vector<Float> uc;
  std::vector<Vec2> u;
};

Inputs make_inputs(uint64_t seed) {
  PCG32 rng(seed, 0x6b61757269ULL);
  Inputs in;
  for (int i = 0; i < kInputs; ++i) {
    Vec3 wo = sample_uniform_sphere(Vec2{rng.next_float(), rng.next_float()});
    wo.z = std::fabs(wo.z) + 1e-3f;  // front hemisphere, as most camera/path hits see it
    in.wo.push_back(normalize(wo));
    in.wi.push_back(sample_uniform_sphere(Vec2{rng.next_float(), rng.next_float()}));
    in.lambda.push_back(SampledWavelengths::sample_visible(rng.next_float()));
    in.uc.push_back(rng.next_float());
    in.u.push_back(Vec2{rng.next_float(), rng.next_float()});
  }
  return in;
}

BSDF build(const Stack& s, Vec3 wo, const SampledWavelengths& lambda) {
  BSDF b;
  Float attrs[kMaxVertexAttributes] = {0, 0, 0, 0};
  build_bsdf(s.material.view, s.material.lobes.data(), s.material.weights.data(), attrs, Frame{}, Normal3{0, 0, 1}, wo, lambda, &b);
  return b;
}

using Clock = std::chrono::steady_clock;

/// Mean ns per call of body(i) over `iterations` calls.
template <class F>
double time_ns(long iterations, F&& body) {
  double acc = 0;
  auto t0 = Clock::now();
  for (long i = 0; i < iterations; ++i) acc += body(i);
  auto t1 = Clock::now();
  g_sink = g_sink + acc;
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / double(iterations);
}

struct Row {
  std::string name;
  int lobes = 0;
  double active = 0;  // mean lobes in the built BSDF (zero-weight lobes are dropped)
  double build = 1e300, eval = 1e300, sample = 1e300, pdf = 1e300;  // best so far
};

/// One stack under test: its prebuilt BSDFs for eval/sample/pdf and its best times.
struct Bench {
  const Stack* s;
  std::vector<BSDF> bsdfs;  // bsdfs[b] was built for wo[b] and lambda[b]
  Row row;

  Bench(const Stack* stack, const Inputs& in) : s(stack) {
    row.name = s->name;
    row.lobes = s->material.view.n_lobes;
    bsdfs.reserve(kBsdfs);
    for (int k = 0; k < kBsdfs; ++k) {
      bsdfs.push_back(build(*s, in.wo[k], in.lambda[k]));
      row.active += bsdfs.back().n_lobes;
    }
    row.active /= kBsdfs;
  }

  /// One repetition of the four measurements; keeps the best of each.
  void measure(const Inputs& in, long iterations) {
    const int mask = kInputs - 1;
    row.build = std::min(row.build, time_ns(iterations, [&](long i) {
      const int k = int(i) & mask;
      BSDF b;
      Float attrs[kMaxVertexAttributes] = {0, 0, 0, 0};
      build_bsdf(s->material.view, s->material.lobes.data(), s->material.weights.data(), attrs, Frame{}, Normal3{0, 0, 1}, in.wo[k],
                 in.lambda[k], &b);
      return double(b.select_prob[0]) + double(b.n_lobes);
    }));
    // ω_i and sample values cycle independently of the BSDF (and its ω_o, λ).
    row.eval = std::min(row.eval, time_ns(iterations, [&](long i) {
      const int b = int(i) & (kBsdfs - 1), k = int(i) & mask;
      SampledSpectrum f = bsdfs[b].eval(in.wo[b], in.wi[k], TransportMode::Radiance);
      return double(f[0] + f[3]);
    }));
    row.sample = std::min(row.sample, time_ns(iterations, [&](long i) {
      const int b = int(i) & (kBsdfs - 1), k = int(i) & mask;
      SampledWavelengths lambda = in.lambda[b];
      BSDFSample bs = bsdfs[b].sample(in.wo[b], in.uc[k], in.u[k], lambda, TransportMode::Radiance);
      return double(bs.pdf) + double(bs.f[0]) + double(bs.wi.z);
    }));
    row.pdf = std::min(row.pdf, time_ns(iterations, [&](long i) {
      const int b = int(i) & (kBsdfs - 1), k = int(i) & mask;
      return double(bsdfs[b].pdf(in.wo[b], in.wi[k]));
    }));
  }
};

}  // namespace

int main(int argc, char** argv) {
  long iterations = 100000;
  bool per_lobe = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--per-lobe")) {
      per_lobe = true;
    } else if (!std::strcmp(argv[i], "--iterations") && i + 1 < argc) {
      iterations = std::atol(argv[++i]);
    } else if (!std::strncmp(argv[i], "--iterations=", 13)) {
      iterations = std::atol(argv[i] + 13);
    } else {
      std::fprintf(stderr, "usage: %s [--iterations N] [--per-lobe]\n", argv[0]);
      return std::strcmp(argv[i], "--help") && std::strcmp(argv[i], "-h") ? 2 : 0;
    }
  }
  if (iterations < 1) {
    std::fprintf(stderr, "--iterations must be >= 1\n");
    return 2;
  }

  std::vector<Stack*> stacks = {make_stack("lambert", one_lobe()),     make_stack("coat3", three_lobes(false)),
                                make_stack("coat3+acc", three_lobes(true)), make_stack("stack6", six_lobes(false)),
                                make_stack("stack6+acc", six_lobes(true))};
  if (per_lobe) {
    const std::pair<LobeType, const char*> types[] = {
        {LobeType::Lambert, "1:lambert"},           {LobeType::SmoothDielectric, "1:dielectric"},
        {LobeType::GGXConductor, "1:conductor"},    {LobeType::DiffuseTransmission, "1:diff_trans"},
        {LobeType::RoughDielectric, "1:rough_diel"}, {LobeType::ThinDielectric, "1:thin_diel"},
        {LobeType::Sheen, "1:sheen"}};
    for (const auto& [type, name] : types) stacks.push_back(make_stack(name, single(type, name)));
  }
  const Inputs in = make_inputs(1);

  std::vector<Bench> benches;
  for (const Stack* s : stacks) benches.emplace_back(s, in);
  // Repetitions are interleaved across stacks, so a burst of load from other
  // processes spoils one repetition of every row rather than all of one row.
  // Round 0 is an untimed warm-up (caches, branch predictors, clock ramp-up).
  const int kRepetitions = 5;
  for (int rep = 0; rep <= kRepetitions; ++rep)
    for (Bench& b : benches) {
      if (rep == 0) {
        Row keep = b.row;
        b.measure(in, iterations);
        b.row = keep;
      } else {
        b.measure(in, iterations);
      }
    }

  std::printf("kauri layered-material cost: %ld calls per measurement, best of %d, mean ns per call\n", iterations,
              kRepetitions);
  std::printf("%-12s %5s %7s %9s %9s %9s %9s\n", "stack", "lobes", "active", "build ns", "eval ns", "sample ns",
              "pdf ns");
  for (const Bench& b : benches) {
    const Row& r = b.row;
    std::printf("%-12s %5d %7.2f %9.1f %9.1f %9.1f %9.1f\n", r.name.c_str(), r.lobes, r.active, r.build, r.eval,
                r.sample, r.pdf);
  }
  std::printf("(active: mean lobes left in the built BSDF; lobes with zero weight are dropped)\n");
  if (g_sink == 12345.678) std::printf("\n");  // keeps the sink observable
  for (Stack* s : stacks) delete s;
  return 0;
}
