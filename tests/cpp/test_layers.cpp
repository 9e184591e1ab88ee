// Layer system: the exact operator weights of the course notes (§8.4.1, eqs. 3–11),
// tree composition, the graph compiler's checks, single-sided/symmetric programs,
// IOR/roughness accumulation, energy conservation and sampling of layered stacks.
#include <gtest/gtest.h>

#include <stdexcept>

#include "chi2.h"
#include "kauri/bsdf/material.h"
#include "kauri/geometry/shapes.h"
#include "kauri/layer/layer_compiler.h"
#include "kauri/scene/scene.h"
#include "kauri/spectral/color_space.h"

namespace kauri {
namespace {

// ---- a small builder for programs written by hand (post-order, root last)

struct ProgramBuilder {
  std::vector<LayerNode> nodes;
  std::vector<uint16_t> children;
  int lobe(int index) {
    LayerNode n;
    n.op = LayerOp::Lobe;
    n.lobe = int16_t(index);
    nodes.push_back(n);
    return int(nodes.size()) - 1;
  }
  int op(LayerOp o, std::initializer_list<int> kids) {
    LayerNode n;
    n.op = o;
    n.first_child = uint16_t(children.size());
    n.n_children = uint8_t(kids.size());
    for (int k : kids) children.push_back(uint16_t(k));
    nodes.push_back(n);
    return int(nodes.size()) - 1;
  }
  LayerProgram program() const { return {nodes.data(), children.data(), int(nodes.size())}; }
};

void evaluate_layer_weights_(const LayerProgram& p, const LayerInputs& in, SampledSpectrum* w) {
  Float transmission[kMaxLayerNodes];
  evaluate_layer_weights(p, in, w, transmission);
}

LayerInputs inputs(std::initializer_list<Float> node_weights, std::initializer_list<Float> stopped) {
  LayerInputs in;
  int i = 0;
  for (Float w : node_weights) in.node_weight[i++] = w;
  i = 0;
  for (Float s : stopped) in.lobe_stopped[i++] = SampledSpectrum(s);
  return in;
}

TEST(LayerOps, MixNormalisesWeights) {  // eqs. 3–4
  ProgramBuilder b;
  int a = b.lobe(0), c = b.lobe(1), d = b.lobe(2);
  b.op(LayerOp::Mix, {a, c, d});
  SampledSpectrum w[3];
  evaluate_layer_weights_(b.program(), inputs({0.2f, 0.3f, 0.5f, 0.8f}, {1, 1, 1}), w);
  EXPECT_FLOAT_EQ(w[0][0], 0.2f / 1.0f * 0.8f);
  EXPECT_FLOAT_EQ(w[1][0], 0.3f * 0.8f);
  EXPECT_FLOAT_EQ(w[2][0], 0.5f * 0.8f);
  // Unnormalised inputs are normalised: (1, 3) → (1/4, 3/4).
  ProgramBuilder b2;
  int x = b2.lobe(0), y = b2.lobe(1);
  b2.op(LayerOp::Mix, {x, y});
  evaluate_layer_weights_(b2.program(), inputs({0.25f, 0.75f, 1}, {1, 1}), w);
  EXPECT_FLOAT_EQ(w[0][0], 0.25f);
  EXPECT_FLOAT_EQ(w[1][0], 0.75f);
}

TEST(LayerOps, CoatUsesTheTopsStoppedEnergy) {  // eqs. 5–7
  ProgramBuilder b;
  int top = b.lobe(0), bottom = b.lobe(1);
  b.op(LayerOp::Coat, {top, bottom});
  SampledSpectrum w[2];
  // a_b1 = a_r1 + a_a1 = 0.3, w_b1 = 0.7, w_l = 0.9.
  evaluate_layer_weights_(b.program(), inputs({0.7f, 0.4f, 0.9f}, {0.3f, 1}), w);
  EXPECT_FLOAT_EQ(w[0][0], 0.7f * 0.9f);
  // Eq. 7 with the bottom's presence w_b2 = 0.4 (see layer_program.h for why it enters).
  EXPECT_FLOAT_EQ(w[1][0], (1 - 0.3f * 0.7f) * 0.4f * 0.9f);
  Float transmission[2];
  evaluate_layer_weights(b.program(), inputs({0.7f, 0.4f, 0.9f}, {0.3f, 1}), w, transmission);
  EXPECT_FLOAT_EQ(transmission[0], 1 - 0.4f);  // the top transmits only where the bottom is absent
  EXPECT_FLOAT_EQ(transmission[1], 1.0f);
  // An opaque (a_t = 0), fully weighted top hides the base exactly.
  evaluate_layer_weights_(b.program(), inputs({1, 1, 1}, {1, 1}), w);
  EXPECT_EQ(w[1][0], 0.0f);
}

TEST(LayerOps, BlendSubstitutes) {  // eqs. 8–9
  ProgramBuilder b;
  int l1 = b.lobe(0), l2 = b.lobe(1);
  b.op(LayerOp::Blend, {l1, l2});
  SampledSpectrum w[2];
  evaluate_layer_weights_(b.program(), inputs({0.3f, 0.6f, 0.5f}, {1, 1}), w);
  EXPECT_FLOAT_EQ(w[0][0], 0.3f * 0.5f);
  EXPECT_FLOAT_EQ(w[1][0], (1 - 0.3f) * 0.6f * 0.5f);
}

TEST(LayerOps, AddSums) {  // eqs. 10–11
  ProgramBuilder b;
  int l1 = b.lobe(0), l2 = b.lobe(1);
  b.op(LayerOp::Add, {l1, l2});
  SampledSpectrum w[2];
  evaluate_layer_weights_(b.program(), inputs({0.4f, 0.9f, 0.5f}, {1, 1}), w);
  EXPECT_FLOAT_EQ(w[0][0], 0.4f * 0.5f);
  EXPECT_FLOAT_EQ(w[1][0], 0.9f * 0.5f);
}

TEST(LayerOps, NestedLayersComposeMultipliers) {
  // coat(mix(A, B) [w_l = 0.5], C) under a root w_l of 0.8. The nested mix enters the
  // coat with w_b = 0.5 and stops a_b = Σ (relative weight × a_b) of its lobes.
  ProgramBuilder b;
  int A = b.lobe(0), B = b.lobe(1);
  int mix = b.op(LayerOp::Mix, {A, B});
  int C = b.lobe(2);
  b.op(LayerOp::Coat, {mix, C});
  SampledSpectrum w[3];
  // node weights: A 1, B 3, mix 0.5, C 1, coat 0.8; stopped: A 0.2, B 0.6, C 1.
  evaluate_layer_weights_(b.program(), inputs({1, 3, 0.5f, 1, 0.8f}, {0.2f, 0.6f, 1}), w);
  const float m_mix = 0.5f * 0.8f;
  EXPECT_FLOAT_EQ(w[0][0], 0.25f * m_mix);
  EXPECT_FLOAT_EQ(w[1][0], 0.75f * m_mix);
  const float stopped_mix = 0.25f * 0.2f + 0.75f * 0.6f;
  EXPECT_FLOAT_EQ(w[2][0], (1 - stopped_mix * 0.5f) * 1.0f * 0.8f);
}

TEST(LayerOps, SpectralAlbedoTintsWhatLiesBelow) {
  ProgramBuilder b;
  int top = b.lobe(0), bottom = b.lobe(1);
  b.op(LayerOp::Coat, {top, bottom});
  LayerInputs in = inputs({1, 1, 1}, {0, 1});
  in.lobe_stopped[0] = SampledSpectrum(0);
  in.lobe_stopped[0][2] = 0.5f;  // the top stops half the light at one wavelength only
  SampledSpectrum w[2];
  evaluate_layer_weights_(b.program(), in, w);
  EXPECT_FLOAT_EQ(w[1][0], 1.0f);
  EXPECT_FLOAT_EQ(w[1][2], 0.5f);
}

// ---- the compiler

LobeDesc lambert_desc(const std::string& name, Float w = 1) {
  LobeDesc l;
  l.name = name;
  l.type = LobeType::Lambert;
  l.weight.value = w;
  return l;
}
LobeDesc glass_desc(const std::string& name, Float ior = 1.5f) {
  LobeDesc l;
  l.name = name;
  l.type = LobeType::SmoothDielectric;
  l.ior = ior;
  return l;
}
LayerDesc layer(const std::string& name, LayerOp op, std::vector<std::string> in, Float w = 1) {
  LayerDesc l;
  l.name = name;
  l.op = op;
  l.inputs = std::move(in);
  l.weight.value = w;
  return l;
}

std::string compile_error(const MaterialDesc& m) {
  try {
    compile_material(m);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(LayerCompiler, ReportsBadGraphsWithMaterialAndNode) {
  MaterialDesc m;
  m.name = "paint";
  m.lobes = {lambert_desc("base"), lambert_desc("top")};
  m.layers = {layer("stack", LayerOp::Coat, {"top", "bsae"})};
  EXPECT_NE(compile_error(m).find("material 'paint', node 'stack': unknown input 'bsae'"), std::string::npos);

  m.layers = {layer("a", LayerOp::Coat, {"top", "b"}), layer("b", LayerOp::Coat, {"base", "a"})};
  EXPECT_NE(compile_error(m).find("cycle"), std::string::npos) << compile_error(m);

  m.layers = {layer("stack", LayerOp::Coat, {"top", "base"}, 1.5f)};
  EXPECT_NE(compile_error(m).find("node 'stack': parameter 'weight': must lie in [0, 1]"), std::string::npos);

  m.layers = {layer("stack", LayerOp::Coat, {"top", "base", "top"})};
  EXPECT_NE(compile_error(m).find("coat takes exactly 2 inputs"), std::string::npos);

  m.layers = {layer("base", LayerOp::Coat, {"top", "base"})};
  EXPECT_NE(compile_error(m).find("duplicate node name"), std::string::npos);

  m.layers = {};
  EXPECT_NE(compile_error(m).find("several unconnected nodes"), std::string::npos);
}

TEST(LayerCompiler, AddOnScatteringLobesBecomesCoatWithWarning) {
  MaterialDesc m;
  m.name = "m";
  m.lobes = {lambert_desc("a"), lambert_desc("b")};
  m.layers = {layer("sum", LayerOp::Add, {"a", "b"})};
  CompiledMaterial c = compile_material(m);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("treated as 'coat'"), std::string::npos);
  EXPECT_EQ(c.layout.nodes.back().op, LayerOp::Coat);
}

TEST(LayerCompiler, SingleSidedStacksReverseVerticalOperatorsOnly) {
  MaterialDesc m;
  m.name = "window";
  m.lobes = {lambert_desc("dirt"), glass_desc("glass"), lambert_desc("x"), lambert_desc("y")};
  m.layers = {layer("pane", LayerOp::Coat, {"dirt", "glass"}), layer("side", LayerOp::Mix, {"x", "y"}),
              layer("all", LayerOp::Blend, {"pane", "side"})};
  m.symmetric = false;
  CompiledMaterial c = compile_material(m);
  const LayerLayout& L = c.layout;
  for (size_t i = 0; i < L.nodes.size(); ++i) {
    const LayerNode& n = L.nodes[i];
    for (int k = 0; k < n.n_children; ++k) {
      uint16_t f = L.front_children[n.first_child + k];
      uint16_t b = L.back_children[n.first_child + k];
      if (n.op == LayerOp::Coat) EXPECT_EQ(b, L.front_children[n.first_child + (n.n_children - 1 - k)]);
      else EXPECT_EQ(b, f);
    }
  }
  m.symmetric = true;
  CompiledMaterial s = compile_material(m);
  EXPECT_EQ(s.layout.front_children, s.layout.back_children);
  EXPECT_NE(s.layout.key(), c.layout.key());
}

TEST(LayerCompiler, IdenticalLayoutsShareAKey) {
  MaterialDesc a, b;
  a.name = "a";
  b.name = "b";
  a.lobes = {lambert_desc("x", 0.3f), glass_desc("g", 1.3f)};
  b.lobes = {lambert_desc("p", 0.9f), glass_desc("q", 1.7f)};
  a.layers = {layer("l", LayerOp::Coat, {"g", "x"}, 0.5f)};
  b.layers = {layer("m", LayerOp::Coat, {"q", "p"}, 1.0f)};
  EXPECT_EQ(compile_material(a).layout.key(), compile_material(b).layout.key());
}

// ---- evaluation through build_bsdf with real lobes

/// A material compiled on its own (the same lobe-parameter mapping scenes use).
using Stack = StandaloneMaterial;
BSDF build(const Stack& s, Vec3 wo, const SampledWavelengths& lambda) {
  BSDF b;
  Float attrs[kMaxVertexAttributes] = {0, 0, 0, 0};
  build_bsdf(s.view, s.lobes.data(), s.weights.data(), attrs, Frame{}, Normal3{0, 0, 1}, wo, lambda, &b);
  return b;
}

LobeDesc conductor_desc(const std::string& name, Float roughness, Float eta = 1.5f, Float k = 3) {
  LobeDesc l;
  l.name = name;
  l.type = LobeType::GGXConductor;
  l.eta_rgb = {eta, eta, eta};
  l.k_rgb = {k, k, k};
  l.roughness = roughness;
  return l;
}

// A single lobe is built straight into the BSDF (evaluate_material's fast path); the
// general path (taken here because accumulation is on, which changes nothing with one
// lobe) must give the same BSDF: lobe, weight, and the conductor's compensation cache.
TEST(LayeredBSDF, SingleLobeFastPathMatchesTheGeneralPath) {
  SampledWavelengths lambda = SampledWavelengths::sample_visible(0.3f);
  const Vec3 wo = normalize(Vec3{0.3f, -0.2f, 0.8f});
  for (int kind = 0; kind < 3; ++kind) {
    MaterialDesc m;
    m.name = "one";
    m.lobes = {kind == 0 ? lambert_desc("a", 0.6f) : conductor_desc("a", kind == 1 ? 0.3f : 0.05f)};
    m.lobes[0].albedo = {0.2f, 0.5f, 0.8f};
    Stack fast(m, ColorSpaceId::LinearSRGB);
    m.ior_accumulation = m.roughness_accumulation = true;
    Stack general(m, ColorSpaceId::LinearSRGB);
    ASSERT_FALSE(fast.view.ior_accumulation);
    BSDF a = build(fast, wo, lambda), b = build(general, wo, lambda);
    ASSERT_EQ(a.n_lobes, 1);
    ASSERT_EQ(b.n_lobes, 1);
    EXPECT_EQ(a.lobes[0].type, b.lobes[0].type);
    for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_EQ(a.weight[0][i], b.weight[0][i]);
    EXPECT_EQ(a.select_prob[0], 1);
    if (kind == 0) {
      EXPECT_NEAR(a.weight[0][0], 0.6f, 1e-6f);
    }
    if (kind > 0) {
      EXPECT_EQ(a.lobes[0].conductor.ms_cached, b.lobes[0].conductor.ms_cached);
    }
    for (Vec3 wi : {Vec3{0, 0, 1}, normalize(Vec3{-0.3f, 0.2f, 0.8f}), normalize(Vec3{0.7f, 0.1f, 0.3f})}) {
      SampledSpectrum fa = a.eval(wo, wi, TransportMode::Radiance), fb = b.eval(wo, wi, TransportMode::Radiance);
      for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_FLOAT_EQ(fa[i], fb[i]) << "kind " << kind;
      EXPECT_FLOAT_EQ(a.pdf(wo, wi), b.pdf(wo, wi));
    }
  }
  // A zero weight leaves the BSDF empty, as BSDF::add does.
  MaterialDesc z;
  z.name = "zero";
  z.lobes = {lambert_desc("a", 0.0f)};
  EXPECT_EQ(build(Stack(z, ColorSpaceId::LinearSRGB), wo, lambda).n_lobes, 0);
}

TEST(LayeredBSDF, ClearCoatWeightsBaseByFresnelTransmission) {
  MaterialDesc m;
  m.name = "varnish";
  m.lobes = {glass_desc("clear", 1.5f), lambert_desc("base")};
  m.lobes[1].albedo = {0.5f, 0.5f, 0.5f};
  m.layers = {layer("stack", LayerOp::Coat, {"clear", "base"})};
  Stack s(m, ColorSpaceId::LinearSRGB);
  SampledWavelengths lambda = SampledWavelengths::sample_visible(0.4f);
  for (Float c : {1.0f, 0.5f, 0.1f}) {
    Vec3 wo{std::sqrt(1 - c * c), 0, c};
    BSDF b = build(s, wo, lambda);
    ASSERT_EQ(b.n_lobes, 2);
    Float F = fresnel_dielectric(c, 1.5f);
    EXPECT_NEAR(b.weight[0][0], 1.0f, 1e-6f);
    EXPECT_NEAR(b.weight[1][0], 1 - F, 1e-5f) << "cos " << c;  // a_b = a_r + a_a = F
  }
}

TEST(LayeredBSDF, SingleSidedStackSeenFromBehind) {
  // Dirt (opaque) coated on glass, single-sided: from the front only the dirt is
  // seen at full weight; from behind the glass is on top and the dirt gets 1 − F.
  MaterialDesc m;
  m.name = "window";
  m.lobes = {lambert_desc("dirt"), glass_desc("glass")};
  m.layers = {layer("pane", LayerOp::Coat, {"dirt", "glass"})};
  m.symmetric = false;
  Stack s(m, ColorSpaceId::LinearSRGB);
  SampledWavelengths lambda = SampledWavelengths::sample_visible(0.4f);
  BSDF front = build(s, Vec3{0, 0, 1}, lambda);
  ASSERT_EQ(front.n_lobes, 1);  // the opaque dirt hides the glass
  EXPECT_EQ(front.lobes[0].type, LobeType::Lambert);
  BSDF back = build(s, Vec3{0, 0, -1}, lambda);
  ASSERT_EQ(back.n_lobes, 2);
  EXPECT_EQ(back.lobes[0].type, LobeType::Lambert);
  EXPECT_NEAR(back.weight[0][0], 1 - fresnel_dielectric(-1, 1.5f), 1e-5f);
  m.symmetric = true;
  Stack sym(m, ColorSpaceId::LinearSRGB);
  BSDF back_sym = build(sym, Vec3{0, 0, -1}, lambda);
  ASSERT_EQ(back_sym.n_lobes, 1);
  EXPECT_EQ(back_sym.lobes[0].type, LobeType::Lambert);
}

TEST(LayeredBSDF, IorAccumulationMakesIndexMatchedInterfacesVanish) {
  // A conductor-like base with real IOR 1.5 under a dielectric of IOR n: its relative
  // IOR becomes 1.5/n; at n = 1.5 with κ = 0 its highlight (Fresnel) is zero.
  MaterialDesc m;
  m.name = "wet";
  m.lobes = {glass_desc("water", 1.5f), conductor_desc("base", 0.2f, 1.5f, 0)};
  m.layers = {layer("stack", LayerOp::Coat, {"water", "base"})};
  m.ior_accumulation = true;
  Stack s(m, ColorSpaceId::LinearSRGB);
  SampledWavelengths lambda = SampledWavelengths::sample_visible(0.4f);
  BSDF b = build(s, Vec3{0, 0, 1}, lambda);
  ASSERT_EQ(b.n_lobes, 2);
  EXPECT_NEAR(b.lobes[1].conductor.eta[0], 1.0f, 1e-3f);
  EXPECT_NEAR(b.lobes[1].albedo_r(Vec3{0, 0, 1})[0], 0.0f, 1e-5f);
  m.ior_accumulation = false;
  BSDF off = build(Stack(m, ColorSpaceId::LinearSRGB), Vec3{0, 0, 1}, lambda);
  EXPECT_GT(off.lobes[1].albedo_r(Vec3{0, 0, 1})[0], 0.03f);
}

TEST(LayeredBSDF, RoughnessAccumulationWidensLobesBelowRoughLayers) {
  MaterialDesc m;
  m.name = "dusty";
  m.lobes = {conductor_desc("dust", 0.7f), conductor_desc("metal", 0.1f)};
  m.lobes[0].weight.value = 0.3f;
  m.layers = {layer("stack", LayerOp::Coat, {"dust", "metal"})};
  m.roughness_accumulation = true;
  SampledWavelengths lambda = SampledWavelengths::sample_visible(0.4f);
  BSDF b = build(Stack(m, ColorSpaceId::LinearSRGB), Vec3{0, 0, 1}, lambda);
  ASSERT_EQ(b.n_lobes, 2);
  EXPECT_NEAR(b.lobes[1].conductor.mf.alpha_x, 0.49f, 1e-5f);
  EXPECT_NEAR(b.lobes[1].roughness(), 0.7f, 1e-5f);
  m.roughness_accumulation = false;
  BSDF off = build(Stack(m, ColorSpaceId::LinearSRGB), Vec3{0, 0, 1}, lambda);
  EXPECT_NEAR(off.lobes[1].conductor.mf.alpha_x, 0.01f, 1e-6f);
}

struct Estimate {
  double mean[kSpectrumSamples], sigma[kSpectrumSamples];
};

Estimate albedo_of(const BSDF& b, Vec3 wo, uint64_t seed, int n) {
  PCG32 rng(seed, 7);
  double s[kSpectrumSamples] = {}, s2[kSpectrumSamples] = {};
  SampledWavelengths lambda0 = SampledWavelengths::sample_visible(0.4f);
  for (int k = 0; k < n; ++k) {
    SampledWavelengths lambda = lambda0;
    BSDFSample bs = b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()}, lambda,
                             TransportMode::Importance);
    if (!bs.valid()) continue;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      double v = double(bs.f[i] * absdot(bs.wi, Vec3{0, 0, 1}) / bs.pdf);
      s[i] += v;
      s2[i] += v * v;
    }
  }
  Estimate e;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    e.mean[i] = s[i] / n;
    e.sigma[i] = std::sqrt(std::max(0.0, s2[i] / n - e.mean[i] * e.mean[i]) / n);
  }
  return e;
}

