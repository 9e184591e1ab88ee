// Light tree: chooses among a scene's finite lights (area, point, spot) in proportion to
// an estimate of what each contributes at the shading point, instead of in proportion to
// power alone. An 8-wide tree over the lights stores, per child of a node, the bounds of
// its lights' extents, a cone bounding their emission normals and their total power; NEE
// descends from the root choosing a child with probability ∝ its importance at the point (Conty
// Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting",
// §4, without the splitting). The importance bound is (their eq. 3)
//     I = Φ cos θ' cos θ_i' / d²,   θ' = max(0, θ − θ_o − θ_u),   θ_i' = max(0, θ_i − θ_u),
// with d the distance from the point to the node's centre, θ the angle between the cone
// axis and the direction from the centre to the point, θ_o the cone's spread and θ_u the
// angle the node's bounding sphere subtends (so I bounds every light in the node), and
// I = 0 beyond θ' ≥ π/2 (one-sided emitters face away). θ_i is the angle between the
// receiver's shading normal n and the direction to the centre, taken on whichever side
// of the surface the centre lies (|cos θ_i|), so the bound holds for transmission too;
// lights near the surface's horizon contribute the cosine's little. A zero n (no surface)
// drops the receiver's factor.
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

#include "kauri/core/lanes.h"
#include "kauri/core/math.h"

#define KAURI_LIGHT_TREE_AVX2 KAURI_LANES_AVX2

namespace kauri {

/// Children per node. Eight, not two: a node's eight bounds are one 8-wide vector
/// operation (AVX2), and the tree is a third as deep (288 lights: 3 levels instead of 9);
/// each choice weighs the bounds of eight smaller clusters, which a binary tree reaches
/// only two levels further down. The steps after the bounds (their sum, the lanes'
/// probabilities, the choice of lane) are written in AVX2 where the compiler has it: GCC 12
/// leaves them scalar, and at 8 lanes they then cost what the saved levels gain.
inline constexpr int kLightTreeArity = 8;
/// Bits per level of a light's trail (the lane taken), and the depth 32-bit trails allow.
inline constexpr int kLightTreeTrailBits = 3;
inline constexpr int kLightTreeMaxDepth = 32 / kLightTreeTrailBits;
static_assert((1 << kLightTreeTrailBits) == kLightTreeArity, "a trail step names one lane");
/// Share of each choice that follows power alone (the defensive mixture above).
inline constexpr Float kLightTreePowerShare = 0.1f;
/// Fewer finite lights than this are chosen by power: a tree of a few lights costs more
/// per estimate (an importance bound per child and level) than it removes in variance
/// (a quad light is two triangles with the same bounds, which a tree cannot tell apart).
inline constexpr int kLightTreeMinLights = 16;

/// The (up to) kLightTreeArity children of one inner node, lane by lane (structure of
/// arrays), so that their importance bounds are computed as one vector operation.
/// Per lane: the bounding sphere of the child's lights, the cone bounding their emission
/// normals (cos θ_o = −1: any direction: points, spheres, two-sided lights) and their power.
struct LightTreeNode {
  Float cx[kLightTreeArity], cy[kLightTreeArity], cz[kLightTreeArity];
  Float radius[kLightTreeArity], radius2[kLightTreeArity];  // radius2 ≥ 1e-12 (points, too)
  Float ax[kLightTreeArity], ay[kLightTreeArity], az[kLightTreeArity];
  Float cos_o[kLightTreeArity], sin_o[kLightTreeArity];
  Float power[kLightTreeArity];        // 0 in unused lanes
  Float power_share[kLightTreeArity];  // power[k] / Σ power (the defensive mixture's part)
  Float power_share_before[kLightTreeArity];  // Σ_(j<k) power_share[j] (the descent's edges)
  int child[kLightTreeArity];          // ≥ 0: the node of that child's children; < 0: −1 − light
};

/// I_k = Φ cos θ' cos θ_i' / d² for every lane k of `node` at point p with shading normal
/// ns (see the header; ns = 0: no receiver factor), branch-free so that the compiler
/// evaluates the lanes side by side.
KAURI_HOST_DEVICE inline void light_tree_importance(const LightTreeNode& n, Point3 p, Normal3 ns,
                                                    Float imp[kLightTreeArity]) {
  const Float has_normal = Float(int(ns.x != 0) | int(ns.y != 0) | int(ns.z != 0));
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
    // The receiver: θ_i' = max(0, θ_i − θ_u) likewise (1 inside the sphere or within θ_u).
    const Float cos_i = fmin_(std::fabs(ns.x * vx + ns.y * vy + ns.z * vz) * inv_d, Float(1));
    const Float sin_i = std::sqrt(fmax_(1 - cos_i * cos_i, Float(0)));
    const Float receiver = has_normal * Float(int(d2 > r2) & int(cos_i < cos_u));
    const Float cos_ip = receiver * fmax_(cos_i * cos_u + sin_i * sin_u, Float(0)) + (1 - receiver);
    imp[k] = n.power[k] * cos_p * cos_ip * inv_d2;  // unused lanes have power 0
  }
}

