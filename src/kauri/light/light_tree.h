// Light tree: chooses among a scene's finite lights (area, point, spot) in proportion to
// an estimate of what each contributes at the shading point, instead of in proportion to
// power alone. A 4-wide tree over the lights stores, per child of a node, the bounds of
// its lights' extents, a cone bounding their emission normals and their total power; NEE
// descends from the root choosing a child with probability ∝ its importance at the point (Conty
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
// pmf(light | p) retraces the same choices along the light's root-to-leaf trail, so
// next-event estimation and the MIS weight of an emitter hit see the same density.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "kauri/core/math.h"

namespace kauri {

/// Children per node. Four, not two: a node's four bounds are computed as one 4-wide
/// vector operation, and the tree is half as deep (288 lights: 5 levels instead of 9).
inline constexpr int kLightTreeArity = 4;
/// Share of each choice that follows power alone (the defensive mixture above).
inline constexpr Float kLightTreePowerShare = 0.1f;
/// Fewer finite lights than this are chosen by power: a tree of a few lights costs more
/// per estimate (an importance bound per child and level) than it removes in variance
/// (a quad light is two triangles with the same bounds, which a tree cannot tell apart).
inline constexpr int kLightTreeMinLights = 16;

/// The (up to) kLightTreeArity children of one inner node, lane by lane (structure of
/// arrays), so that their four importance bounds are computed as one vector operation.
/// Per lane: the bounding sphere of the child's lights, the cone bounding their emission
/// normals (cos θ_o = −1: any direction: points, spheres, two-sided lights) and their power.
struct LightTreeNode {
  Float cx[kLightTreeArity], cy[kLightTreeArity], cz[kLightTreeArity];
  Float radius[kLightTreeArity], radius2[kLightTreeArity];  // radius2 ≥ 1e-12 (points, too)
  Float ax[kLightTreeArity], ay[kLightTreeArity], az[kLightTreeArity];
  Float cos_o[kLightTreeArity], sin_o[kLightTreeArity];
  Float power[kLightTreeArity];  // 0 in unused lanes
  int child[kLightTreeArity];    // ≥ 0: the node of that child's children; < 0: −1 − light
};

/// I_k = Φ cos θ' / d² for every lane k of `node` at point p (see the header), branch-free
/// so that the compiler evaluates the lanes side by side.
KAURI_HOST_DEVICE inline void light_tree_importance(const LightTreeNode& n, Point3 p, Float imp[kLightTreeArity]) {
  for (int k = 0; k < kLightTreeArity; ++k) {
    const Float vx = p.x - n.cx[k], vy = p.y - n.cy[k], vz = p.z - n.cz[k];
    const Float d2 = vx * vx + vy * vy + vz * vz, r2 = n.radius2[k];
    const Float inv_d2 = 1 / fmax_(d2, r2);  // r2 > 0 (the builder's floor)
    const Float inv_d = std::sqrt(inv_d2);
    const Float cos_theta = (n.ax[k] * vx + n.ay[k] * vy + n.az[k] * vz) * inv_d;  // |·| ≤ 1 up to rounding
    const Float sin_theta = std::sqrt(fmax_(1 - cos_theta * cos_theta, Float(0)));
    // θ' = max(0, θ − φ) with φ = θ_o + θ_u, by angle-sum identities (no inverse trig).
    const Float cos_o = n.cos_o[k], sin_o = n.sin_o[k];
    const Float sin_u = n.radius[k] * inv_d;  // ≤ 1 outside the sphere (inside, bounded is 0)
    const Float cos_u = std::sqrt(fmax_(1 - sin_u * sin_u, Float(0)));
    const Float cos_phi = cos_o * cos_u - sin_o * sin_u, sin_phi = sin_o * cos_u + cos_o * sin_u;
    // φ ≥ π (sin φ < 0), an any-direction cone, or θ ≤ φ: the bound allows every direction.
    // The conditions as an integer mask, not branches or selects: GCC then vectorises the
    // loop (with -fno-math-errno, which renderer.cpp is compiled with, for the sqrts).
    // Inside the bounding sphere (d² ≤ r²) every direction is possible, at distance r.
    const Float bounded = Float(int(d2 > r2) & int(cos_o > -1) & int(sin_phi >= 0) & int(cos_phi > -1) &
                                int(cos_theta < cos_phi));
    const Float cos_p =
        bounded * fmax_(cos_theta * cos_phi + sin_theta * sin_phi, Float(0)) + (1 - bounded);
    imp[k] = n.power[k] * cos_p * inv_d2;  // unused lanes have power 0
  }
}

/// Probabilities of descending into each lane of `node` at p (zero in unused lanes).
KAURI_HOST_DEVICE inline void light_tree_child_probs(const LightTreeNode& node, Point3 p,
                                                     Float prob[kLightTreeArity]) {
  Float imp[kLightTreeArity];
  light_tree_importance(node, p, imp);
  Float imp_sum = 0, pow_sum = 0;
  for (int k = 0; k < kLightTreeArity; ++k) {
    imp_sum += imp[k];
    pow_sum += node.power[k];
  }
  const Float inv_imp = imp_sum > 0 ? 1 / imp_sum : Float(0), inv_pow = 1 / pow_sum;
  for (int k = 0; k < kLightTreeArity; ++k) {
    const Float share = node.power[k] * inv_pow;
    prob[k] = (1 - kLightTreePowerShare) * (imp_sum > 0 ? imp[k] * inv_imp : share) + kLightTreePowerShare * share;
  }
}

struct LightTreeView {
  const LightTreeNode* nodes = nullptr;  // nodes[0] holds the root's children
  const uint32_t* trail = nullptr;       // per light: 2 bits per level, the lane taken
  int n_nodes = 0;