TEST(LayeredBSDF, OperatorsKeepEnergyConservingStacksConserving) {
  // White (albedo 1) lobes and a non-absorbing dielectric in every operator: the
  // stack's directional albedo never exceeds 1.
  std::vector<MaterialDesc> cases;
  for (LayerOp op : {LayerOp::Mix, LayerOp::Coat, LayerOp::Blend}) {
    MaterialDesc m;
    m.name = "case";
    m.lobes = {glass_desc("g"), lambert_desc("w", 0.6f), conductor_desc("c", 0.4f, 1, 1e4f)};
    m.lobes[1].albedo = {1, 1, 1};
    m.layers = {layer("inner", op, {"w", "c"}), layer("root", LayerOp::Coat, {"g", "inner"})};
    cases.push_back(m);
  }
  uint64_t seed = 900;
  for (const MaterialDesc& m : cases) {
    Stack s(m, ColorSpaceId::LinearSRGB);
    for (Float c : {1.0f, 0.4f, 0.1f}) {
      Vec3 wo{std::sqrt(1 - c * c), 0, c};
      BSDF b = build(s, wo, SampledWavelengths::sample_visible(0.4f));
      Estimate e = albedo_of(b, wo, seed++, 200000);
      for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_LE(e.mean[i], 1 + 4 * e.sigma[i]) << "cos " << c;
    }
  }
}