/// Probabilities of descending into each lane of `node` given the lanes' bounds `imp`:
/// (1 − s) I_k / Σ I + s Φ_k / Σ Φ with s = kLightTreePowerShare, or Φ_k / Σ Φ where every
/// bound is 0 (zero in unused lanes). The lane-by-lane definition, which the vector path
/// below matches up to rounding and its estimated bound (tests/cpp/test_light_tree.cpp).
KAURI_HOST_DEVICE inline void light_tree_probs_scalar(const LightTreeNode& node, const Float imp[kLightTreeArity],
                                                      Float prob[kLightTreeArity]) {
  Float imp_sum = 0;
  for (int k = 0; k < kLightTreeArity; ++k) imp_sum += imp[k];
  const Float a = imp_sum > 0 ? (1 - kLightTreePowerShare) / imp_sum : Float(0);
  const Float b = imp_sum > 0 ? kLightTreePowerShare : Float(1);
  for (int k = 0; k < kLightTreeArity; ++k) prob[k] = imp[k] * a + node.power_share[k] * b;
}

#if KAURI_LIGHT_TREE_AVX2
static_assert(kLightTreeArity == 8, "the AVX2 steps hold a node's lanes in one 8-float register");
#endif

#if KAURI_LIGHT_TREE_AVX2
namespace light_tree_detail {
using lanes::F32x8;
inline F32x8 load8(const Float* a) {
  F32x8 v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
inline F32x8 max8(F32x8 a, F32x8 b) { return _mm256_max_ps(a, b); }
/// √y for y ≥ 0 from the reciprocal square root estimate (rel. error ≤ 1.5 · 2⁻¹²).
inline F32x8 sqrt_estimate(F32x8 y) { return y * _mm256_rsqrt_ps(max8(y, F32x8{} + 1e-30f)); }
}  // namespace light_tree_detail

/// light_tree_importance over the 8 lanes with the reciprocal square root estimate (~12
/// bits) for 1/d and the sines: the bound only shapes the proposal, sample() and pmf() both
/// read this one function, and its dependency chain (the three reciprocal square roots side
/// by side, then a dozen multiplications and comparisons),
/// repeated at every level, is what a many-light NEE waits on. The estimate's
/// bits are the CPU's own (they differ between vendors), so the hangar-like scenes' images
/// are reproducible per CPU model, not across them; any positive bound keeps the estimate
/// unbiased.
inline void light_tree_importance_lanes(const LightTreeNode& n, Point3 p, Normal3 ns, Float imp[kLightTreeArity]) {
  using namespace light_tree_detail;
  const F32x8 zero{}, one = zero + 1;
  const F32x8 vx = p.x - load8(n.cx), vy = p.y - load8(n.cy), vz = p.z - load8(n.cz);
  const F32x8 d2 = vx * vx + vy * vy + vz * vz, r2 = load8(n.radius2);
  const F32x8 dd = max8(d2, r2);  // d² (clamped as in the definition)
  const F32x8 inv_d = _mm256_rsqrt_ps(dd);
  // The sines and cosines as lengths times 1/d: d cos θ = a·v, d sin θ = √(d² − (a·v)²) and
  // d cos θ_u = √(d² − r²) start from d² and a·v, beside the reciprocal square root,
  // instead of after it (each level of the descent waits on this chain).
  const F32x8 d_cos_theta = load8(n.ax) * vx + load8(n.ay) * vy + load8(n.az) * vz;
  const F32x8 cos_theta = d_cos_theta * inv_d;
  const F32x8 sin_theta = sqrt_estimate(max8(dd - d_cos_theta * d_cos_theta, zero)) * inv_d;
  const F32x8 cos_o = load8(n.cos_o), sin_o = load8(n.sin_o);
  const F32x8 sin_u = load8(n.radius) * inv_d;
  const F32x8 cos_u = sqrt_estimate(max8(dd - r2, zero)) * inv_d;
  const F32x8 cos_phi = cos_o * cos_u - sin_o * sin_u, sin_phi = sin_o * cos_u + cos_o * sin_u;
  const auto bounded = (d2 > r2) & (cos_o > -1) & (sin_phi >= 0) & (cos_phi > -1) & (cos_theta < cos_phi);
  const F32x8 cos_p = bounded ? max8(cos_theta * cos_phi + sin_theta * sin_phi, zero) : one;
  const F32x8 d_cos_i = ns.x * vx + ns.y * vy + ns.z * vz;  // ± d cos θ_i
  const F32x8 cos_i = max8(d_cos_i, -d_cos_i) * inv_d;
  const F32x8 sin_i = sqrt_estimate(max8(dd - d_cos_i * d_cos_i, zero)) * inv_d;
  const bool has_normal = ns.x != 0 || ns.y != 0 || ns.z != 0;
  const auto receiver = (d2 > r2) & (cos_i < cos_u) & (zero + Float(has_normal) > 0);
  const F32x8 cos_ip = receiver ? max8(cos_i * cos_u + sin_i * sin_u, zero) : one;
  const F32x8 out = (cos_p * cos_ip) * (load8(n.power) * (inv_d * inv_d));
  __builtin_memcpy(imp, &out, sizeof out);
}

/// The mixture's weights of a node's bounds `i` and power shares: prob_k = i_k a + share_k b
/// (light_tree_probs_scalar's a and b, in every lane).
struct LightTreeMix {
  __m256 a, b;
};
/// From the bounds' sum S in every lane (S = 0: the power shares alone).
inline LightTreeMix light_tree_mix_of_sum(__m256 sum) {
  const __m256 bounded = _mm256_cmp_ps(sum, _mm256_setzero_ps(), _CMP_GT_OQ);
  return {_mm256_and_ps(bounded, _mm256_div_ps(_mm256_set1_ps(1 - kLightTreePowerShare), sum)),
          _mm256_blendv_ps(_mm256_set1_ps(1), _mm256_set1_ps(kLightTreePowerShare), bounded)};
}
inline LightTreeMix light_tree_mix_lanes(__m256 i) { return light_tree_mix_of_sum(lanes::lane_sum(i)); }
inline __m256 light_tree_probs_lanes(const LightTreeNode& node, __m256 i, LightTreeMix m) {
  return _mm256_fmadd_ps(i, m.a, _mm256_mul_ps(_mm256_loadu_ps(node.power_share), m.b));
}
inline __m256 light_tree_importance_vector(const LightTreeNode& node, Point3 p, Normal3 ns) {
  alignas(32) Float imp[kLightTreeArity];
  light_tree_importance_lanes(node, p, ns, imp);
  return _mm256_load_ps(imp);
}

/// light_tree_child_probs as one vector.
inline __m256 light_tree_child_probs_lanes(const LightTreeNode& node, Point3 p, Normal3 ns) {
  const __m256 i = light_tree_importance_vector(node, p, ns);
  return light_tree_probs_lanes(node, i, light_tree_mix_lanes(i));
}
#endif

/// Probabilities of descending into each lane of `node` at p, shading normal ns (zero in
/// unused lanes).
KAURI_HOST_DEVICE inline void light_tree_child_probs(const LightTreeNode& node, Point3 p, Normal3 ns,
                                                     Float prob[kLightTreeArity]) {
#if KAURI_LIGHT_TREE_AVX2
  _mm256_storeu_ps(prob, light_tree_child_probs_lanes(node, p, ns));
#else
  alignas(32) Float imp[kLightTreeArity];
  light_tree_importance(node, p, ns, imp);
  light_tree_probs_scalar(node, imp, prob);
#endif
}

/// The lane of a node whose share [lo + width·cdf_k, lo + width·cdf_(k+1)) of the interval
/// [lo, lo + width) holds u, cdf_k = Σ_(j<k) pk[j]: the last lane with probability whose
/// share starts at or below u (lane 0 when none does). *start gets the share's start. The
/// lane-by-lane definition; the vector step below (light_tree_step_lanes) sums in a scan's
/// order, so its shares' edges match up to rounding.
KAURI_HOST_DEVICE inline int light_tree_choose_scalar(const Float pk[kLightTreeArity], Float u, Float lo, Float width,
                                                      Float* start) {
  int chosen = 0;
  Float acc = 0;
  *start = lo;
  for (int k = 1; k < kLightTreeArity; ++k) {
    acc += pk[k - 1];
    const Float edge = lo + acc * width;
    if (pk[k] > 0 && !(u < edge)) {
      chosen = k;
      *start = edge;
    }
  }
  return chosen;
}

#if KAURI_LIGHT_TREE_AVX2
/// Exclusive prefix sums of the 8 lanes, Σ_(j<k) v_j in lane k, by a scan in the register:
/// two shifts within each half, then the low half's total carried into the high half. It
/// adds in another order than a lane-by-lane loop (sums may differ by rounding), and spares
/// the sequential chain of eight additions and the trip through memory that a vector load
/// of eight scalar stores cannot forward.
inline __m256 light_tree_exclusive_sums(__m256 v) {
  // Each 128-bit half shifted up by one, then two lanes (zeros shifted in): inclusive sums
  // within each half.
  __m256 incl = _mm256_add_ps(v, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(v), 4)));
  incl = _mm256_add_ps(incl, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(incl), 8)));
  const __m256 low_total = _mm256_permute2f128_ps(_mm256_permute_ps(incl, 0xff), incl, 0x08);  // (0 | Σ low)
  incl = _mm256_add_ps(incl, low_total);
  return _mm256_blend_ps(_mm256_permutevar8x32_ps(incl, _mm256_setr_epi32(0, 0, 1, 2, 3, 4, 5, 6)),
                         _mm256_setzero_ps(), 1);
}

