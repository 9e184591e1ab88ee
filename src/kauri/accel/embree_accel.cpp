#include "kauri/accel/embree_accel.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace kauri {

namespace {

void check(RTCDevice d, const char* what) {
  RTCError e = rtcGetDeviceError(d);
  if (e != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree error ") + std::to_string(int(e)) + " while " + what);
}

/// A quad_pairs() mesh as Embree quads (EmbreeAccel::quad_pairs): pair (a, b, c),
/// (a, c, d) as quad (b, c, d, a).
RTCGeometry make_quads(RTCDevice dev, const MeshView& m) {
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_QUAD);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m.p, 0, sizeof(Point3), m.n_vertices);
  const uint32_t n = m.n_triangles / 2;
  auto* q = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(uint32_t), n));
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t* t = m.index + 6 * i;  // a b c, a c d
    q[4 * i] = t[1], q[4 * i + 1] = t[2], q[4 * i + 2] = t[5], q[4 * i + 3] = t[0];
  }
  return g;
}

/// `quads`: a mesh (quad_pairs()) as Embree quads; ignored for other shapes.
RTCGeometry make_geometry(RTCDevice dev, const ShapeView& s, bool quads) {
  switch (s.type) {
    case ShapeType::Mesh: {
      if (quads) return make_quads(dev, s.mesh);
      RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
      // Shared buffers: Embree reads our arrays in place; the host scene keeps
      // one padding vertex because Embree may load 16 bytes from the last one.
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s.mesh.p, 0, sizeof(Point3),
                                 s.mesh.n_vertices);
      rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, s.mesh.index, 0,
                                 3 * sizeof(uint32_t), s.mesh.n_triangles);
      return g;
    }
    case ShapeType::Sphere: {
      RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, 1));
      v[0] = s.sphere.center.x; v[1] = s.sphere.center.y; v[2] = s.sphere.center.z; v[3] = s.sphere.radius;
      return g;
    }
    case ShapeType::Disk: {
      RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, 1));
      v[0] = s.disk.center.x; v[1] = s.disk.center.y; v[2] = s.disk.center.z; v[3] = s.disk.radius;
      auto* n = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 12, 1));
      n[0] = s.disk.normal.x; n[1] = s.disk.normal.y; n[2] = s.disk.normal.z;
      return g;
    }
  }
  return nullptr;
}

void extend_bounds(const ShapeView& s, const Transform* xf, Bounds3* b) {
  auto add = [&](Point3 p) { b->extend(xf ? xf->point(p) : p); };
  auto add_box = [&](Point3 c, Float r) {
    for (int k = 0; k < 8; ++k) add(c + Vec3{k & 1 ? r : -r, k & 2 ? r : -r, k & 4 ? r : -r});
  };
  switch (s.type) {
    case ShapeType::Mesh:
      for (uint32_t i = 0; i < s.mesh.n_vertices; ++i) add(s.mesh.p[i]);
      break;
    case ShapeType::Sphere: add_box(s.sphere.center, s.sphere.radius); break;
    case ShapeType::Disk: add_box(s.disk.center, s.disk.radius); break;
  }
}

}  // namespace

bool EmbreeAccel::quad_pairs(const MeshView& m) {
  if (m.n_triangles == 0 || m.n_triangles % 2 != 0) return false;
  for (uint32_t i = 0; i < m.n_triangles; i += 2) {
    const uint32_t* t = m.index + 3 * size_t(i);
    if (t[3] != t[0] || t[4] != t[2]) return false;
  }
  return true;
}

EmbreeAccel::EmbreeAccel() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("could not create an Embree device");
}

EmbreeAccel::~EmbreeAccel() {
  for (RTCScene s : prototypes_) rtcReleaseScene(s);
  if (root_) rtcReleaseScene(root_);
  if (device_) rtcReleaseDevice(device_);
}