TEST(LayeredBSDF, SamplingMatchesPdfForStacksOfTwoToFiveLobes) {
  uint64_t seed = 1200;
  for (int n = 2; n <= 5; ++n) {
    MaterialDesc m;
    m.name = "stack" + std::to_string(n);
    m.lobes = {lambert_desc("diffuse", 0.8f)};
    m.lobes[0].albedo = {0.6f, 0.4f, 0.2f};
    for (int k = 1; k < n; ++k) {
      m.lobes.push_back(conductor_desc("metal" + std::to_string(k), 0.15f + 0.2f * Float(k), 1.2f, 2));
      m.lobes.back().weight.value = 0.5f;
    }
    // metal_{n-1} coated over ... over a mix of the diffuse and metal1.
    std::string below = "diffuse";
    for (int k = 1; k < n; ++k) {
      std::string name = "layer" + std::to_string(k);
      LayerOp op = k == 1 ? LayerOp::Mix : LayerOp::Coat;
      m.layers.push_back(layer(name, op, {"metal" + std::to_string(k), below}));
      below = name;
    }
    Stack s(m, ColorSpaceId::LinearSRGB);
    Vec3 wo = normalize(Vec3{0.5f, 0.2f, 0.6f});
    SampledWavelengths lambda0 = SampledWavelengths::sample_visible(0.4f);
    BSDF b = build(s, wo, lambda0);
    ASSERT_EQ(b.n_lobes, n);
    auto sample = [&](PCG32& r, Vec3* w) {
      SampledWavelengths lambda = lambda0;
      BSDFSample bs = b.sample(wo, r.next_float(), {r.next_float(), r.next_float()}, lambda,
                               TransportMode::Radiance);
      if (!bs.valid()) return false;
      *w = bs.wi;
      return true;
    };
    test::SphereChi2Config cfg;
    cfg.name = "layered stack of " + std::to_string(n) + " lobes";
    cfg.forced_cos = {0};
    cfg.samples = 300000;
    cfg.seed = seed++;
    EXPECT_TRUE(test::sphere_chi2(sample, [&](Vec3 w) { return double(b.pdf(wo, w)); }, cfg));
  }
}

}  // namespace
}  // namespace kauri