/// The highest lane set in `pass` (lane 0 when none: the fallback), by a movemask.
inline int light_tree_highest_lane(__m256 pass) {
  const unsigned mask = unsigned(_mm256_movemask_ps(pass)) | 1u;
  return 31 - __builtin_clz(mask);
}

/// Lane k of v, without a branch on k.
inline Float light_tree_lane(__m256 v, int k) {
  return _mm256_cvtss_f32(_mm256_permutevar8x32_ps(v, _mm256_set1_epi32(k)));
}

/// One level of the descent from the node's bounds `i` (the form sample() uses): the lane
/// light_tree_choose_scalar takes on light_tree_probs_lanes. Its share of [lo, lo + width)
/// starts at lo + width (a CI_k + b CP_k), CI the exclusive sums of the bounds, CP the
/// node's stored ones of the power shares, a = (1 − s) / S and b = s (S = Σ I > 0, s the
/// power share of the mixture). The choice compares those starts with u multiplied through
/// by S,
///     width ((1 − s) CI_k + s CP_k S) ≤ (u − lo) S,
/// so that it waits on the sum but not on the division by it: each level of the descent
/// is a dependency chain (bounds, sum, choice, the chosen child's node), and the division
/// and the probabilities then run beside the next level's bounds. Where S = 0 the shares
/// are the power shares alone: width CP_k ≤ u − lo, known before the bounds. A lane without
/// power has probability 0 and is never taken. The starts match the scan of the
/// probabilities up to rounding; *start and *taken (light_tree_probs_lanes' lane, bit for
/// bit as pmf() computes it) are the chosen lane's.
inline int light_tree_step_lanes(const LightTreeNode& node, __m256 i, Float u, Float lo, Float width, Float* start,
                                 Float* taken) {
  const __m256 zero = _mm256_setzero_ps(), share_before = _mm256_loadu_ps(node.power_share_before);
  const __m256 has_power = _mm256_cmp_ps(_mm256_loadu_ps(node.power_share), zero, _CMP_GT_OQ);
  const __m256 u_lo = _mm256_set1_ps(u - lo);
  // Off the chain: the power-only choice, and width times each term's weight.
  const __m256 pass_power = _mm256_cmp_ps(_mm256_mul_ps(_mm256_set1_ps(width), share_before), u_lo, _CMP_LE_OQ);
  const __m256 w_bounds = _mm256_set1_ps(width * (1 - kLightTreePowerShare));
  const __m256 w_power = _mm256_mul_ps(_mm256_set1_ps(width * kLightTreePowerShare), share_before);
  // The chain: the bounds' sum and exclusive sums, then one comparison.
  const __m256 ci = light_tree_exclusive_sums(i);
  const __m256 sum = lanes::lane_sum(i);
  const __m256 bounded = _mm256_cmp_ps(sum, zero, _CMP_GT_OQ);
  const __m256 lhs = _mm256_fmadd_ps(w_bounds, ci, _mm256_mul_ps(w_power, sum));
  const __m256 pass_bounds = _mm256_cmp_ps(lhs, _mm256_mul_ps(u_lo, sum), _CMP_LE_OQ);
  const int chosen = light_tree_highest_lane(_mm256_and_ps(_mm256_blendv_ps(pass_power, pass_bounds, bounded), has_power));
  // Beside the next level: the probabilities and the chosen share's start.
  const LightTreeMix m = light_tree_mix_of_sum(sum);
  const __m256 before = _mm256_fmadd_ps(ci, m.a, _mm256_mul_ps(share_before, m.b));
  *start = light_tree_lane(_mm256_fmadd_ps(before, _mm256_set1_ps(width), _mm256_set1_ps(lo)), chosen);
  *taken = light_tree_lane(light_tree_probs_lanes(node, i, m), chosen);
  return chosen;
}
#endif

