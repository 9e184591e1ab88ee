// Small-vector math for render-time code: plain structs, inline functions.
#pragma once

#include <cmath>
#include <cstring>
#if defined(__SSE4_1__) && !defined(__CUDACC__)
#include <immintrin.h>
#endif

#include "kauri/core/platform.h"

namespace kauri {

KAURI_HOST_DEVICE inline Float sqr(Float x) { return x * x; }
KAURI_HOST_DEVICE inline Float clamp(Float x, Float lo, Float hi) { return x < lo ? lo : (x > hi ? hi : x); }
/// Integer i wrapped into [0, n) (repeating texel indices). A lookup at coordinates in
/// [0, 1] gives i in [−1, n]: one compare and add wraps it, where the remainder is an
/// integer division (tens of cycles of latency); i further out takes the remainder.
KAURI_HOST_DEVICE inline int repeat_index(int i, int n) {
  if (i >= 0 && i < n) return i;
  if (i < 0 && i >= -n) return i + n;
  if (i >= n && i < 2 * n) return i - n;
  const int r = i % n;
  return r < 0 ? r + n : r;
}
KAURI_HOST_DEVICE inline Float lerp(Float t, Float a, Float b) { return (1 - t) * a + t * b; }
KAURI_HOST_DEVICE inline Float safe_sqrt(Float x) { return std::sqrt(x > 0 ? x : Float(0)); }
KAURI_HOST_DEVICE inline Float safe_acos(Float x) { return std::acos(clamp(x, -1, 1)); }
KAURI_HOST_DEVICE inline Float safe_asin(Float x) { return std::asin(clamp(x, -1, 1)); }

/// atan2(y, x) in [−π, π] (−π for y = −0, x < 0, as libm) without a library call, to ~1e-7 absolute: the ratio
/// min(|x|, |y|) / max(|x|, |y|) ∈ [0, 1], folded to |z| ≤ tan(π/8) by
/// atan r = π/4 + atan((r − 1)/(r + 1)), then atan z = z + z³ P(z²) with P of degree 4,
/// fitted here (weighted least squares, max error 1.8e-8 on [0, tan π/8]); the octant
/// and quadrant are restored by symmetry. libm's atan2f was 6% of an environment-lit
/// render's instructions (the lat-long lookup of every escaped ray). (0, 0) gives 0.
KAURI_HOST_DEVICE inline Float atan2_poly(Float y, Float x) {
  const Float ax = std::fabs(x), ay = std::fabs(y);
  const Float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
  const Float r = hi > 0 ? lo / hi : Float(0);
  const bool fold = r > Float(0.41421356f);  // tan(π/8)
  const Float z = fold ? (r - 1) / (r + 1) : r;
  const Float z2 = z * z;
  const Float p =
      z2 * (-0.33333316f + z2 * (0.19998547f + z2 * (-0.14244778f + z2 * (0.10602067f + z2 * -0.06097298f))));
  Float a = z + z * p + (fold ? Float(0.78539816f) : Float(0));
  if (ay > ax) a = Float(1.57079633f) - a;
  if (x < 0) a = Float(3.14159265f) - a;
  return std::signbit(y) ? -a : a;
}
/// acos(x) for x clamped to [−1, 1], as atan2_poly(√((1 − x)(1 + x)), x).
KAURI_HOST_DEVICE inline Float acos_poly(Float x) {
  x = clamp(x, -1, 1);
  return atan2_poly(std::sqrt((1 - x) * (1 + x)), x);
}
/// 1/√x, to ~3e-7 relative on the CPU: the SSE estimate (12 bits) and one Newton step
/// y(3 − x·y²)/2, about half the latency of a square root followed by a division. Every
/// hit normalises its geometric normal and its shading frame's tangent on the chain that
/// leads to the next ray; the square root and division there were the two hottest
/// instructions of a Cornell box render's path loop (perf, cpu-clock samples). Zero,
/// subnormal (which the estimate reads as 0), infinite and NaN inputs take 1/√x, so
/// normalize() behaves as a division there. CUDA and other targets divide.
KAURI_HOST_DEVICE inline Float rsqrt(Float x) {
#if defined(__SSE4_1__) && !defined(__CUDACC__)
  if (!(x >= Float(1.17549435e-38f) && x <= Float(3.40282347e38f))) return 1 / std::sqrt(x);
  const Float y = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return y * (Float(1.5f) - Float(0.5f) * x * y * y);
#else
  return 1 / std::sqrt(x);
#endif
}
KAURI_HOST_DEVICE inline Float fmin_(Float a, Float b) { return a < b ? a : b; }
KAURI_HOST_DEVICE inline Float fmax_(Float a, Float b) { return a > b ? a : b; }
KAURI_HOST_DEVICE inline bool is_finite(Float x) { return std::isfinite(x); }

KAURI_HOST_DEVICE inline uint32_t float_as_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}
KAURI_HOST_DEVICE inline float bits_as_float(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

/// x < y ? a : b as a blend, never a branch: for conditions decided by a fresh random
/// number (which half of a sample square), where a branch mispredicts every other call
/// (~15 cycles) and GCC keeps float ternaries as branches whatever it is told of the odds.
/// The comparison and the blend stay in the vector registers the floats are in.
KAURI_HOST_DEVICE inline Float select_if_less(Float x, Float y, Float a, Float b) {
#if defined(__SSE4_1__) && !defined(__CUDACC__)
  const __m128 m = _mm_cmplt_ss(_mm_set_ss(x), _mm_set_ss(y));
  return _mm_cvtss_f32(_mm_blendv_ps(_mm_set_ss(b), _mm_set_ss(a), m));
#else
  return x < y ? a : b;
#endif
}

/// e^x for |x| ≤ 80, branch-free so that a loop over several vectorises: e^x = 2^n e^y
/// with n = round(x / ln 2) and y = x − n ln 2 (Cody–Waite: ln 2 in two parts, so y
/// stays exact), |y| ≤ ln 2 / 2, and e^y by its Taylor series to degree 7 (first omitted
/// term < 6e-9). Relative error ~2e-7, the same on every CPU and on CUDA.
KAURI_HOST_DEVICE inline Float exp_poly(Float x);
/// exp_poly's two steps after n = round(x / ln 2), written once for floats and for vector
/// lanes (film/splat_lanes.h): y = x − n ln 2 with ln 2 in two parts, and e^y to degree 7.
template <class F>
KAURI_HOST_DEVICE inline F exp_poly_reduced(F x, F n) {
  const F y = (x - n * 0.693145752f) - n * 1.42860677e-6f;  // ln 2 = 0.693145752 + 1.42860677e-6
  return 1 + y * (1 + y * (1.0f / 2 + y * (1.0f / 6 + y * (1.0f / 24 + y * (1.0f / 120 + y * (1.0f / 720 + y * (1.0f / 5040)))))));
}
KAURI_HOST_DEVICE inline Float exp_poly(Float x) {
  const Float n = std::floor(x * 1.44269504f + 0.5f);
  return exp_poly_reduced(x, n) * bits_as_float(uint32_t(int32_t(n) + 127) << 23);
}

struct Vec2 {
  Float x = 0, y = 0;
  KAURI_HOST_DEVICE Float operator[](int i) const { return i == 0 ? x : y; }
};
KAURI_HOST_DEVICE inline Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
KAURI_HOST_DEVICE inline Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
KAURI_HOST_DEVICE inline Vec2 operator*(Vec2 a, Float s) { return {a.x * s, a.y * s}; }
KAURI_HOST_DEVICE inline Vec2 operator*(Float s, Vec2 a) { return {a.x * s, a.y * s}; }

struct Vec3 {
  Float x = 0, y = 0, z = 0;
  KAURI_HOST_DEVICE Float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  KAURI_HOST_DEVICE Float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  KAURI_HOST_DEVICE Vec3& operator+=(Vec3 b) { x += b.x; y += b.y; z += b.z; return *this; }
  KAURI_HOST_DEVICE Vec3& operator*=(Float s) { x *= s; y *= s; z *= s; return *this; }
};
/// Points and normals share the vector type; the names document intent.
using Point3 = Vec3;
using Normal3 = Vec3;

KAURI_HOST_DEVICE inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KAURI_HOST_DEVICE inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KAURI_HOST_DEVICE inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
KAURI_HOST_DEVICE inline Vec3 operator*(Vec3 a, Float s) { return {a.x * s, a.y * s, a.z * s}; }
KAURI_HOST_DEVICE inline Vec3 operator*(Float s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
KAURI_HOST_DEVICE inline Vec3 operator/(Vec3 a, Float s) { Float r = 1 / s; return a * r; }
KAURI_HOST_DEVICE inline Vec3 mul(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
KAURI_HOST_DEVICE inline Float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KAURI_HOST_DEVICE inline Float absdot(Vec3 a, Vec3 b) { return std::fabs(dot(a, b)); }
KAURI_HOST_DEVICE inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
KAURI_HOST_DEVICE inline Float length_squared(Vec3 a) { return dot(a, a); }
KAURI_HOST_DEVICE inline Float length(Vec3 a) { return std::sqrt(dot(a, a)); }
KAURI_HOST_DEVICE inline Vec3 normalize(Vec3 a) { return a * rsqrt(dot(a, a)); }
KAURI_HOST_DEVICE inline Float distance(Point3 a, Point3 b) { return length(a - b); }
KAURI_HOST_DEVICE inline Vec3 vmin(Vec3 a, Vec3 b) { return {fmin_(a.x, b.x), fmin_(a.y, b.y), fmin_(a.z, b.z)}; }
KAURI_HOST_DEVICE inline Vec3 vmax(Vec3 a, Vec3 b) { return {fmax_(a.x, b.x), fmax_(a.y, b.y), fmax_(a.z, b.z)}; }
KAURI_HOST_DEVICE inline Float max_component(Vec3 a) { return fmax_(a.x, fmax_(a.y, a.z)); }
KAURI_HOST_DEVICE inline bool is_finite(Vec3 a) { return is_finite(a.x) && is_finite(a.y) && is_finite(a.z); }
/// Flip `n` so it lies in the hemisphere of `v`.
KAURI_HOST_DEVICE inline Vec3 face_forward(Vec3 n, Vec3 v) { return dot(n, v) < 0 ? -n : n; }

/// Spherical direction helpers (z is up, as in the local shading frame).
KAURI_HOST_DEVICE inline Float cos_theta(Vec3 w) { return w.z; }
KAURI_HOST_DEVICE inline Float abs_cos_theta(Vec3 w) { return std::fabs(w.z); }
KAURI_HOST_DEVICE inline Float cos2_theta(Vec3 w) { return w.z * w.z; }
KAURI_HOST_DEVICE inline Float sin2_theta(Vec3 w) { return fmax_(0, 1 - cos2_theta(w)); }
KAURI_HOST_DEVICE inline Float tan2_theta(Vec3 w) { return sin2_theta(w) / cos2_theta(w); }
KAURI_HOST_DEVICE inline bool same_hemisphere(Vec3 a, Vec3 b) { return a.z * b.z > 0; }
KAURI_HOST_DEVICE inline Vec3 reflect_z(Vec3 w) { return {-w.x, -w.y, w.z}; }
KAURI_HOST_DEVICE inline Vec3 reflect(Vec3 wo, Vec3 n) { return -wo + 2 * dot(wo, n) * n; }

/// Branchless orthonormal basis around unit `n` (Duff et al. 2017, JCGT 6(1)).
KAURI_HOST_DEVICE inline void coordinate_system(Vec3 n, Vec3* s, Vec3* t) {
  Float sign = std::copysign(Float(1), n.z);
  Float a = -1 / (sign + n.z);
  Float b = n.x * n.y * a;
  *s = {1 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  *t = {b, sign + n.y * n.y * a, -n.y};
}

/// Orthonormal frame; `z` is the normal of a shading frame.
struct Frame {
  Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  KAURI_HOST_DEVICE static Frame from_z(Vec3 n) {
    Frame f;
    f.z = n;
    coordinate_system(n, &f.x, &f.y);
    return f;
  }
  /// Frame with normal `n` and first tangent as close as possible to `dpdu`.
  KAURI_HOST_DEVICE static Frame from_zx(Vec3 n, Vec3 dpdu) {
    Vec3 t = dpdu - n * dot(n, dpdu);
    Float l2 = length_squared(t);
    if (!(l2 > 1e-12f)) return from_z(n);
    Frame f;
    f.z = n;
    f.x = t * rsqrt(l2);
    f.y = cross(n, f.x);
    return f;
  }
  KAURI_HOST_DEVICE Vec3 to_local(Vec3 v) const { return {dot(v, x), dot(v, y), dot(v, z)}; }
  KAURI_HOST_DEVICE Vec3 to_world(Vec3 v) const { return x * v.x + y * v.y + z * v.z; }
};

struct Ray {
  Point3 o;
  Vec3 d;
  Float tmax = kInfinity;
  KAURI_HOST_DEVICE Point3 at(Float t) const { return o + d * t; }
};

struct Bounds3 {
  Point3 lo{kInfinity, kInfinity, kInfinity};
  Point3 hi{-kInfinity, -kInfinity, -kInfinity};
  KAURI_HOST_DEVICE void extend(Point3 p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  KAURI_HOST_DEVICE void extend(const Bounds3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  KAURI_HOST_DEVICE bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  KAURI_HOST_DEVICE Point3 center() const { return (lo + hi) * Float(0.5); }
  KAURI_HOST_DEVICE Vec3 diagonal() const { return hi - lo; }
  /// Centre and radius of a sphere enclosing the box.
  KAURI_HOST_DEVICE void bounding_sphere(Point3* c, Float* r) const {
    *c = center();
    *r = empty() ? Float(0) : distance(*c, hi);
  }
};

/// Affine transform stored as a 3x4 matrix plus its inverse.
struct Transform {
  Float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
  Float inv[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  KAURI_HOST_DEVICE Point3 point(Point3 p) const { return apply(m, p, 1); }
  KAURI_HOST_DEVICE Vec3 vector(Vec3 v) const { return apply(m, v, 0); }
  /// Normals transform with the inverse transpose.
  KAURI_HOST_DEVICE Normal3 normal(Normal3 n) const {
    return {inv[0][0] * n.x + inv[1][0] * n.y + inv[2][0] * n.z,
            inv[0][1] * n.x + inv[1][1] * n.y + inv[2][1] * n.z,
            inv[0][2] * n.x + inv[1][2] * n.y + inv[2][2] * n.z};
  }
  KAURI_HOST_DEVICE Point3 inverse_point(Point3 p) const { return apply(inv, p, 1); }
  KAURI_HOST_DEVICE Vec3 inverse_vector(Vec3 v) const { return apply(inv, v, 0); }

  KAURI_HOST_DEVICE static Vec3 apply(const Float a[3][4], Vec3 v, Float w) {
    return {a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z + a[0][3] * w,
            a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z + a[1][3] * w,
            a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z + a[2][3] * w};
  }
};

// Host-only constructors (they can fail, so they live outside device code).
/// Builds a Transform from a row-major 3x4 (or the top of a 4x4) matrix; returns false if singular.
bool make_transform(const double rows[3][4], Transform* out);
Transform look_at(Point3 eye, Point3 target, Vec3 up);  // camera-to-world
Transform compose(const Transform& a, const Transform& b);  // a after b

}  // namespace kauri
