// CPU ray queries through Embree 3 (two-level: root shapes plus instances of
// prototype groups). Host code; satisfies the `Accel` concept of path_tracer.h.
#pragma once

#include <embree3/rtcore.h>

#include <vector>

#include "kauri/geometry/shapes.h"

namespace kauri {

class EmbreeAccel {
 public:
  EmbreeAccel();
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  /// Builds one Embree scene per group; group 0 is the root. `instances[k]`
  /// places group `instance_groups[k]` (k ≥ 1 groups) with transform `xf[k]`.
  void build(const std::vector<std::vector<ShapeView>>& groups, const std::vector<int>& instance_groups,
             const std::vector<Transform>& instance_xf);

  bool intersect(const Ray& r, HitRecord* h) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = r.o.x; rh.ray.org_y = r.o.y; rh.ray.org_z = r.o.z;
    rh.ray.dir_x = r.d.x; rh.ray.dir_y = r.d.y; rh.ray.dir_z = r.d.z;
    rh.ray.tnear = 0;
    rh.ray.tfar = r.tmax;
    rh.ray.time = 0;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(root_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    h->t = rh.ray.tfar;
    h->u = rh.hit.u;
    h->v = rh.hit.v;
    h->geom = rh.hit.geomID;
    h->prim = rh.hit.primID;
    h->inst = rh.hit.instID[0];
    return true;
  }
  bool occluded(const Ray& r) const {
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
  Bounds3 bounds() const { return bounds_; }

 private:
  RTCScene build_group(const std::vector<ShapeView>& shapes);
  RTCDevice device_ = nullptr;
  RTCScene root_ = nullptr;
  std::vector<RTCScene> prototypes_;
  Bounds3 bounds_;
};

}  // namespace kauri