/// Where one root-to-leaf descent of LightTreeView::sample stands: the node whose children
/// it chooses among next, the product of its choices' probabilities, and the interval
/// [lo, lo + width) of u that reaches the node.
struct LightTreeDescent {
  int node = 0;
  Float prob = 1, lo = 0, width = 1;
};

/// Most points LightTreeView::sample_many takes at once (the path lanes' width).
inline constexpr int kLightTreeBatch = 16;

struct LightTreeView {
  const LightTreeNode* nodes = nullptr;  // nodes[0] holds the root's children
  const uint32_t* trail = nullptr;       // per light: kLightTreeTrailBits per level, the lane taken
  int n_nodes = 0;

  /// One level of descent `d` for u at p, shading normal ns: the light (≥ 0) where the
  /// chosen child is a leaf, else −1 with d at the chosen child. u is not rescaled at each
  /// step (a division on the critical path): the interval of u that reaches the node is
  /// split instead, without branches (the choice is a draw the branch predictor cannot learn).
  KAURI_HOST_DEVICE int step(LightTreeDescent* d, Float u, Point3 p, Normal3 ns) const {
    const LightTreeNode& n = nodes[d->node];
    Float start, taken;
#if KAURI_LIGHT_TREE_AVX2
    const int chosen = light_tree_step_lanes(n, light_tree_importance_vector(n, p, ns), u, d->lo, d->width, &start, &taken);
#else
    Float pk[kLightTreeArity];
    light_tree_child_probs(n, p, ns, pk);
    const int chosen = light_tree_choose_scalar(pk, u, d->lo, d->width, &start);
    taken = pk[chosen];
#endif
    d->prob *= taken;
    d->lo = start;
    d->width *= taken;
    const int c = n.child[chosen];
    if (c < 0) return -1 - c;
    d->node = c;
    return -1;
  }
  /// u rescaled to [0, 1) within the leaf's interval (sample()'s u_remapped).
  KAURI_HOST_DEVICE static Float remapped(const LightTreeDescent& d, Float u) {
    return d.width > 0 ? fmin_(fmax_((u - d.lo) / d.width, Float(0)), kOneMinusEpsilon) : Float(0);
  }

