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
  int child = -1;         // internal: first child (the second is child + 1); leaf: −1 − light
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

/// Probability of descending into the first child of `node` at p.
KAURI_HOST_DEVICE inline Float light_tree_first_child_prob(const LightTreeNode* nodes, const LightTreeNode& node,
                                                           Point3 p) {
  const LightTreeNode& a = nodes[node.child];
  const LightTreeNode& b = nodes[node.child + 1];
  const Float pa = a.power / (a.power + b.power);
  const Float ia = light_tree_importance(a, p), ib = light_tree_importance(b, p);
  const Float ta = ia + ib > 0 ? ia / (ia + ib) : pa;
  return (1 - kLightTreePowerShare) * ta + kLightTreePowerShare * pa;
}

struct LightTreeView {
  const LightTreeNode* nodes = nullptr;  // nodes[0] is the root
  const uint32_t* trail = nullptr;       // per light: bit k = 1 if the k-th step takes the second child
  int n_nodes = 0;

  /// A finite light chosen at p; *pmf its probability (0 if the tree has no power).
  KAURI_HOST_DEVICE int sample(Float u, Point3 p, Float* pmf) const {
    *pmf = 0;
    if (n_nodes == 0 || !(nodes[0].power > 0)) return -1;
    // u is not rescaled at each step (a division on the critical path): the interval
    // [lo, hi) of u that reaches node i is split instead, and the step is branch-free
    // (the choice is a coin flip the branch predictor cannot learn).
    Float prob = 1, lo = 0, hi = 1;
    int i = 0;
    while (nodes[i].child >= 0) {
      const Float pa = light_tree_first_child_prob(nodes, nodes[i], p);
      const Float split = lo + pa * (hi - lo);
      const bool second = !(u < split);
      prob *= second ? 1 - pa : pa;
      lo = second ? split : lo;
      hi = second ? hi : split;
      i = nodes[i].child + (second ? 1 : 0);
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
    for (int k = 0; nodes[i].child >= 0; ++k) {
      const Float pa = light_tree_first_child_prob(nodes, nodes[i], p);
      const bool second = (bits >> k) & 1u;
      prob *= second ? 1 - pa : pa;
      i = nodes[i].child + (second ? 1 : 0);
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
