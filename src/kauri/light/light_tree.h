// Light tree: chooses among a scene's finite lights (area, point, spot) in proportion to
// an estimate of what each contributes at the shading point, instead of in proportion to
// power alone. A binary tree over the lights stores, per node, the bounds of its lights'
// positions, a cone bounding their emission normals and their total power; NEE descends
// from the root choosing a child with probability ∝ its importance at the point (Conty
// Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting",
// §4, without the splitting). The importance bound is
//     I = Φ cos θ' / d²,   θ' = max(0, θ − θ_o − θ_u),
// with d the distance from the point to the node's centre, θ the angle between the cone
// axis and the direction from the centre to the point, θ_o the cone's spread and θ_u the
// angle the node's bounding sphere subtends (so I bounds every light in the node), and
// I = 0 beyond θ' ≥ π/2 (one-sided emitters face away).
//
// Each choice mixes in a fraction of the power ratio (a defensive mixture, Hesterberg
// 1995): every light with power keeps a nonzero probability wherever it is, so the
// estimate stays unbiased even where the bound is loose or zero by rounding.
//
// pmf(light | p) retraces the same choices along the light's root-to-leaf bit trail, so
// next-event estimation and the MIS weight of an emitter hit see the same density.
#pragma once

#include <cstdint>
#include <vector>

#include "kauri/core/math.h"

namespace kauri {

/// Children per node. Four, not two: a level's four bounds are independent (the core
/// computes them side by side) and the tree is half as deep, so a descent waits on half as
/// many dependent steps (288 lights: 5 levels instead of 9).
inline constexpr int kLightTreeArity = 4;
/// Share of each choice that follows power alone (the defensive mixture above).
inline constexpr Float kLightTreePowerShare = 0.1f;
/// Fewer finite lights than this are chosen by power: a tree of a few lights costs more
/// per estimate (an importance bound per child and level) than it removes in variance
/// (a quad light is two triangles with the same bounds, which a tree cannot tell apart).
inline constexpr int kLightTreeMinLights = 16;

struct LightTreeNode {
  Point3 centre;          // of the bounding sphere of the lights' extents
  Float radius = 0, radius2 = 0;  // its radius and radius²
  Vec3 axis;              // emission normals lie within θ_o of it
  Float cos_theta_o = -1, sin_theta_o = 0;  // cos −1: any direction (point, sphere, two-sided)
  Float power = 0;        // Σ Φ of the lights below
  int child = -1;         // internal: first child (the others follow it); leaf: −1 − light
  int n_children = 0;     // internal: 2 … kLightTreeArity
};

/// I = Φ cos θ' / d² of `node` at point p (see the header).
KAURI_HOST_DEVICE inline Float light_tree_importance(const LightTreeNode& node, Point3 p) {
  if (!(node.power > 0)) return 0;
  const Float r2 = node.radius2;
  const Vec3 v = p - node.centre;
  const Float d2 = length_squared(v);
  if (d2 <= r2) return node.power / fmax_(r2, Float(1e-12f));  // inside: every direction possible
  const Float inv_d2 = 1 / d2;
  if (node.cos_theta_o <= -1) return node.power * inv_d2;
  const Float inv_d = std::sqrt(inv_d2);
  const Float cos_theta = clamp(dot(node.axis, v) * inv_d, -1, 1);
  const Float sin_theta = safe_sqrt(1 - cos_theta * cos_theta);
  // θ' = max(0, θ − φ) with φ = θ_o + θ_u, by angle-sum identities (no inverse trig).
  const Float cos_o = node.cos_theta_o, sin_o = node.sin_theta_o;
  const Float sin_u = node.radius * inv_d, cos_u = safe_sqrt(1 - sin_u * sin_u);
  const Float cos_phi = cos_o * cos_u - sin_o * sin_u, sin_phi = sin_o * cos_u + cos_o * sin_u;
  Float cos_p = 1;  // φ ≥ π (sin φ < 0) or θ ≤ φ: the bound allows any direction
  if (sin_phi >= 0 && cos_phi > -1 && cos_theta < cos_phi) cos_p = cos_theta * cos_phi + sin_theta * sin_phi;
  if (cos_p <= 0) return 0;
  return node.power * cos_p * inv_d2;
}

/// Probabilities of descending into each child of `node` at p (kLightTreeArity entries,
/// zero past n_children).
KAURI_HOST_DEVICE inline void light_tree_child_probs(const LightTreeNode* nodes, const LightTreeNode& node, Point3 p,
                                                     Float prob[kLightTreeArity]) {
  Float imp[kLightTreeArity], phi[kLightTreeArity];
  Float imp_sum = 0, pow_sum = 0;
  for (int k = 0; k < kLightTreeArity; ++k) {
    const bool live = k < node.n_children;
    const LightTreeNode& c = nodes[node.child + (live ? k : 0)];
    imp[k] = live ? light_tree_importance(c, p) : Float(0);
    phi[k] = live ? c.power : Float(0);
    imp_sum += imp[k];
    pow_sum += phi[k];
  }
  const Float inv_imp = imp_sum > 0 ? 1 / imp_sum : Float(0), inv_pow = 1 / pow_sum;
  for (int k = 0; k < kLightTreeArity; ++k) {
    const Float share = phi[k] * inv_pow;
    prob[k] = (1 - kLightTreePowerShare) * (imp_sum > 0 ? imp[k] * inv_imp : share) + kLightTreePowerShare * share;
  }
}

struct LightTreeView {
  const LightTreeNode* nodes = nullptr;  // nodes[0] is the root
  const uint32_t* trail = nullptr;       // per light: 2 bits per level, the child taken
  int n_nodes = 0;

