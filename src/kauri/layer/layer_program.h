// Layer programs: a material's layer tree compiled into a flat, post-order node
// list (children before parents, root last). Evaluated at each hit, a program
// turns per-node weights and per-lobe directional albedos into the final weight
// of every lobe, following the layering operators of the course notes
// ("Path tracing in Production, Part 2", §8.4.1, equations 3–11).
//
// The layout (ops and tree shape) carries no parameter values, so identical
// layouts across materials are stored once; weights live with each material.
#pragma once

#include "kauri/core/scratch_array.h"
#include "kauri/spectral/sampled.h"

namespace kauri {

enum class LayerOp : uint8_t { Lobe, Mix, Coat, Blend, Add };

inline constexpr int kMaxLayerNodes = 16;   // lobes + operators per material
inline constexpr int kMaxMixInputs = 8;

struct LayerNode {
  LayerOp op = LayerOp::Lobe;
  uint8_t n_children = 0;
  uint16_t first_child = 0;  // into LayerProgram::children
  int16_t lobe = -1;         // op == Lobe: the lobe's index within the material
};

/// A view of one compiled layout. `children` lists, per operator node, its input
/// node indices in order (for coat: top first).
struct LayerProgram {
  const LayerNode* nodes = nullptr;
  const uint16_t* children = nullptr;
  int n_nodes = 0;
};

/// Inputs of one program evaluation.
struct LayerInputs {
  Float node_weight[kMaxLayerNodes];   // w_b for lobe nodes, w_l for operator nodes
  ScratchArray<SampledSpectrum, kMaxLayerNodes> lobe_stopped;  // per lobe: a_b = a_r + a_a = 1 − a_t at ω_o (eq. 5)
};

/// Evaluates the weight program: `lobe_weight[k]` receives the final weight of lobe k,
/// and `lobe_transmission[k]` the fraction of lobe k's own transmission that leaves
/// the stack. A lobe in the top input of a coat hands the energy it transmits to the
/// bottom input — whose weight already accounts for it — so only the part the bottom
/// does not cover (1 − w_b2) is rendered as the top's transmission. Without this a
/// transmissive coat over a base would return more energy than it receives.
/// Weights are spectral: albedos vary with wavelength, so light reaching the bottom
/// of a tinted stack is tinted (node weights themselves are scalars).
///
/// Conventions (how eqs. 3–11 compose in a tree): every node's own weight is its
/// presence and is applied exactly once — a lobe's w_b and a nested layer's w_l
/// enter the parent's equation as that input's w_b; the root's w_l enters its own
/// equation as w_l. A nested layer used as an input stops the energy
/// a_b = Σ (its lobes' weights relative to it) × (1 − a_t): the albedo of the
/// sub-stack. Coat weights the bottom input by (1 − a_b1 w_b1) w_b2 w_l: eq. 7 as
/// printed omits the bottom's own presence w_b2; we include it, as eqs. 9 and 11 do
/// for their second input, so a masked base is absent where its mask is 0 (light
/// then passes through the top instead of reaching a base that is not there).
KAURI_HOST_DEVICE inline void evaluate_layer_weights(const LayerProgram& p, const LayerInputs& in,
                                                     SampledSpectrum* lobe_weight, Float* lobe_transmission) {
  ScratchArray<SampledSpectrum, kMaxLayerNodes> mult;     // multiplier each node receives from its parent
  ScratchArray<SampledSpectrum, kMaxLayerNodes> stopped;  // a_b of each node as an input (per unit presence)
  const int root = p.n_nodes - 1;
  // Bottom-up: each operator's input multipliers and its own stopped albedo.
  for (int i = 0; i < p.n_nodes; ++i) {
    const LayerNode& n = p.nodes[i];
    if (n.op == LayerOp::Lobe) {
      stopped[i] = in.lobe_stopped[n.lobe];
      continue;
    }
    const uint16_t* c = p.children + n.first_child;
    const Float wl = i == root ? in.node_weight[i] : Float(1);
    auto w_b = [&](int k) { return in.node_weight[c[k]]; };
    switch (n.op) {
      case LayerOp::Mix: {  // eqs. 3–4
        Float sum = 0;
        for (int k = 0; k < n.n_children; ++k) sum += w_b(k);
        for (int k = 0; k < n.n_children; ++k) mult[c[k]] = SampledSpectrum(sum > 0 ? w_b(k) / sum * wl : 0);
        break;
      }
      case LayerOp::Coat:  // eqs. 5–7
        mult[c[0]] = SampledSpectrum(w_b(0) * wl);
        mult[c[1]] = (SampledSpectrum(1) - stopped[c[0]] * w_b(0)) * (w_b(1) * wl);
        break;
      case LayerOp::Blend:  // eqs. 8–9
        mult[c[0]] = SampledSpectrum(w_b(0) * wl);
        mult[c[1]] = SampledSpectrum((1 - w_b(0)) * w_b(1) * wl);
        break;
      case LayerOp::Add:  // eqs. 10–11 (emission only; the compiler turns other adds into coats)
        mult[c[0]] = SampledSpectrum(w_b(0) * wl);
        mult[c[1]] = SampledSpectrum(w_b(1) * wl);
        break;
      default: break;
    }
    // Relative to this node at unit presence (its own w_l is applied by its parent).
    SampledSpectrum s(0);
    for (int k = 0; k < n.n_children; ++k)
      if (wl > 0) s += mult[c[k]] * stopped[c[k]] * (1 / wl);
    for (int j = 0; j < kSpectrumSamples; ++j) s[j] = fmin_(s[j], 1);
    stopped[i] = s;
  }
  // Top-down: accumulate multipliers from the root.
  ScratchArray<SampledSpectrum, kMaxLayerNodes> acc;
  Float trans[kMaxLayerNodes];
  acc[root] = SampledSpectrum(p.nodes[root].op == LayerOp::Lobe ? in.node_weight[root] : Float(1));
  trans[root] = 1;
  for (int i = root; i >= 0; --i) {
    const LayerNode& n = p.nodes[i];
    if (n.op == LayerOp::Lobe) {
      lobe_weight[n.lobe] = acc[i];
      lobe_transmission[n.lobe] = trans[i];
      continue;
    }
    const uint16_t* c = p.children + n.first_child;
    for (int k = 0; k < n.n_children; ++k) {
      acc[c[k]] = acc[i] * mult[c[k]];
      trans[c[k]] = n.op == LayerOp::Coat && k == 0 ? trans[i] * (1 - in.node_weight[c[1]]) : trans[i];
    }
  }
}

/// What a lobe sees above it, for IOR and roughness accumulation (notes §8.4.3).
struct LayerAbove {
  SampledSpectrum ior{0};   // 0: nothing with an IOR above (air)
  Float roughness = 0;
};

/// Per-lobe interface properties: `ior` 0 and `roughness` < 0 mark lobes that take
/// no part in accumulation (Lambert, alpha-style lobes).
struct LobeInterface {
  SampledSpectrum ior{0};
  Float roughness = -1;
};

/// The accumulation program: the same layout walked for interfaces instead of
/// weights. A coat's bottom input sees the top's IOR (if it has one) and at
/// least the top's roughness; horizontal operators pass what is above through.
KAURI_HOST_DEVICE inline void evaluate_accumulation(const LayerProgram& p, const LobeInterface* lobe_if,
                                                    LayerAbove* lobe_above) {
  LobeInterface node_if[kMaxLayerNodes];
  for (int i = 0; i < p.n_nodes; ++i) {
    const LayerNode& n = p.nodes[i];
    if (n.op == LayerOp::Lobe) {
      node_if[i] = lobe_if[n.lobe];
      continue;
    }
    const uint16_t* c = p.children + n.first_child;
    LobeInterface r;
    for (int k = 0; k < n.n_children; ++k) {
      const LobeInterface& ci = node_if[c[k]];
      if (r.ior.is_black() && !ci.ior.is_black()) r.ior = ci.ior;  // the upper-most interface wins
      r.roughness = fmax_(r.roughness, ci.roughness);
      if (n.op == LayerOp::Coat || n.op == LayerOp::Add) break;  // seen from above: the top only
    }
    if (n.op == LayerOp::Coat && r.ior.is_black()) r.ior = node_if[c[1]].ior;
    node_if[i] = r;
  }
  LayerAbove above[kMaxLayerNodes];
  const int root = p.n_nodes - 1;
  above[root] = LayerAbove{};
  for (int i = root; i >= 0; --i) {
    const LayerNode& n = p.nodes[i];
    if (n.op == LayerOp::Lobe) {
      lobe_above[n.lobe] = above[i];
      continue;
    }
    const uint16_t* c = p.children + n.first_child;
    for (int k = 0; k < n.n_children; ++k) above[c[k]] = above[i];
    if (n.op == LayerOp::Coat || n.op == LayerOp::Add) {
      const LobeInterface& top = node_if[c[0]];
      if (!top.ior.is_black()) above[c[1]].ior = top.ior;
      above[c[1]].roughness = fmax_(above[i].roughness, top.roughness);
    }
  }
}

}  // namespace kauri