  /// A finite light chosen at p; *pmf its probability (0 if the tree has no power).
  KAURI_HOST_DEVICE int sample(Float u, Point3 p, Float* pmf, Float* u_remapped = nullptr) const {
    *pmf = 0;
    if (n_nodes == 0) return -1;
    // u is not rescaled at each step (a division on the critical path): the interval
    // [lo, lo + width) of u that reaches the node is split instead, without branches (the
    // choice is a draw the branch predictor cannot learn).
    Float prob = 1, lo = 0, width = 1;
    int i = 0;
    for (;;) {
      const LightTreeNode& n = nodes[i];
      Float pk[kLightTreeArity];
      light_tree_child_probs(n, p, pk);
      int chosen = 0;
      Float start = lo, taken = pk[0];
      for (int k = 1; k < kLightTreeArity; ++k) {
        const Float edge = start + taken * width;
        const bool beyond = pk[k] > 0 && !(u < edge);
        chosen = beyond ? k : chosen;
        start = beyond ? edge : start;
        taken = beyond ? pk[k] : taken;
      }
      prob *= taken;
      lo = start;
      width *= taken;
      if (n.child[chosen] < 0) {
        *pmf = prob;
        if (u_remapped) *u_remapped = width > 0 ? fmin_(fmax_((u - lo) / width, Float(0)), kOneMinusEpsilon) : Float(0);
        return -1 - n.child[chosen];
      }
      i = n.child[chosen];
    }
  }
  /// Probability that sample() at p returns `light` (a finite light of the tree).
  KAURI_HOST_DEVICE Float pmf(int light, Point3 p) const {
    if (n_nodes == 0) return 0;
    const uint32_t bits = trail[light];
    Float prob = 1;
    int i = 0;
    for (int level = 0; level < 16; ++level) {
      const LightTreeNode& n = nodes[i];
      Float pk[kLightTreeArity];
      light_tree_child_probs(n, p, pk);
      const int k = int((bits >> (2 * level)) & 3u);
      prob *= pk[k];
      if (n.child[k] < 0) return -1 - n.child[k] == light ? prob : 0;
      i = n.child[k];
    }
    return 0;
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
