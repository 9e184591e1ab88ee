// CPU ray queries through Embree 3 (two-level: root shapes plus instances of
// prototype groups). Host code; satisfies the `Accel` concept of path_tracer.h.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "kauri/geometry/shapes.h"

namespace kauri {

/// An analytic shape of the root group that the accelerator tests itself.
struct DirectShape {
  ShapeType type = ShapeType::Sphere;
  unsigned geom = 0;  // its geometry id (index in the root group), as Embree would report
  SphereShape sphere;
  DiskShape disk;
  bool intersect(const Ray& r, Float tmax, Float* t) const {
    return type == ShapeType::Sphere ? intersect_sphere(sphere, r, tmax, t) : intersect_disk(disk, r, tmax, t);
  }
};

class EmbreeAccel {
 public:
  /// A root group with at most this many spheres and disks tests them directly instead of
  /// giving them to Embree. Embree keeps one acceleration structure per primitive type and
  /// traverses each per ray: one sphere beside triangles halved its throughput (bench
  /// textured scene), while a few analytic tests cost a few dozen instructions.
  static constexpr size_t kMaxDirectShapes = 8;

  /// Whether `m`'s triangles come in pairs (a, b, c), (a, c, d), as the scene splits its
  /// quads (scene.cpp). Where every mesh of the root group is such, Embree gets them as
  /// quads (b, c, d, a), whose two triangles (b, c, a) and (d, a, c) are the pair's own,
  /// diagonal a–c included: Embree tests a quad's two triangles at once over a BVH of half
  /// the primitives. One-thread render time side by side (bench/ab_builds.py): textured
  /// room 0.89x, Cornell box 0.95x, hangar 1.07x (its 144 lamps, 4 to a leaf as quads
  /// rather than 2, are entered by more of the rays that pass between them). Not where
  /// some meshes are triangles: Embree keeps a BVH per primitive type and traverses each
  /// per ray (the Cornell box with its lamp as triangles beside quad walls gained nothing).
  /// Hits are reported as the triangle's (quad_hit), so nothing past the accelerator sees
  /// the quads.
  static bool quad_pairs(const MeshView& m);
  /// Per root geometry id: 1 where Embree holds the mesh as quads (its hits are mapped by
  /// quad_hit here; callers of intersect_lanes map them themselves).
  const std::vector<uint8_t>& root_quads() const { return root_quads_; }
  /// A hit (u, v) on the quad `prim` of a quad_pairs() mesh as the hit on its triangle
  /// 2·prim or 2·prim + 1 with that triangle's barycentrics. Embree's quad (v0 … v3)
  /// parameterises its first triangle (v0, v1, v3) as v0 + u(v1 − v0) + v(v3 − v0) and its
  /// second (v2, v3, v1), where u + v ≥ 1, as v2 + (1 − u)(v3 − v2) + (1 − v)(v1 − v2)
  /// (Embree 3 API, RTC_GEOMETRY_TYPE_QUAD); with (v0 … v3) = (b, c, d, a) these are
  /// triangle (a, b, c) at (1 − u − v, u) and triangle (a, c, d) at (1 − v, u + v − 1).
  static void quad_hit(Float u, Float v, unsigned* prim, Float* hu, Float* hv) {
    const bool second = u + v > 1;
    *prim = 2 * *prim + (second ? 1u : 0u);
    *hu = second ? 1 - v : 1 - u - v;
    *hv = second ? u + v - 1 : u;
  }

  EmbreeAccel();
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  /// Builds one Embree scene per group; group 0 is the root. `instances[k]`
  /// places group `instance_groups[k]` (k ≥ 1 groups) with transform `xf[k]`.
  /// `max_direct`: see kMaxDirectShapes (0: every shape goes to Embree).
  void build(const std::vector<std::vector<ShapeView>>& groups, const std::vector<int>& instance_groups,
             const std::vector<Transform>& instance_xf, size_t max_direct = kMaxDirectShapes);

