// Device views of scene geometry and the surface record computed at a hit.
// Embree finds the hit; everything else (position, normals, uv) is recomputed
// here from our own data so CPU and a future GPU backend agree bit for bit.
#pragma once

#include "kauri/core/lanes.h"
#include "kauri/core/math.h"

namespace kauri {

enum class ShapeType : uint8_t { Mesh, Sphere, Disk };

/// Named per-vertex float inputs (material weights, later texture coordinates).
inline constexpr int kMaxVertexAttributes = 4;

struct MeshView {
  const Point3* p = nullptr;
  const Normal3* n = nullptr;   // optional per-vertex shading normals
  const Vec2* uv = nullptr;     // optional per-vertex uvs
  const uint32_t* index = nullptr;  // 3 per triangle
  uint32_t n_triangles = 0;
  uint32_t n_vertices = 0;
  const float* attr[kMaxVertexAttributes] = {nullptr, nullptr, nullptr, nullptr};  // per vertex, by scene slot
};
struct SphereShape {
  Point3 center;
  Float radius = 1;
};
struct DiskShape {
  Point3 center;
  Normal3 normal{0, 0, 1};
  Float radius = 1;
};

/// One shape of a group (the root scene or an instanced prototype).
struct ShapeView {
  ShapeType type = ShapeType::Mesh;
  int material = -1;       // index into the material table; -1 = black (pure emitter)
  int first_light = -1;    // for root shapes: first light of this emitter, else -1
  MeshView mesh;
  SphereShape sphere;
  DiskShape disk;
};

/// Where a ray hit, in the form Embree reports it.
struct HitRecord {
  Float t = kInfinity;
  Float u = 0, v = 0;
  uint32_t geom = ~0u, prim = ~0u, inst = ~0u;
  KAURI_HOST_DEVICE bool hit() const { return geom != ~0u; }
};

/// Local differential geometry at a hit, in world space.
struct SurfaceHit {
  Point3 p;
  Normal3 ng;       // geometric normal, unit, as authored (not face-forwarded)
  Normal3 ns;       // shading normal, unit, on the side of ng
  Vec3 dpdu;
  Vec2 uv;
  Float t = 0;
  int material = -1;
  int light = -1;   // index of the emitter hit, or -1
  Float attrs[kMaxVertexAttributes] = {0, 0, 0, 0};  // interpolated vertex attributes
};

KAURI_HOST_DEVICE inline Vec2 sphere_uv(Vec3 n_local) {
  Float phi = atan2_poly(n_local.y, n_local.x);
  if (phi < 0) phi += 2 * kPi;
  return {phi * kInv2Pi, acos_poly(n_local.z) * kInvPi};
}

/// Fills `s` (in the shape's object space) for a hit on triangle `prim` at barycentrics (u, v).
KAURI_HOST_DEVICE inline void triangle_hit(const MeshView& m, uint32_t prim, Float u, Float v, SurfaceHit* s) {
  const uint32_t* i = m.index + 3 * prim;
  Point3 p0 = m.p[i[0]], p1 = m.p[i[1]], p2 = m.p[i[2]];
  Float w = 1 - u - v;
  s->p = p0 * w + p1 * u + p2 * v;
  Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const Normal3 ng = normalize(cross(e1, e2));
  s->ng = ng;
  if (m.uv) {
    const Vec2 uv0 = m.uv[i[0]], uv1 = m.uv[i[1]], uv2 = m.uv[i[2]];
    s->uv = uv0 * w + uv1 * u + uv2 * v;
    // ∂p/∂u from the uv parameterisation (pbrt-v4 §6.5.3 derivation).
    const Vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    const Float det = d1.x * d2.y - d1.y * d2.x;
    s->dpdu = std::fabs(det) > 1e-12f ? (e1 * d2.y - e2 * d1.y) / det : e1;
  } else {
    // The default parameterisation uv = (0, 0), (1, 0), (1, 1) at the three vertices, in
    // closed form: uv = (u + v, v), and ∂p/∂u = e1 (d1 = (1, 0), d2 = (1, 1), det = 1).
    s->uv = {u + v, v};
    s->dpdu = e1;
  }
  for (int a = 0; a < kMaxVertexAttributes; ++a)
    if (m.attr[a]) s->attrs[a] = m.attr[a][i[0]] * w + m.attr[a][i[1]] * u + m.attr[a][i[2]] * v;
  s->ns = ng;  // from the register (sphere_hit)
  if (m.n) {
    Normal3 n = m.n[i[0]] * w + m.n[i[1]] * u + m.n[i[2]] * v;
    if (length_squared(n) > 0) s->ns = face_forward(normalize(n), ng);
  }
}

/// `need_uv`: whether the material reads textures (the uv costs an atan2 and an acos).
KAURI_HOST_DEVICE inline void sphere_hit(const SphereShape& sp, const Ray& r, Float t, bool need_uv, SurfaceHit* s) {
  Point3 p = r.at(t);
  Vec3 n = normalize(p - sp.center);
  s->p = sp.center + n * sp.radius;  // re-project: the hit point lies on the sphere
  // Both from the register, not ng copied from ns: that copy read 8 bytes that two 4-byte
  // stores had just written, a store-forwarding stall (perf: 1.6% of the glossy scene).
  s->ns = n;
  s->ng = n;
  if (need_uv) s->uv = sphere_uv(n);
  s->dpdu = Vec3{-n.y, n.x, 0};
  if (length_squared(s->dpdu) == 0) s->dpdu = {1, 0, 0};
}

KAURI_HOST_DEVICE inline void disk_hit(const DiskShape& d, const Ray& r, Float t, bool need_uv, SurfaceHit* s) {
  Point3 p = r.at(t);
  Vec3 off = p - d.center;
  s->p = p - d.normal * dot(off, d.normal);  // snap onto the disk plane
  s->ns = d.normal;  // both from the register (sphere_hit)
  s->ng = d.normal;
  Frame f = Frame::from_z(d.normal);
  if (need_uv) {
    Vec3 l = f.to_local(off);
    Float rr = std::sqrt(l.x * l.x + l.y * l.y) / d.radius;
    Float phi = atan2_poly(l.y, l.x);
    if (phi < 0) phi += 2 * kPi;
    s->uv = {phi * kInv2Pi, rr};
  }
  s->dpdu = f.x;
}

/// Nearest t in (0, tmax) at which `r` meets the sphere, if any (rays from inside meet it
/// on the way out). With B = (o − c)·d the quadratic is a t² + 2B t + c = 0; its
/// discriminant is taken from the ray's perpendicular offset l from the centre,
/// B² − a c = a (r² − |l|²), which keeps precision for small spheres far away, and the
/// roots as q / a and c / q with q = −B − sign(B) √disc avoid cancellation (Haines et al.
/// 2019, "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7).
KAURI_HOST_DEVICE inline bool intersect_sphere(const SphereShape& sp, const Ray& r, Float tmax, Float* t_hit) {
  const Vec3 f = r.o - sp.center;
  const Float a = dot(r.d, r.d), B = dot(f, r.d), r2 = sp.radius * sp.radius;
  const Vec3 l = f - r.d * (B / a);
  const Float disc = a * (r2 - dot(l, l));
  if (!(disc >= 0)) return false;
  const Float q = -B - std::copysign(std::sqrt(disc), B);
  if (q == 0) return false;  // tangent at the origin
  Float t0 = q / a, t1 = (dot(f, f) - r2) / q;
  if (t0 > t1) {
    const Float tmp = t0;
    t0 = t1;
    t1 = tmp;
  }
  const Float t = t0 > 0 ? t0 : t1;
  if (!(t > 0 && t < tmax)) return false;
  *t_hit = t;
  return true;
}

/// Nearest t in (0, tmax) at which `r` meets the disk (either side), if any.
KAURI_HOST_DEVICE inline bool intersect_disk(const DiskShape& dk, const Ray& r, Float tmax, Float* t_hit) {
  const Float dn = dot(r.d, dk.normal);
  if (dn == 0) return false;
  const Float t = dot(dk.center - r.o, dk.normal) / dn;
  if (!(t > 0 && t < tmax)) return false;
  if (length_squared(r.at(t) - dk.center) > dk.radius * dk.radius) return false;
  *t_hit = t;
  return true;
}

/// Offsets a ray origin off a surface along the geometric normal, scaled to the
/// float spacing of the position (Wächter & Binder 2019, "A Fast and Robust
/// Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6).
KAURI_HOST_DEVICE inline Point3 offset_ray_origin(Point3 p, Normal3 n) {
  constexpr Float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
#if KAURI_LANE_VECTORS
  // The three axes in the lanes of one vector, bit for bit the scalar steps below: the
  // per-axis branches were ~35 instructions a ray (2% of a Cornell box render's).
  using lanes::F32x4;
  using lanes::I32x4;
  const F32x4 pv = {p.x, p.y, p.z, 0}, nv = {n.x, n.y, n.z, 0};
  const I32x4 of_i = __builtin_convertvector(kIntScale * nv, I32x4);
  const I32x4 negative = pv < 0;  // -1 where p < 0: (of ^ -1) - (-1) = -of
  // A cast between vector types of one size reinterprets the bits (GCC, Clang).
  const F32x4 scaled = (F32x4)((I32x4)pv + ((of_i ^ negative) - negative));
  const F32x4 abs_p = (F32x4)((I32x4)pv & 0x7fffffff);
  const F32x4 near_origin = pv + kFloatScale * nv;
  const F32x4 r = abs_p < kOrigin ? near_origin : scaled;
  return {r[0], r[1], r[2]};
#else
  Point3 r;
  for (int a = 0; a < 3; ++a) {
    int32_t of_i = int32_t(kIntScale * n[a]);
    float pi = bits_as_float(uint32_t(int32_t(float_as_bits(p[a])) + (p[a] < 0 ? -of_i : of_i)));
    r[a] = std::fabs(p[a]) < kOrigin ? p[a] + kFloatScale * n[a] : pi;
  }
  return r;
#endif
}

/// Spawns a ray leaving `p` in direction `d`, offset to the side `d` points to.
KAURI_HOST_DEVICE inline Ray spawn_ray(Point3 p, Normal3 ng, Vec3 d) {
  Normal3 n = dot(d, ng) < 0 ? -ng : ng;
  return Ray{offset_ray_origin(p, n), d, kInfinity};
}
/// Spawns a ray from `p` towards `target` that stops just short of it.
KAURI_HOST_DEVICE inline Ray spawn_ray_to(Point3 p, Normal3 ng, Point3 target) {
  Vec3 d = target - p;
  Normal3 n = dot(d, ng) < 0 ? -ng : ng;
  Point3 o = offset_ray_origin(p, n);
  return Ray{o, target - o, 1 - 1e-4f};
}

}  // namespace kauri
