// Host construction of the light tree (see light_tree.h).
#include "kauri/light/light_tree.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "kauri/light/light.h"

namespace kauri {
namespace {

/// A cone of directions: axis and half-angle θ (θ ≥ π: every direction).
struct Cone {
  Vec3 axis{0, 0, 1};
  Float theta = kPi;
};

/// Smallest cone (of this construction) holding both: the classic merge of bounding
/// cones, rotating the wider one's axis towards the other's by half the excess.
Cone merge(Cone a, Cone b) {
  if (a.theta >= kPi || b.theta >= kPi) return {a.axis, kPi};
  if (b.theta > a.theta) std::swap(a, b);
  const Float theta_d = safe_acos(dot(a.axis, b.axis));
  if (theta_d + b.theta <= a.theta) return a;
  const Float theta_o = (a.theta + theta_d + b.theta) / 2;
  if (theta_o >= kPi) return {a.axis, kPi};
  const Vec3 k = cross(a.axis, b.axis);
  if (length_squared(k) < 1e-12f) return {a.axis, kPi};  // opposite axes
  const Vec3 kn = normalize(k);
  const Float theta_r = theta_o - a.theta;  // a.axis ⟂ kn: Rodrigues' rotation without the k(k·v) term
  return {normalize(a.axis * std::cos(theta_r) + cross(kn, a.axis) * std::sin(theta_r)), theta_o};
}

/// Bounds and normal cone of one light.
void light_extent(const Light& l, Point3* lo, Point3* hi, Cone* cone) {
  switch (l.type) {
    case LightType::Triangle:
      *lo = vmin(l.p0, vmin(l.p1, l.p2));
      *hi = vmax(l.p0, vmax(l.p1, l.p2));
      *cone = l.two_sided ? Cone{l.n, kPi} : Cone{l.n, 0};
      return;
    case LightType::Disk:
    case LightType::Sphere: {
      const Vec3 r{l.radius, l.radius, l.radius};
      *lo = l.p0 - r;
      *hi = l.p0 + r;
      *cone = (l.type == LightType::Disk && !l.two_sided) ? Cone{l.n, 0} : Cone{l.n, kPi};
      return;
    }
    default:  // point and spot lights: a point, emitting anywhere (a spot's cone is not used)
      *lo = *hi = l.p0;
      *cone = Cone{l.n, kPi};
  }
}

/// What a subtree offers its parent: bounds, cone, power, and where it lives.
struct Summary {
  Point3 lo, hi;
  Cone cone;
  Float power = 0;
  int child = 0;  // ≥ 0: its node; < 0: −1 − light
};

struct Builder {
  const std::vector<Light>& lights;
  const std::vector<Float>& power;
  std::vector<int> order;  // lights of the tree, permuted by the splits
  std::vector<Point3> centre;
  LightTreeStorage out;

  Summary build(int begin, int end, int depth, uint32_t trail) {
    if (depth >= kLightTreeMaxDepth)
      throw std::runtime_error("light tree: deeper than its 32-bit trails allow (" +
                               std::to_string(kLightTreeMaxDepth) + " levels)");
    Summary s;
    if (end - begin == 1) {
      const int li = order[size_t(begin)];
      light_extent(lights[size_t(li)], &s.lo, &s.hi, &s.cone);
      s.power = power[size_t(li)];
      s.child = -1 - li;
      out.trail[size_t(li)] = trail;
      return s;
    }
    // log2(arity) levels of median splits (widest axis of the light centres) give up to
    // kLightTreeArity groups, the node's lanes: bounds[k] .. bounds[k + 1].
    int bounds[kLightTreeArity + 1] = {begin, end};
    int n = 1;
    for (int groups = 1; groups < kLightTreeArity; groups *= 2) {
      int next[kLightTreeArity + 1];
      int m = 0;
      for (int k = 0; k < n; ++k) {
        next[m++] = bounds[k];
        if (bounds[k + 1] - bounds[k] >= 2) next[m++] = split(bounds[k], bounds[k + 1]);
      }
      next[m] = end;
      std::copy(next, next + m + 1, bounds);
      n = m;
    }
    const int node = int(out.nodes.size());
    out.nodes.emplace_back();
    LightTreeNode lanes{};
    for (int k = 0; k < kLightTreeArity; ++k) lanes.cos_o[k] = -1;
    for (int k = 0; k < n; ++k) {
      const Summary c =
          build(bounds[k], bounds[k + 1], depth + 1, trail | (uint32_t(k) << (kLightTreeTrailBits * depth)));
      set_lane(&lanes, k, c);
      s.lo = k == 0 ? c.lo : vmin(s.lo, c.lo);
      s.hi = k == 0 ? c.hi : vmax(s.hi, c.hi);
      s.cone = k == 0 ? c.cone : merge(s.cone, c.cone);
      s.power += c.power;
    }
    for (int k = 0; k < n; ++k) lanes.power_share[k] = lanes.power[k] / s.power;
    for (int k = 1; k < kLightTreeArity; ++k)
      lanes.power_share_before[k] = lanes.power_share_before[k - 1] + lanes.power_share[k - 1];
    out.nodes[size_t(node)] = lanes;  // after the recursion: emplace_back may have moved it
    s.child = node;
    return s;
  }
  static void set_lane(LightTreeNode* n, int k, const Summary& c) {
    const Point3 centre = (c.lo + c.hi) * 0.5f;
    n->cx[k] = centre.x;
    n->cy[k] = centre.y;
    n->cz[k] = centre.z;
    n->radius2[k] = std::max(length_squared(c.hi - c.lo) * 0.25f, Float(1e-12f));
    n->radius[k] = std::sqrt(n->radius2[k]);
    n->ax[k] = c.cone.axis.x;
    n->ay[k] = c.cone.axis.y;
    n->az[k] = c.cone.axis.z;
    const bool any = c.cone.theta >= kPi;
    n->cos_o[k] = any ? Float(-1) : std::cos(c.cone.theta);
    n->sin_o[k] = any ? Float(0) : std::sin(c.cone.theta);
    n->power[k] = c.power;
    n->child[k] = c.child;
  }
  /// Median split of order[begin, end) along the widest axis of the light centres.
  int split(int begin, int end) {
    Point3 clo = centre[size_t(order[size_t(begin)])], chi = clo;
    for (int i = begin; i < end; ++i) {
      clo = vmin(clo, centre[size_t(order[size_t(i)])]);
      chi = vmax(chi, centre[size_t(order[size_t(i)])]);
    }
    const Vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const int mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](int a, int b) { return centre[size_t(a)][axis] < centre[size_t(b)][axis]; });
    return mid;
  }
};

}  // namespace

LightTreeStorage build_light_tree(const std::vector<Light>& lights, const std::vector<Float>& power) {
  Builder b{lights, power, {}, {}, {}};
  b.out.trail.assign(lights.size(), 0);
  b.centre.resize(lights.size());
  for (size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].is_infinite() || !(power[i] > 0)) continue;
    Point3 lo, hi;
    Cone cone;
    light_extent(lights[i], &lo, &hi, &cone);
    b.centre[i] = (lo + hi) * 0.5f;
    b.order.push_back(int(i));
  }
  if (int(b.order.size()) < kLightTreeMinLights) return std::move(b.out);  // power selection
  b.build(0, int(b.order.size()), 0, 0);
  return std::move(b.out);
}

}  // namespace kauri