  bool intersect(const Ray& r, HitRecord* h) const {
    // The direct shapes first: a hit shortens the ray Embree traverses.
    Float tmax = r.tmax;
    const int direct = nearest_direct(r, &tmax);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = r.o.x; rh.ray.org_y = r.o.y; rh.ray.org_z = r.o.z;
    rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
    rh.ray.tnear = 0;
    rh.ray.tfar = tmax;
    rh.ray.time = 0;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(root_, &ctx, &rh);
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      *h = embree_hit(rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0]);
      return true;
    }
    if (direct < 0) return false;
    *h = direct_hit(direct, tmax);
    return true;
  }
  /// Rays per packet of intersect_packet().
  static constexpr int kPacketSize = 8;
  /// Closest hits of `n` ≤ kPacketSize rays in one Embree packet (rtcIntersect8), for
  /// coherent rays such as a pixel's camera rays, which then traverse the BVH together;
  /// the same answers as intersect() ray by ray (tests/cpp/test_accel.cpp).
  /// `found[k]`: whether ray k hit; `hits[k]` as intersect() fills it.
  void intersect_packet(const Ray* rays, int n, HitRecord* hits, bool* found) const;
  /// Widths of intersect_stream() / occluded_stream(): Embree's rtcIntersect8/16 and
  /// rtcOccluded8/16 packets.
  static bool stream_width_supported(int width) { return width == 8 || width == 16; }
  static constexpr int kMaxStreamWidth = 16;
  /// Closest hits of `n` rays, `width` at a time in Embree packets of incoherent rays
  /// (ray replay's packet mode: what a wavefront integrator's traversal would cost); the
  /// same answers as intersect() ray by ray. `width`: stream_width_supported().
  void intersect_stream(const Ray* rays, size_t n, int width, HitRecord* hits, bool* found) const;
  /// Whether each of `n` rays is blocked, `width` at a time, as occluded() ray by ray.
  void occluded_stream(const Ray* rays, size_t n, int width, bool* blocked) const;
  /// rtcIntersect8/16 / rtcOccluded8/16 on a packet the caller has filled in Embree's
  /// layout (structures of arrays, as the path lanes keep their rays), lanes where
  /// valid[k] = −1. Embree's geometry alone: the caller tests the direct shapes
  /// (nearest_direct_shape). `coherent`: Embree's coherent context (camera rays).
  void intersect_lanes(const int* valid, RTCRayHit8* rh, bool coherent = false) const;
  void occluded_lanes(const int* valid, RTCRay8* ray) const;
  void intersect_lanes(const int* valid, RTCRayHit16* rh, bool coherent = false) const;
  void occluded_lanes(const int* valid, RTCRay16* ray) const;
  bool occluded(const Ray& r) const {
    if (blocked_by_direct(r)) return true;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray;
    ray.org_x = r.o.x; ray.org_y = r.o.y; ray.org_z = r.o.z;
    ray.dir_x = r.d.x; ray.dir_y = r.d.y; ray.dir_z = r.d.z;
    ray.tnear = 0;
    ray.tfar = r.tmax;
    ray.time = 0;
    ray.mask = ~0u;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(root_, &ctx, &ray);
    return ray.tfar < 0;  // Embree sets tfar = −inf on a hit
  }
  /// Shapes tested directly (tests, statistics), and the shapes themselves: callers that
  /// give Embree its packets themselves (intersect_lanes, occluded_lanes; the path lanes) test them
  /// first, as intersect() and occluded() do, and report a hit on one as direct_hit does
  /// (its geometry id, primitive 0, u = v = 0).
  size_t direct_shape_count() const { return direct_.size(); }
  const DirectShape* direct_shapes() const { return direct_.data(); }
  Bounds3 bounds() const { return bounds_; }

 private:
  /// `quads`: quad_pairs() meshes as Embree quads, and root_quads_ set.
  RTCScene build_group(const std::vector<ShapeView>& shapes, bool keep_analytic, bool quads);
  /// One Embree packet of m ≤ W rays (`coherent`: Embree's hint for rays that travel together).
  template <int W> void intersect_one_packet(const Ray* rays, int m, bool coherent, HitRecord* hits, bool* found) const;
  /// One Embree packet of m ≤ W shadow rays.
  template <int W> void occluded_one_packet(const Ray* rays, int m, bool* blocked) const;
  /// Whether a direct shape blocks `r` (occlusion queries test them before Embree).
  bool blocked_by_direct(const Ray& r) const {
    for (const DirectShape& s : direct_) {
      Float t;
      if (s.intersect(r, r.tmax, &t)) return true;
    }
    return false;
  }
  /// The nearest direct shape `r` meets before `*tmax` (which it shortens), or −1.
  int nearest_direct(const Ray& r, Float* tmax) const {
    int direct = -1;
    for (size_t i = 0; i < direct_.size(); ++i) {
      Float t;
      if (direct_[i].intersect(r, *tmax, &t)) {
        *tmax = t;
        direct = int(i);
      }
    }
    return direct;
  }
  /// Embree's hit as a HitRecord: on a root quad mesh (root_quads_), its triangle's.
  HitRecord embree_hit(Float t, Float u, Float v, unsigned geom, unsigned prim, unsigned inst) const {
    HitRecord h;
    h.t = t;
    h.u = u;
    h.v = v;
    h.geom = geom;
    h.prim = prim;
    h.inst = inst;
    if (inst == RTC_INVALID_GEOMETRY_ID && geom < root_quads_.size() && root_quads_[geom])
      quad_hit(u, v, &h.prim, &h.u, &h.v);
    return h;
  }
  HitRecord direct_hit(int direct, Float t) const {
    return embree_hit(t, 0, 0, direct_[size_t(direct)].geom, 0, ~0u);
  }
  RTCDevice device_ = nullptr;
  RTCScene root_ = nullptr;
  std::vector<RTCScene> prototypes_;
  std::vector<DirectShape> direct_;
  std::vector<uint8_t> root_quads_;  // per root geometry id: 1 where Embree has it as quads
  Bounds3 bounds_;
};

}  // namespace kauri