/// `keep_analytic` false: spheres and disks are left out (the root's direct shapes).
RTCScene EmbreeAccel::build_group(const std::vector<ShapeView>& shapes, bool keep_analytic, bool quads) {
  RTCScene scene = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  // Quads only where every mesh is quad pairs (quad_pairs: one BVH, not one per type).
  bool as_quads = quads;
  for (const ShapeView& s : shapes) as_quads = as_quads && (s.type != ShapeType::Mesh || quad_pairs(s.mesh));
  if (quads) root_quads_.assign(shapes.size(), 0);
  for (size_t i = 0; i < shapes.size(); ++i) {
    const bool mesh = shapes[i].type == ShapeType::Mesh;
    if (!keep_analytic && !mesh) continue;
    if (as_quads && mesh) root_quads_[i] = 1;
    RTCGeometry g = make_geometry(device_, shapes[i], as_quads);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, unsigned(i));
    rtcReleaseGeometry(g);
  }
  check(device_, "adding geometry");
  return scene;
}

void EmbreeAccel::build(const std::vector<std::vector<ShapeView>>& groups, const std::vector<int>& instance_groups,
                        const std::vector<Transform>& instance_xf, size_t max_direct) {
  const std::vector<ShapeView>& root = groups.at(0);
  size_t analytic = 0;
  for (const ShapeView& s : root) analytic += s.type != ShapeType::Mesh ? 1 : 0;
  const bool direct = analytic > 0 && analytic <= max_direct;
  direct_.clear();
  if (direct)
    for (size_t i = 0; i < root.size(); ++i)
      if (root[i].type != ShapeType::Mesh) direct_.push_back({root[i].type, unsigned(i), root[i].sphere, root[i].disk});
  root_ = build_group(root, !direct, true);
  for (const ShapeView& s : groups[0]) extend_bounds(s, nullptr, &bounds_);
  prototypes_.assign(groups.size(), nullptr);
  for (size_t g = 1; g < groups.size(); ++g) {
    prototypes_[g] = build_group(groups[g], true, false);
    rtcCommitScene(prototypes_[g]);
  }
  const unsigned first_instance_id = unsigned(groups[0].size());
  for (size_t k = 0; k < instance_groups.size(); ++k) {
    int grp = instance_groups[k];
    RTCGeometry inst = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(inst, prototypes_.at(size_t(grp)));
    float m[12];  // column-major 3x4
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) m[c * 3 + r] = instance_xf[k].m[r][c];
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
    rtcCommitGeometry(inst);
    rtcAttachGeometryByID(root_, inst, first_instance_id + unsigned(k));
    rtcReleaseGeometry(inst);
    for (const ShapeView& s : groups[size_t(grp)]) extend_bounds(s, &instance_xf[k], &bounds_);
  }
  rtcCommitScene(root_);
  check(device_, "building the acceleration structure");
}

namespace {

/// Embree's packet types and calls by width.
template <int W> struct EmbreePacket;
template <> struct EmbreePacket<8> {
  using RayHit = RTCRayHit8;
  using Ray = RTCRay8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect8(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded8(valid, s, c, r); }
};
template <> struct EmbreePacket<16> {
  using RayHit = RTCRayHit16;
  using Ray = RTCRay16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) { rtcIntersect16(valid, s, c, r); }
  static void occluded(const int* valid, RTCScene s, RTCIntersectContext* c, Ray* r) { rtcOccluded16(valid, s, c, r); }
};

/// Lane k of an Embree packet ray from `r`, traversed up to `tmax`.
template <class PacketRay>
void set_packet_ray(PacketRay& p, int k, const Ray& r, Float tmax) {
  p.org_x[k] = r.o.x; p.org_y[k] = r.o.y; p.org_z[k] = r.o.z;
  p.dir_x[k] = r.d.x; p.dir_y[k] = r.d.y; p.dir_z[k] = r.d.z;
  p.tnear[k] = 0;
  p.tfar[k] = tmax;
  p.time[k] = 0;
  p.mask[k] = ~0u;
  p.id[k] = unsigned(k);
  p.flags[k] = 0;
}

}  // namespace