  /// A finite light chosen at p; *pmf its probability (0 if the tree has no power).
  KAURI_HOST_DEVICE int sample(Float u, Point3 p, Float* pmf) const {
    *pmf = 0;
    if (n_nodes == 0 || !(nodes[0].power > 0)) return -1;
    // u is not rescaled at each step (a division on the critical path): the interval
    // [lo, hi) of u that reaches node i is split instead, without branches (the choice is
    // a draw the branch predictor cannot learn).
    Float prob = 1, lo = 0;
    Float width = 1;
    int i = 0;
    while (nodes[i].child >= 0) {
      Float pk[kLightTreeArity];
      light_tree_child_probs(nodes, nodes[i], p, pk);
      int chosen = 0;
      Float start = lo, taken = pk[0];
      for (int k = 1; k < kLightTreeArity; ++k) {
        const Float edge = start + taken * width;
        const bool beyond = k < nodes[i].n_children && pk[k] > 0 && !(u < edge);
        chosen = beyond ? k : chosen;
        start = beyond ? edge : start;
        taken = beyond ? pk[k] : taken;
      }
      prob *= taken;
      lo = start;
      width *= taken;
      i = nodes[i].child + chosen;
    }
    *pmf = prob;
    return -1 - nodes[i].child;
  }
  /// Probability that sample() at p returns `light` (a finite light of the tree).
  KAURI_HOST_DEVICE Float pmf(int light, Point3 p) const {
    if (n_nodes == 0 || !(nodes[0].power > 0)) return 0;
    const uint32_t bits = trail[light];
    Float prob = 1;
    int i = 0;
    for (int level = 0; nodes[i].child >= 0; ++level) {
      Float pk[kLightTreeArity];
      light_tree_child_probs(nodes, nodes[i], p, pk);
      const int k = int((bits >> (2 * level)) & 3u);
      if (k >= nodes[i].n_children) return 0;
      prob *= pk[k];
      i = nodes[i].child + k;
    }
    return -1 - nodes[i].child == light ? prob : 0;
  }
};

// ---- host (light_tree.cpp) ----

struct Light;

/// Owns a tree's nodes and trails; view() is what render code reads.
struct LightTreeStorage {
  std::vector<LightTreeNode> nodes;
  std::vector<uint32_t> trail;  // one per light (0 for lights outside the tree)
  LightTreeView view() const { return {nodes.data(), trail.data(), int(nodes.size())}; }
  size_t bytes() const { return nodes.size() * sizeof(LightTreeNode) + trail.size() * sizeof(uint32_t); }
};

/// Tree over the finite lights with power[i] > 0 (median splits along the widest axis of
/// their centres; one light per leaf). Infinite lights and powerless ones stay outside.
LightTreeStorage build_light_tree(const std::vector<Light>& lights, const std::vector<Float>& power);

}  // namespace kauri