  /// A finite light chosen at p, shading normal ns (zero: no surface); *pmf its
  /// probability (0 if the tree has no power).
  KAURI_HOST_DEVICE int sample(Float u, Point3 p, Normal3 ns, Float* pmf, Float* u_remapped = nullptr) const {
    *pmf = 0;
    if (n_nodes == 0) return -1;
    LightTreeDescent d;
    for (;;) {
      const int light = step(&d, u, p, ns);
      if (light < 0) continue;
      *pmf = d.prob;
      if (u_remapped) *u_remapped = remapped(d, u);
      return light;
    }
  }
  /// sample() for n ≤ kLightTreeBatch points at once, point i's light in light[i], its
  /// probability in pmf[i] and its remapped u in u_remapped[i]: the same choices, bit for
  /// bit, with the descents interleaved level by level. One descent is a chain of dependent
  /// steps (the bounds, their sum, the choice, the chosen child's node), each waiting on
  /// the last; the points' chains are independent, so the CPU runs several side by side.
  KAURI_HOST_DEVICE void sample_many(int n, const Float* u, const Point3* p, const Normal3* ns, int* light, Float* pmf,
                                     Float* u_remapped) const {
    LightTreeDescent d[kLightTreeBatch];
    int unfinished[kLightTreeBatch];  // the points whose descent goes on, first `left` of them
    for (int i = 0; i < n; ++i) {
      light[i] = -1, pmf[i] = 0, u_remapped[i] = 0;
      d[i] = LightTreeDescent{};
      unfinished[i] = i;
    }
    if (n_nodes == 0) return;
    for (int left = n; left > 0;) {  // each pass: one level of every unfinished descent
      int next = 0;
      for (int j = 0; j < left; ++j) {
        const int i = unfinished[j];
        const int l = step(&d[i], u[i], p[i], ns[i]);
        if (l < 0) {
          unfinished[next++] = i;
          continue;
        }
        light[i] = l;
        pmf[i] = d[i].prob;
        u_remapped[i] = remapped(d[i], u[i]);
      }
      left = next;
    }
  }
  /// Probability that sample() at p, shading normal ns, returns `light` (a finite light of
  /// the tree).
  KAURI_HOST_DEVICE Float pmf(int light, Point3 p, Normal3 ns) const {
    if (n_nodes == 0) return 0;
    const uint32_t bits = trail[light];
    Float prob = 1;
    int i = 0;
    for (int level = 0; level < kLightTreeMaxDepth; ++level) {
      const LightTreeNode& n = nodes[i];
      Float pk[kLightTreeArity];
      light_tree_child_probs(n, p, ns, pk);
      const int k = int((bits >> (kLightTreeTrailBits * level)) & uint32_t(kLightTreeArity - 1));
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