template <int W>
void EmbreeAccel::intersect_one_packet(const Ray* rays, int m, bool coherent, HitRecord* hits, bool* found) const {
  using P = EmbreePacket<W>;
  alignas(64) int valid[W];
  alignas(64) typename P::RayHit rh;
  Float tmax[W];
  int direct[W];
  for (int k = 0; k < W; ++k) {
    valid[k] = k < m ? -1 : 0;
    const Ray& r = rays[k < m ? k : 0];
    // The direct shapes first, as in intersect(): a hit shortens the ray Embree traverses.
    tmax[k] = r.tmax;
    direct[k] = k < m ? nearest_direct(r, &tmax[k]) : -1;
    set_packet_ray(rh.ray, k, r, tmax[k]);
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (coherent) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  P::intersect(valid, root_, &ctx, &rh);
  for (int k = 0; k < m; ++k) {
    found[k] = true;
    if (rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID)
      hits[k] = embree_hit(rh.ray.tfar[k], rh.hit.u[k], rh.hit.v[k], rh.hit.geomID[k], rh.hit.primID[k],
                           rh.hit.instID[0][k]);
    else if (direct[k] >= 0)
      hits[k] = direct_hit(direct[k], tmax[k]);
    else
      found[k] = false;
  }
}

void EmbreeAccel::intersect_packet(const Ray* rays, int n, HitRecord* hits, bool* found) const {
  intersect_one_packet<kPacketSize>(rays, n, true, hits, found);
}

template <int W>
void EmbreeAccel::occluded_one_packet(const Ray* rays, int m, bool* blocked) const {
  using P = EmbreePacket<W>;
  alignas(64) int valid[W];
  alignas(64) typename P::Ray ray;
  bool by_direct[W];
  for (int k = 0; k < W; ++k) {
    const Ray& r = rays[k < m ? k : 0];
    by_direct[k] = k < m && blocked_by_direct(r);  // as occluded(): a direct shape answers first
    valid[k] = k < m && !by_direct[k] ? -1 : 0;
    set_packet_ray(ray, k, r, r.tmax);
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  P::occluded(valid, root_, &ctx, &ray);
  for (int k = 0; k < m; ++k) blocked[k] = by_direct[k] || ray.tfar[k] < 0;
}

void EmbreeAccel::intersect_lanes(const int* valid, RTCRayHit8* rh, bool coherent) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (coherent) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect8(valid, root_, &ctx, rh);
}

void EmbreeAccel::occluded_lanes(const int* valid, RTCRay8* ray) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded8(valid, root_, &ctx, ray);
}

void EmbreeAccel::intersect_lanes(const int* valid, RTCRayHit16* rh, bool coherent) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (coherent) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect16(valid, root_, &ctx, rh);
}

void EmbreeAccel::occluded_lanes(const int* valid, RTCRay16* ray) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded16(valid, root_, &ctx, ray);
}

void EmbreeAccel::intersect_stream(const Ray* rays, size_t n, int width, HitRecord* hits, bool* found) const {
  if (!stream_width_supported(width))
    throw std::invalid_argument("intersect_stream: width must be 8 or 16, not " + std::to_string(width));
  for (size_t i = 0; i < n; i += size_t(width)) {  // incoherent rays: Embree's default context
    const int m = int(std::min<size_t>(size_t(width), n - i));
    if (width == 16) intersect_one_packet<16>(rays + i, m, false, hits + i, found + i);
    else intersect_one_packet<8>(rays + i, m, false, hits + i, found + i);
  }
}

void EmbreeAccel::occluded_stream(const Ray* rays, size_t n, int width, bool* blocked) const {
  if (!stream_width_supported(width))
    throw std::invalid_argument("occluded_stream: width must be 8 or 16, not " + std::to_string(width));
  for (size_t i = 0; i < n; i += size_t(width)) {
    const int m = int(std::min<size_t>(size_t(width), n - i));
    if (width == 16) occluded_one_packet<16>(rays + i, m, blocked + i);
    else occluded_one_packet<8>(rays + i, m, blocked + i);
  }
}

}  // namespace kauri
