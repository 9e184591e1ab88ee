// A pixel's group of camera paths traced together, one path per vector lane: the first
// stage of the vector integrator (docs/benchmarks.md, "Where kauri's time goes").
//
// trace_paths_lanes() takes the same inputs and gives the same outputs as calling
// trace_path() on each path of the group: the same sampler dimensions, the same estimators
// (next-event estimation with MIS, Russian roulette, bounce budgets), the same operations
// up to rounding (a reciprocal square root or a contracted multiply-add may differ in
// the last bit, and where such a bit decides a comparison two paths part ways; the
// images agree within noise, tests/cpp/test_path_lanes.cpp). The state stays in
// structures of arrays from the camera hits to the outputs. Across the lanes: Embree's
// queries (rtcIntersect8 / rtcOccluded8 packets filled from the lanes' vectors; a hit on
// a mesh Embree holds as quads mapped to its triangle, as EmbreeAccel::quad_hit), triangle
// surface hits (rows of LaneTriangles, transposed), the shading frame, next-event estimation's
// light point, densities, Lambert value and MIS weight, the cosine-weighted BSDF sample,
// the throughput, roulette, the next rays' offset origins, and the ray tests of the
// spheres and disks that EmbreeAccel keeps out of Embree (its direct shapes). Lane by
// lane, over the live lanes only: the light tree's choice, the sampler's values, the
// albedo (a sigmoid or a texture lookup), emission found by a BSDF sample, the surface at
// a sphere's or disk's hit, an infinite light's sample (its direction and density by
// sample_light; its MIS weight and shadow ray across the lanes) and what a path escaping
// into a constant environment or a distant light receives. An environment image's samples
// and lookups, a constant environment's radiance and a measured metal's η and κ are taken
// across the lanes (path_lanes_env.inl, path_lanes_conductor.inl).
//
// Why the state must live in the lanes: a first version that kept the per-path structures
// and handed Embree packets of them (rtcIntersect8 on copies, surface hits by
// compute_surface_hit lane by lane) was 5–9% slower than one path at a time on two
// threads; moving rays, hits and surfaces into the lanes made the Cornell box 0.76–0.80×
// the one-path time (docs/benchmarks.md).
//
// It covers the scenes (path_lanes_supported) of shapes of the root group (triangle meshes,
// spheres and disks), triangle area lights with their own emission and infinite lights
// (constant and image environments, distant lights), with at least one surface whose
// vertices the lanes run across the vector: those of materials of one lobe with a constant
// weight, Lambert (its albedo constant, RGB or an image texture), a rough GGX conductor, a
// rough dielectric without dispersion, a mirror or smooth glass without dispersion
// (path_lanes_conductor.inl). At a vertex of any other BSDF (dispersive glass, Beckmann
// conductors, Oren–Nayar, sheen, layered stacks) a group with more than half its lanes live
// builds, evaluates and samples it lane by lane with trace_path's own functions
// (bsdf_vertex: direct_sample, continue_path) and keeps the path, whose rays stay in the
// group's packets; a sparser group hands the path over there, to trace_path() from that
// hit with the lane's state, and its lane ends, as every group does at a material whose
// weights read vertex attributes (which the lanes do not interpolate). Other scenes take
// trace_path() one path at a time. Host CPU code (GCC/Clang vector types, AVX2; AVX-512
// in the x86-64-v4 core); a CUDA build runs trace_path().
//
// The lane count follows the core's instruction set, as Dr.Jit's LLVM kernels follow the
// machine: 8 lanes (one AVX2 register of floats) in the x86-64-v3 core, 16 (one AVX-512
// register) in the x86-64-v4 core, with Embree's 16-wide packets. The code is written once
// over LF / LI (the lane vectors); the few steps across lanes that GCC does not find by
// itself (masks, the tables' row transposes, gathers) have a version per width. On the
// bench's Xeon (AVX-512) the 16 lanes took 3–7% off the render time of every lanes scene
// against 8 in the same core (docs/benchmarks.md).
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <type_traits>
#include <vector>

#include "kauri/accel/embree_accel.h"
#include "kauri/core/lanes.h"
#include "kauri/integrator/path_tracer.h"

#define KAURI_PATH_LANES KAURI_LANES_AVX2

namespace kauri {

/// Paths a group traces together: one vector of floats, 16 lanes where the core is
/// compiled for AVX-512 (the x86-64-v4 core), else 8 (AVX2).
inline constexpr int kPathLanes = KAURI_LANES_AVX512 ? 16 : 8;

/// Triangles at most for the lanes: their tables (LaneTriangles) cost 64 bytes a triangle
/// besides the scene's own, 160 with uv and shading normals (32–80 MiB at this count). Larger scenes spend most of
/// their time in traversal, where the lanes gain least (the bench's million-triangle
/// scene: 58% of its render is Embree's), and take trace_path().
inline constexpr size_t kPathLanesMaxTriangles = size_t(1) << 19;

/// Whether trace_paths_lanes() runs `s` (see above: its shapes and lights, a surface the
/// lanes run across the vector, at most kPathLanesMaxTriangles) and the build has the vector types. Host code,
/// once per render.
bool path_lanes_supported(const SceneView& s);

/// The root group's shapes and triangles as tables of rows the lanes read by shape and by
/// triangle number (first + prim): 8 lanes' rows are loaded and transposed into one vector
/// per field (lanes::load_columns8), which costs less than a gather per field. A
/// triangle's row holds what triangle_hit() computes per triangle whatever the hit's
/// barycentrics (the unit geometric normal and ∂p/∂u, by triangle_hit itself, so bit for
/// bit its values) beside its vertices.
struct alignas(32) LaneShapeRow {
  int32_t first = -1;        // its first triangle's number; −1: a sphere or disk
  int32_t quads = 0;         // −1: Embree has it as quads (EmbreeAccel::root_quads)
  int32_t material = -1;     // (spheres and disks too: the lanes hand over their paths by it)
  int32_t first_light = -1;  // the light of its triangle `prim` is first_light + prim (a sphere's or disk's: first_light); −1: none
  int32_t has_n = 0;         // −1: per-vertex shading normals
  int32_t unused[3] = {};
};
struct alignas(64) LaneTriangleRow {
  float p[9];     // p0.x, p0.y, p0.z, p1.x, …, p2.z
  float ng[3];
  float dpdu[3];
  float unused;
};
struct alignas(32) LaneUvRow {
  float uv[6];  // uv0.u, uv0.v, uv1.u, …: the mesh's, or triangle_hit's default
  float unused[2];
};
struct alignas(64) LaneNormalRow {
  float n[9];  // per-vertex shading normals, as p
  float unused[7];
};
/// A triangle light's row (per scene light; zero for the others): what next-event
/// estimation's point on it needs.
struct alignas(64) LaneLightRow {
  float p0[3], p1[3], p2[3], n[3];
  float inv_area;     // 1 / area
  int32_t two_sided;  // −1: emits on both sides
  float unused[2];
};
/// An environment image's next-event density (env_distribution for kNextEventDensity),
/// read flat for lookups and samples across the lanes (path_lanes_env.inl): pointers into
/// the Distribution2D, which keeps its rows one after another. `conditional_func` null: no
/// density (next-event estimation never samples the light).
struct LaneEnvTables {
  const float* conditional_func = nullptr;  // nv × nu
  const float* conditional_cdf = nullptr;   // nv × (nu + 1)
  const float* marginal_func = nullptr;     // nv: the rows' integrals
  const float* marginal_cdf = nullptr;      // nv + 1
  float marginal_integral = 0;              // > 0 where the tables are set
  int nu = 0, nv = 0;
  // Guide tables of the inverse-CDF searches (cutpoints, Chen & Asau 1974): for a
  // distribution of n bins, G = the power of two ≥ n buckets, and guide[j] (j = 0 … G) the
  // bin find_interval returns for u = j / G. A u in bucket j = ⌊u G⌋ (exact: G is a power
  // of two) has its bin in [guide[j], guide[j + 1]], so the search starts from that
  // bracket, mostly a bin or two, instead of halving all n: ⌈log₂ n⌉ gathers, each
  // waiting on the last, were the environment scene's largest cost in the lanes.
  const int32_t* marginal_guide = nullptr;     // gv + 1
  const int32_t* conditional_guide = nullptr;  // nv × (gu + 1)
  int gu = 0, gv = 0;
};
/// Where the lanes run a material's vertices (LaneTriangles::lane_material).
enum LaneMaterial : uint8_t {
  kHandOver = 0,  // trace_path goes on from the hit: the material reads vertex attributes
  kLaneLambert,   // one Lambert lobe, its albedo constant, RGB or a texture: across the lanes
  kLaneConductor, // one rough GGX conductor lobe: across the lanes (path_lanes_conductor.inl)
  kLaneDielectric,// one rough GGX dielectric lobe without dispersion: across the lanes, likewise
  kLaneSpecular,  // a mirror or smooth glass without dispersion: across the lanes, likewise
  kLaneBsdf,      // any other BSDF: built, sampled and evaluated lane by lane (bsdf_vertex)
};
struct LaneTriangles {
  const LaneShapeRow* shapes = nullptr;       // per root shape
  const LaneLightRow* lights = nullptr;       // per scene light
  const LaneTriangleRow* triangles = nullptr;
  const LaneUvRow* uv = nullptr;              // null: no mesh's material reads uv
  const LaneNormalRow* normals = nullptr;     // null: no mesh has shading normals
  const LaneEnvTables* env = nullptr;         // per scene light (empty but for environment images)
  const uint8_t* lane_material = nullptr;     // per material: its LaneMaterial
  // Per lobe, [2 × lobe + side] (side 0: ω_o outside): a compensated kLaneDielectric lobe's
  // multiple-scattering terms (RoughDielectricLobe::ms_terms), the same for every path
  // (its η does not depend on the wavelength), computed once per render.
  const RoughDielectricLobe::MS* dielectric_ms = nullptr;
  // The light whose emission (an RGB illuminant spectrum) most triangle lights share, or −1:
  // each lane's EmissionCache starts with it, evaluated across the lanes (prefill_emission).
  int common_emission_light = -1;
  bool any_quads = false;
};
/// Host storage of a LaneTriangles (build_lane_triangles).
struct LaneTrianglesStore {
  std::vector<LaneShapeRow> shapes;
  std::vector<LaneLightRow> lights;
  std::vector<LaneTriangleRow> triangles;
  std::vector<LaneUvRow> uv;
  std::vector<LaneNormalRow> normals;
  std::vector<LaneEnvTables> env;  // per scene light
  std::vector<std::vector<int32_t>> env_guides;  // per scene light: its marginal's guide, then its rows'
  std::vector<uint8_t> lane_material;
  std::vector<RoughDielectricLobe::MS> dielectric_ms;
  int common_emission_light = -1;
  bool any_quads = false;
  LaneTriangles view() const;
};
/// The triangles of a path_lanes_supported() scene; `root_quads`: EmbreeAccel::root_quads()
/// of its accelerator (which meshes' hits the lanes map from quads to triangles).
LaneTrianglesStore build_lane_triangles(const SceneView& s, const std::vector<uint8_t>& root_quads);

#if KAURI_PATH_LANES
namespace path_lanes_detail {
constexpr int W = kPathLanes;
/// The lane vectors and Embree's packets of this width.
template <class Narrow, class Wide>
using ByWidth = std::conditional_t<W == 16, Wide, Narrow>;
using LF = ByWidth<lanes::F32x8, lanes::F32x16>;
using LI = ByWidth<lanes::I32x8, lanes::I32x16>;
using LU = ByWidth<lanes::U32x8, lanes::U32x16>;
using RTCRayHitW = ByWidth<RTCRayHit8, RTCRayHit16>;
using RTCRayW = ByWidth<RTCRay8, RTCRay16>;
/// Bytes of a lane vector: the alignment of the lanes' columns.
constexpr int kLaneBytes = int(sizeof(LF));

struct V3 {
  LF x, y, z;
};
inline LF splat(Float v) { return LF{} + v; }
inline V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(const V3& a, LF s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator-(const V3& a) { return {-a.x, -a.y, -a.z}; }
inline LF dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
#if KAURI_LANES_AVX512
inline LF vsqrt(LF x) { return LF(_mm512_sqrt_ps(__m512(x))); }
/// The lanes set in `m` as bits (lane k: bit k).
inline int mask_bits(LI m) { return int(_mm512_movepi32_mask(__m512i(m))); }
inline LF vfloor(LF x) { return LF(_mm512_roundscale_ps(__m512(x), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)); }
#else
inline LF vsqrt(LF x) { return __builtin_ia32_sqrtps256(x); }
inline int mask_bits(LI m) { return _mm256_movemask_ps((__m256)m); }
inline LF vfloor(LF x) { return LF(_mm256_floor_ps(__m256(x))); }
#endif
/// Every lane set.
inline bool all(LI m) { return mask_bits(m) == (1 << W) - 1; }
/// Lane k holds k.
inline LI lane_index() {
  LI v;
  for (int k = 0; k < W; ++k) v[k] = k;
  return v;
}
inline LF vabs(LF x) { return (LF)((LI)x & 0x7fffffff); }
inline LF vmax(LF a, LF b) { return a > b ? a : b; }
inline LF vmin(LF a, LF b) { return a < b ? a : b; }
inline V3 normalize(const V3& a) { return a * (1 / vsqrt(dot(a, a))); }
inline V3 select(LI m, const V3& a, const V3& b) { return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z}; }
inline bool any(LI m) { return mask_bits(m) != 0; }

/// A float array of W lanes as one vector and back.
inline LF load(const float* a) {
  LF v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
inline void store(LF v, float* a) { __builtin_memcpy(a, &v, sizeof v); }
inline LI load(const int32_t* a) {
  LI v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
inline void store(LI v, int32_t* a) { __builtin_memcpy(a, &v, sizeof v); }

/// Three float arrays (x, y, z) of W lanes.
struct V3Lanes {
  alignas(kLaneBytes) float x[W], y[W], z[W];
  void set(int k, Vec3 v) { x[k] = v.x, y[k] = v.y, z[k] = v.z; }
  Vec3 get(int k) const { return {x[k], y[k], z[k]}; }
  V3 load() const { return {path_lanes_detail::load(x), path_lanes_detail::load(y), path_lanes_detail::load(z)}; }
  void store(const V3& v) {
    path_lanes_detail::store(v.x, x), path_lanes_detail::store(v.y, y), path_lanes_detail::store(v.z, z);
  }
};
/// A spectrum per lane: wavelength i of every lane in v[i].
struct SpectrumLanes {
  alignas(kLaneBytes) float v[kSpectrumSamples][W];
  void set(int k, const SampledSpectrum& s) {
    for (int i = 0; i < kSpectrumSamples; ++i) v[i][k] = s[i];
  }
  SampledSpectrum get(int k) const {
    SampledSpectrum s;
    for (int i = 0; i < kSpectrumSamples; ++i) s[i] = v[i][k];
    return s;
  }
};

/// cos_sin_quarter over lanes (the same polynomial).
inline void cos_sin_quarter(LF phi, LF* c, LF* s) {
  const LF x2 = phi * phi;
  *c = 1 + x2 * (-1.0f / 2 + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320 - x2 * (1.0f / 3628800)))));
  *s = phi * (1 + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880)))));
}

/// sample_cosine_hemisphere over lanes.
inline V3 sample_cosine_hemisphere(LF ux, LF uy) {
  const LF a = 2 * ux - 1, b = 2 * uy - 1;
  const LF abs_a = vabs(a), abs_b = vabs(b);
  const LI wedge_a = abs_b < abs_a;
  const LF r = wedge_a ? a : b, q = wedge_a ? b : a;
  const LI centre = (a == 0) & (b == 0);
  LF c, s;
  cos_sin_quarter(kPiOver4 * (q / (centre ? splat(1) : r)), &c, &s);
  const LF dx = centre ? LF{} : r * (wedge_a ? c : s);
  const LF dy = centre ? LF{} : r * (wedge_a ? s : c);
  const LF rr = vmax(abs_a, abs_b);
  const LF z2 = (1 - rr) * (1 + rr);
  return {dx, dy, vsqrt(z2 > 0 ? z2 : LF{})};
}

/// power_heuristic over lanes.
inline LF power_heuristic(LF pa, LF pb) {
  const LF a = pa * pa, b = pb * pb;
  const LF s = a + b;
  const LF w = s > 0 ? a / (s > 0 ? s : splat(1)) : LF{};
  return a < kInfinity ? w : splat(1);
}

/// path_detail::rr_survival over lanes (cbrt_unit's bit guess and two Newton steps).
inline LF rr_survival(LF beta_max) {
  const LF x = vmax(beta_max, splat(1.17549435e-38f));
  LF y = (LF)((LI)((LU)x / 3u + 709921077u));
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  y = vmin(y, splat(1));
  return beta_max > 0 ? (beta_max >= 1 ? splat(1) : y) : LF{};
}

/// The shading frame Frame::from_zx(n, dpdu) over lanes; lanes whose tangent degenerates
/// take Frame::from_z one by one.
inline void shading_frames(const V3& n, const V3& dpdu, V3* fx, V3* fy) {
  const V3 t = dpdu - n * dot(n, dpdu);
  const LF l2 = dot(t, t);
  const LI ok = l2 > 1e-12f;
  *fx = t * (1 / vsqrt(ok ? l2 : splat(1)));
  if (!all(ok)) {
    for (int k = 0; k < W; ++k)
      if (!ok[k]) {
        const Frame f = Frame::from_z(Vec3{n.x[k], n.y[k], n.z[k]});
        fx->x[k] = f.x.x, fx->y[k] = f.x.y, fx->z[k] = f.x.z;
      }
  }
  *fy = cross(n, *fx);
  // from_z's second tangent is coordinate_system's, not n × x in general: take it too.
  if (!all(ok)) {
    for (int k = 0; k < W; ++k)
      if (!ok[k]) {
        const Frame f = Frame::from_z(Vec3{n.x[k], n.y[k], n.z[k]});
        fy->x[k] = f.y.x, fy->y[k] = f.y.y, fy->z[k] = f.y.z;
      }
  }
}

/// PathState's fields as columns, lane k of each the state of path k.
struct PathColumns {
  alignas(kLaneBytes) int32_t depth[W], diffuse_depth[W], glossy_depth[W], transmission_depth[W];
  alignas(kLaneBytes) int32_t last_segment[W], specular[W], any_non_specular[W];  // -1: true
  alignas(kLaneBytes) float prev_pdf[W], eta_scale[W];
  V3Lanes prev_p, prev_n;
  SpectrumLanes beta;
  /// PathState of lane k, for the per-lane code shared with trace_path.
  PathState state(int k) const {
    PathState st;
    st.beta = beta.get(k);
    st.eta_scale = eta_scale[k];
    st.depth = depth[k];
    st.diffuse_depth = diffuse_depth[k];
    st.glossy_depth = glossy_depth[k];
    st.transmission_depth = transmission_depth[k];
    st.specular_bounce = specular[k] != 0;
    st.any_non_specular = any_non_specular[k] != 0;
    st.last_segment = last_segment[k] != 0;
    st.prev_pdf = prev_pdf[k];
    st.prev_p = prev_p.get(k);
    st.prev_n = prev_n.get(k);
    return st;
  }
  void set_state(int k, const PathState& st) {
    beta.set(k, st.beta);
    eta_scale[k] = st.eta_scale;
    depth[k] = st.depth;
    diffuse_depth[k] = st.diffuse_depth;
    glossy_depth[k] = st.glossy_depth;
    transmission_depth[k] = st.transmission_depth;
    specular[k] = st.specular_bounce ? -1 : 0;
    any_non_specular[k] = st.any_non_specular ? -1 : 0;
    last_segment[k] = st.last_segment ? -1 : 0;
    prev_pdf[k] = st.prev_pdf;
    prev_p.set(k, st.prev_p);
    prev_n.set(k, st.prev_n);
  }
  /// Lanes `m` of every column from `o`.
  void take(LI m, const PathColumns& o) {
    auto take_int = [&](int32_t(PathColumns::*f)[W]) { store(m ? load(o.*f) : load(this->*f), this->*f); };
    auto take_float = [&](float(PathColumns::*f)[W]) { store(m ? load(o.*f) : load(this->*f), this->*f); };
    take_int(&PathColumns::depth), take_int(&PathColumns::diffuse_depth), take_int(&PathColumns::glossy_depth);
    take_int(&PathColumns::transmission_depth), take_int(&PathColumns::last_segment);
    take_int(&PathColumns::specular), take_int(&PathColumns::any_non_specular);
    take_float(&PathColumns::prev_pdf), take_float(&PathColumns::eta_scale);
    prev_p.store(select(m, o.prev_p.load(), prev_p.load()));
    prev_n.store(select(m, o.prev_n.load(), prev_n.load()));
    for (int i = 0; i < kSpectrumSamples; ++i) store(m ? load(o.beta.v[i]) : load(beta.v[i]), beta.v[i]);
  }
};

/// The lanes' paths between bounces: their states, and what they have gathered.
struct Paths : PathColumns {
  alignas(kLaneBytes) int32_t alive[W];  // -1: the path goes on; 0: it has ended
  SpectrumLanes L, L_direct;
  EmissionCache emission[W];
  /// PathOutput::add into the lanes' sums: light seen directly or via one bounce is
  /// direct.
  void add(int k, const SampledSpectrum& c, ContributionKind kind) {
    const bool direct = kind == ContributionKind::DirectLight ? depth[k] == 0 : depth[k] <= 1;
    SpectrumLanes& s = direct ? L_direct : L;
    for (int i = 0; i < kSpectrumSamples; ++i) s.v[i][k] += c[i];
  }
};

/// A bounce's vertices: what the per-lane part finds for the vector part.
struct Vertices {
  alignas(kLaneBytes) int32_t scatter[W];   // -1: the lane samples light and its BSDF
  alignas(kLaneBytes) int32_t conductor[W]; // -1: that BSDF is a GGX conductor
  alignas(kLaneBytes) int32_t dielectric[W];// -1: a rough dielectric
  alignas(kLaneBytes) int32_t specular[W];  // -1: a mirror or smooth glass (none of these: Lambert)
  alignas(kLaneBytes) int32_t nee[W];       // -1: next-event estimation has a light
  V3Lanes p, ng, ns, wo, dpdu;
  alignas(kLaneBytes) float uv[2][W];
  SpectrumLanes albedo;              // w_b · ρ(λ)
  alignas(kLaneBytes) float u_light[2][W], u_lobe[W], u_rr[W], u_bsdf[2][W];
  alignas(kLaneBytes) float light_pmf[W];
  alignas(kLaneBytes) int32_t light_index[W];  // a triangle light's row (LaneTriangles::lights)
  // An infinite light's sample (sample_light, lane by lane): −1 in light_dir, its direction
  // and solid-angle density; light_delta −1 for a distant light.
  alignas(kLaneBytes) int32_t light_dir[W], light_delta[W];
  alignas(kLaneBytes) int32_t env[W];  // −1: an environment image's sample, taken across the lanes
  V3Lanes light_wi;
  alignas(kLaneBytes) float light_pdf[W];
  SpectrumLanes Le;
};
/// A bounce's vertices of materials whose BSDFs the lanes build, sample and evaluate lane
/// by lane (bsdf_vertex): the next-event estimate up to its shadow ray, which joins the
/// group's packet, and the path's state after the BSDF sample, which the lanes take once
/// the group's estimates are added.
struct BsdfVertices {
  alignas(kLaneBytes) int32_t active[W];  // -1: the lane's vertex is one of these
  alignas(kLaneBytes) int32_t nee[W];     // -1: a shadow ray, and c
  alignas(kLaneBytes) int32_t alive[W];   // -1: the path goes on from `next`
  SpectrumLanes c;                // what the estimate adds where the shadow ray is unoccluded
  V3Lanes shadow_o, shadow_d, wi;
  alignas(kLaneBytes) float shadow_tmax[W];
  PathColumns next;
};
}  // namespace path_lanes_detail

namespace path_lanes_detail {
/// Lane k of a vector triple.
inline Vec3 lane(const V3& v, int k) { return {v.x[k], v.y[k], v.z[k]}; }
/// Columns 8c … 8c + 7 of the rows `index` of a LaneTriangles table (lanes::load_columns8,
/// per 8 lanes).
template <class Row>
inline void load_columns(const Row* table, LI index, int c, LF column[8]) {
  static_assert(sizeof(Row) % 32 == 0 && alignof(Row) >= 32, "rows of whole 32-byte columns");
#if KAURI_LANES_AVX512
  lanes::load_columns16(reinterpret_cast<const float*>(table), int(sizeof(Row) / sizeof(float)), index, c, column);
#else
  __m256 v[8];
  lanes::load_columns8(reinterpret_cast<const float*>(table), int(sizeof(Row) / sizeof(float)), index, c, v);
  __builtin_memcpy(column, v, sizeof v);
#endif
}
/// offset_ray_origin over lanes (the same steps, axis by axis).
inline LF offset_axis(LF p, LF n) {
  constexpr Float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
  const LI of_i = __builtin_convertvector(kIntScale * n, LI);
  const LI negative = p < 0;
  const LF scaled = (LF)((LI)p + ((of_i ^ negative) - negative));
  const LF abs_p = (LF)((LI)p & 0x7fffffff);
  return abs_p < kOrigin ? p + kFloatScale * n : scaled;
}
inline V3 offset_ray_origin(const V3& p, const V3& n) {
  return {offset_axis(p.x, n.x), offset_axis(p.y, n.y), offset_axis(p.z, n.z)};
}
inline V3 splat3(Vec3 v) { return {splat(v.x), splat(v.y), splat(v.z)}; }
inline LF copysign(LF mag, LF sign) {
  return (LF)(((LI)mag & 0x7fffffff) | ((LI)sign & int32_t(0x80000000u)));
}
/// intersect_sphere over lanes, the same steps (Haines et al. 2019): the lanes whose ray
/// meets `sp` in (0, tmax), and there t.
inline LI intersect_sphere(const SphereShape& sp, const V3& o, const V3& d, LF tmax, LF* t_hit) {
  const V3 f = o - splat3(sp.center);
  const LF a = dot(d, d), B = dot(f, d), r2 = splat(sp.radius * sp.radius);
  const V3 l = f - d * (B / a);
  const LF disc = a * (r2 - dot(l, l));
  LI hit = disc >= 0;
  const LF q = -B - copysign(vsqrt(hit ? disc : LF{}), B);
  hit &= q != 0;  // tangent at the origin
  const LF t0 = q / a, t1 = (dot(f, f) - r2) / (hit ? q : splat(1));
  const LI swap = t0 > t1;
  const LF near = swap ? t1 : t0, far = swap ? t0 : t1;
  const LF t = near > 0 ? near : far;
  *t_hit = t;
  return hit & (t > 0) & (t < tmax);
}
/// intersect_disk over lanes, the same steps.
inline LI intersect_disk(const DiskShape& dk, const V3& o, const V3& d, LF tmax, LF* t_hit) {
  const V3 n = splat3(dk.normal), c = splat3(dk.center);
  const LF dn = dot(d, n);
  LI hit = dn != 0;
  const LF t = dot(c - o, n) / (hit ? dn : splat(1));
  const V3 off = (o + d * t) - c;
  *t_hit = t;
  return hit & (t > 0) & (t < tmax) & ~(dot(off, off) > splat(dk.radius * dk.radius));
}
inline LI intersect_direct(const DirectShape& s, const V3& o, const V3& d, LF tmax, LF* t_hit) {
  return s.type == ShapeType::Sphere ? intersect_sphere(s.sphere, o, d, tmax, t_hit)
                                     : intersect_disk(s.disk, o, d, tmax, t_hit);
}
/// The lanes set in `m` (a movemask), lowest first: for per-lane loops that skip dead
/// lanes without a branch per lane on their pattern.
inline int next_lane(int* bits) {
  const int k = __builtin_ctz(unsigned(*bits));
  *bits &= *bits - 1;
  return k;
}
/// The lanes set in `bits` as a mask.
inline LI mask_of(int bits) {
#if KAURI_LANES_AVX512
  return LI(_mm512_movm_epi32(__mmask16(bits)));
#else
  return ((LI{} + bits) & ((LI{} + 1) << lane_index())) != 0;
#endif
}
/// The lanes of `todo` (not empty) whose entry of `column` equals that of its lowest lane,
/// taken out of `todo`, and that value (*value): a per-lane choice (a light, a lobe) handled
/// one value at a time across the lanes.
inline LI take_equal_lanes(const int32_t* column, LI* todo, int* value) {
  *value = column[__builtin_ctz(unsigned(mask_bits(*todo)))];
  const LI m = *todo & (load(column) == *value);
  *todo &= ~m;
  return m;
}

/// The normal on the side of the surface `d` points to (spawn_ray, spawn_ray_to).
inline V3 side_normal(const V3& ng, const V3& d) { return select(dot(d, ng) < 0, -ng, ng); }
template <class T>
inline void put(void* dst, const T& v) {
  __builtin_memcpy(dst, &v, sizeof v);
}
}  // namespace path_lanes_detail

#include "kauri/integrator/path_lanes_env.inl"

namespace path_lanes_detail {
#include "kauri/integrator/path_lanes_conductor.inl"

/// Every live lane's EmissionCache started with light `l`'s emission at its wavelengths,
/// scale · s(λ) · I(λ) (an RGB illuminant spectrum: Spectrum::sample_other's expression, up
/// to rounding), across the lanes: one sigmoid and one illuminant lookup per wavelength for
/// the group instead of an out-of-line call per path. The light is the colour most of the
/// scene's triangle lights share (LaneTriangles::common_emission_light); a path that meets
/// another colour evaluates that one on its own, as before. Cornell box (callgrind): the
/// per-path evaluations were 1.7% of the render's instructions.
inline void prefill_emission(const Light& l, const BatchColumns& cols, int n, Paths* P) {
  alignas(kLaneBytes) float Le[kSpectrumSamples][W];
  for (int i = 0; i < kSpectrumSamples; ++i) store(rgb_illuminant_lanes(l.Le.rgb, load(cols.lambda[i])), Le[i]);
  for (int k = 0; k < n; ++k) {
    EmissionCache& c = P->emission[k];
    c.id = l.emission_id;
    for (int i = 0; i < kSpectrumSamples; ++i) c.Le[i] = Le[i][k];
  }
}

/// escaped_radiance_of for constant environment `l` (light `li`, radiance Le at the lanes'
/// wavelengths) over the lanes in `m`, whose paths have bounced: its density (uniform on
/// the sphere, the same in every direction) and the light's choice probability (an
/// infinite light's: the power distribution's, wherever the path was) make one MIS
/// weight but after a specular bounce; β · Le · w_MIS added to the paths as emission
/// (Paths::add). Lane by lane this was ~2.5% of the glossy scene's render.
inline void add_constant_escaped(const SceneView& s, const IntegratorSettings& cfg, const Light& l, int li,
                                 const LF* Le, LI m, Paths& P) {
  const Float p_light = s.light_pmf(li, Point3{}, Normal3{}, cfg.light_tree) *
                        light_pdf(l, Point3{}, Vec3{0, 0, 1}, Point3{}, Normal3{}, kNextEventDensity);
  const LF w_mis = load(P.specular) ? splat(1) : power_heuristic(load(P.prev_pdf), splat(p_light));
  const LI direct = load(P.depth) <= 1;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const LF add = m ? load(P.beta.v[i]) * Le[i] * w_mis : LF{};
    store(load(P.L_direct.v[i]) + (direct ? add : LF{}), P.L_direct.v[i]);
    store(load(P.L.v[i]) + (direct ? LF{} : add), P.L.v[i]);
  }
}

/// The per-lane part of lane k's kLaneConductor, kLaneDielectric or kLaneSpecular vertex:
/// the lobe as build_single_lobe makes it (η, κ and F_ms, or η and the compensation's
/// terms, at the lane's wavelengths) into the columns `out` (ConductorVertices,
/// DielectricVertices, SpecularVertices), and its albedo times w_b (BSDF::albedo) where the
/// albedo output asks for it (`aov`). Out of line: the Lambert vertices keep their registers.
template <class Columns>
__attribute__((noinline)) SampledSpectrum lobe_lane(const SceneView& s, const LobeParams& lobe, Float w_b,
                                                    const Vertices& V, int k, const SampledWavelengths& lambda,
                                                    bool aov, Columns* out) {
  const Float no_attrs[kMaxVertexAttributes] = {0, 0, 0, 0};
  const ShadingInputs sp(no_attrs, Vec2{V.uv[0][k], V.uv[1][k]}, s.textures);
  Lobe l = material_detail::instantiate(lobe, sp, lambda);
  // A rough conductor's F_ms (a mirror's is never read: the specular lanes skip its quadrature).
  if (l.type == LobeType::GGXConductor && !std::is_same_v<Columns, SpecularVertices>) l.conductor.cache_multiple_scattering();
  out->set(k, l, w_b, int(&lobe - s.lobes));
  if (!aov) return SampledSpectrum(0);
  const Vec3 wo = Frame::from_zx(V.ns.get(k), V.dpdu.get(k)).to_local(V.wo.get(k));
  return (l.albedo_r(wo) + l.albedo_t(wo)) * w_b;  // BSDF::albedo of the lone lobe (transmission weight 1)
}
}  // namespace path_lanes_detail

namespace path_lanes_detail {

/// Live lanes at least for a group to run kLaneBsdf vertices itself. Lane by lane, a BSDF
/// vertex costs what trace_path's does, and the path's later rays join the group's
/// packets; but a group left with a few long paths (glossy and specular bounces escape
/// roulette) runs whole vector bounces for them, where trace_path, handed the path, runs
/// one. Glossy bench scene, one thread, against every such path handed over at its first
/// BSDF vertex (non-PGO builds, 96 × 96, 32 spp): none handed over 1.06× the time, those of
/// groups of 2 or fewer live lanes 1.00×, 4 or fewer 0.977×, 6 or fewer 0.977×.
inline constexpr int kBsdfLanesMin = W / 2 + 1;
/// Live lanes at least for a group to run its conductor, dielectric and specular vertices
/// across the lanes. Their vector stages cost the same for one live lane as for sixteen,
/// and a glass sphere's paths outlive the group's others (refraction and total internal
/// reflection escape roulette): the glossy bench scene (one core, 16 lanes, v4 core
/// without profile, 16 alternations, the time against running every such vertex in the
/// lanes) took 0.938× handing a group's last path over to trace_path, 0.927× at 2 or
/// fewer live lanes, **0.920×** at 3 or fewer, 0.929× at 4, 0.951× at 8, 0.988× at 12 and
/// 1.25× handing every such path over. W / 4 is that optimum at 16 lanes; the 8-lane core
/// takes it at 2 (not measured there).
inline constexpr int kVectorLobeLanesMin = W / 4;
/// Live lanes at least for a group to run its Lambert vertices across the lanes: a group's
/// last live path goes on in trace_path. Environment scene 0.942× the time (one core, 16
/// lanes, 40 alternations, quartiles 0.928–0.953; its paths escape early and leave one
/// lane running the vector stages and the environment's lookups), Cornell box 0.983×
/// (quartiles 0.93–1.06, noise); at 2 or fewer live lanes the Cornell box read 1.018×,
/// and at 8 lanes (callgrind) 1.05× the instructions.
inline constexpr int kLambertLanesMin = 2;
/// Whether a path at a vertex of kind `lm` (a surface with a material) goes on in
/// trace_path, the group having `live` live lanes.
inline bool handed_over(uint8_t lm, int live) {
  return lm == kHandOver || live < kLambertLanesMin || (lm == kLaneBsdf && live < kBsdfLanesMin) ||
         ((lm == kLaneConductor || lm == kLaneDielectric || lm == kLaneSpecular) && live < kVectorLobeLanesMin);
}

/// trace_path's vertex for lane k at the surface in `V`, of material `mat` (kLaneBsdf): the
/// BSDF built, the albedo output, next-event estimation up to its shadow ray
/// (direct_sample) and the BSDF sample with the path's next state (continue_path), into
/// `G`; the shadow ray is tested in the group's packet and `G->next` taken after the
/// bounce's estimates are added. `u`: the bounce's three pairs, `lc`: its light choice.
/// False: the path ends at this vertex without scattering (a bounce budget is spent).
/// Out of line: the Lambert vertices keep their registers.
__attribute__((noinline)) inline bool bsdf_vertex(const SceneView& s, const IntegratorSettings& cfg,
                                                  const MaterialView& mat, const Vertices& V, int k,
                                                  SampledWavelengths& lambda, const Vec2 u[3],
                                                  const path_detail::LightChoice& lc, bool scatters, Paths* P,
                                                  PathOutput* out, BsdfVertices* G) {
  const Point3 p = V.p.get(k);
  const Normal3 ng = V.ng.get(k);
  const Vec3 wo = V.wo.get(k);
  const Frame frame = Frame::from_zx(V.ns.get(k), V.dpdu.get(k));
  const Float no_attrs[kMaxVertexAttributes] = {0, 0, 0, 0};  // kHandOver: materials that read them
  BSDF bsdf;
  build_bsdf(mat, s.lobes, s.node_weights, ShadingInputs(no_attrs, Vec2{V.uv[0][k], V.uv[1][k]}, s.textures), frame,
             ng, wo, lambda, &bsdf);
  if (cfg.albedo_aov && !out->albedo_set && (bsdf.has_non_specular() || P->depth[k] + 1 >= cfg.max_depth)) {
    out->albedo = bsdf.albedo(frame.to_local(wo));
    out->albedo_set = true;
  }
  if (!scatters) return false;
  path_detail::DirectSample ds;
  G->nee[k] = 0;
  if (bsdf.has_non_specular() && path_detail::direct_sample(s, p, ng, bsdf, wo, lambda, lc, &P->emission[k], &ds)) {
    G->nee[k] = -1;
    G->c.set(k, ds.c);
    G->shadow_o.set(k, ds.shadow.o);
    G->shadow_d.set(k, ds.shadow.d);
    G->shadow_tmax[k] = ds.shadow.tmax;
  }
  const BSDFSample bs = bsdf.sample(wo, u[1].x, u[2], lambda, TransportMode::Radiance);
  PathState st = P->state(k);
  G->alive[k] = path_detail::continue_path(cfg, bs, p, frame.z, u[1].y, &st) ? -1 : 0;
  G->next.set_state(k, st);
  G->wi.set(k, bs.wi);
  return true;
}
}  // namespace path_lanes_detail

/// trace_path() for the n ≤ kPathLanes paths of a group, in vector lanes: camera rays and
/// wavelengths in `cols` (entries 0 … n − 1; the wavelengths also in `lambda`), samplers
/// (left at the dimension trace_path leaves each) and outputs as trace_path's, except the
/// radiance sums, which go to cols.L and cols.L_direct (entries ≥ n to ignore; `outs`' own
/// L and L_direct_first hold only what handed-over paths gathered in trace_path). The
/// lanes find the camera rays' hits themselves, as one packet of their width with Embree's
/// coherent context; before, the render loop sent them to Embree 8 at a
/// time and converted the hits to HitRecords and back into the lanes (callgrind, 8 lanes:
/// Cornell box −4.1%, environment −7.6% instructions). The scene must be
/// path_lanes_supported(), `tris` its build_lane_triangles(), and `accel` without direct
/// shapes.
template <class Accel>
void trace_paths_lanes(const SceneView& s, const LaneTriangles& tris, const Accel& accel, const IntegratorSettings& cfg,
                       BatchColumns& cols, SampledWavelengths* lambda, Sampler* samplers, PathOutput* outs, int n) {
  using namespace path_lanes_detail;
  Paths P;
  Vertices V{};
  BsdfVertices G;
  ConductorVertices C;    // read only in the lanes of V.conductor
  DielectricVertices Dv;  // and of V.dielectric
  Dv.terms = tris.dielectric_ms;
  SpecularVertices S;     // and of V.specular
  // A camera path's PathState, in every lane (whole columns at once).
  store(lane_index() < n, P.alive);
  for (int32_t* c : {P.depth, P.diffuse_depth, P.glossy_depth, P.transmission_depth, P.last_segment, P.specular,
                     P.any_non_specular})
    store(LI{}, c);
  store(LF{}, P.prev_pdf), store(splat(1), P.eta_scale);
  P.prev_p.store(V3{}), P.prev_n.store(V3{});
  for (int i = 0; i < kSpectrumSamples; ++i)
    store(splat(1), P.beta.v[i]), store(LF{}, P.L.v[i]), store(LF{}, P.L_direct.v[i]);
  if (tris.common_emission_light >= 0) prefill_emission(s.lights[tris.common_emission_light], cols, n, &P);
  static_assert(W <= kBatchColumns, "a group's camera rays are columns of the batch");
  V3 o{load(cols.o[0]), load(cols.o[1]), load(cols.o[2])}, d{load(cols.d[0]), load(cols.d[1]), load(cols.d[2])};
  const LF camera_tmax = load(cols.tmax);
  LI ray_count{};
  int handed = 0;  // the lanes whose paths went on in trace_path
  alignas(kLaneBytes) RTCRayHitW rh;
  alignas(kLaneBytes) RTCRayW shadow;
  // The packets' fields that stay the same: Embree writes a query's tfar and hit only.
  for (RTCRayW* r : {&rh.ray, &shadow}) {
    put(r->tnear, LF{}), put(r->time, LF{});
    put(r->mask, ~LI{}), put(r->id, LI{}), put(r->flags, LI{});
  }
  alignas(kLaneBytes) int32_t valid[W];
  LaneSpectra spectra;  // the wavelengths and illuminant as columns, for environment images
  const bool tree = cfg.light_tree && s.light_tree.n_nodes > 0;  // choose_light reads the point and normal
  const size_t n_direct = accel.direct_shape_count();
  const DirectShape* direct_shapes = accel.direct_shapes();
  for (bool camera = true;; camera = false) {  // the camera rays first, with Embree's coherent context
    LI alive = load(P.alive);
    LI geom, prim;  // the bounce's closest hits (the camera rays' on the first pass)
    LF t, hu, hv;
    V3 sphere_c{};     // where a lane's closest hit is a direct shape that is a sphere (−1 in
    LF sphere_r{};     // direct_sphere), its centre and radius
    LI direct_sphere{};
    {  // its rays' queries; what they leave behind stays in this scope
      put(rh.ray.org_x, o.x), put(rh.ray.org_y, o.y), put(rh.ray.org_z, o.z);
      put(rh.ray.dir_x, d.x), put(rh.ray.dir_y, d.y), put(rh.ray.dir_z, d.z);
      // The direct shapes first, across the lanes, as EmbreeAccel::intersect: a hit
      // shortens the ray Embree traverses. `direct_geom`: the nearest one's geometry id.
      LF tmax = camera ? camera_tmax : splat(kInfinity);
      LI direct_geom = ~LI{};
      for (size_t i = 0; i < n_direct; ++i) {
        LF ti;
        const LI h = alive & intersect_direct(direct_shapes[i], o, d, tmax, &ti);
        tmax = h ? ti : tmax;
        direct_geom = h ? LI{} + int32_t(direct_shapes[i].geom) : direct_geom;
        const bool sphere = direct_shapes[i].type == ShapeType::Sphere;
        direct_sphere = h ? LI{} - int32_t(sphere) : direct_sphere;
        if (sphere) {
          sphere_c = select(h, splat3(direct_shapes[i].sphere.center), sphere_c);
          sphere_r = h ? splat(direct_shapes[i].sphere.radius) : sphere_r;
        }
      }
      put(rh.ray.tfar, tmax);
      put(rh.hit.geomID, ~LI{}), put(rh.hit.instID[0], ~LI{});
      store(alive, valid);
      accel.intersect_lanes(valid, &rh, camera);
      geom = load(reinterpret_cast<const int32_t*>(rh.hit.geomID));
      prim = load(reinterpret_cast<const int32_t*>(rh.hit.primID));
      t = load(rh.ray.tfar), hu = load(rh.hit.u), hv = load(rh.hit.v);
      if (n_direct) {  // Embree missed, a direct shape was met: its hit (EmbreeAccel::direct_hit)
        const LI take = alive & (geom == -1) & (direct_geom >= 0);
        direct_sphere &= take;
        geom = take ? direct_geom : geom, prim = take ? LI{} : prim;
        t = take ? tmax : t, hu = take ? LF{} : hu, hv = take ? LF{} : hv;
      }
    }
    // The hit shapes' rows (LaneShapeRow; lanes without a hit read row 0).
    LF shape_row[8];
    load_columns(tris.shapes, (alive & (geom >= 0)) ? geom : LI{}, 0, shape_row);
    const LI shape_first = (LI)shape_row[0], shape_material = (LI)shape_row[2];
    const LI shape_light = (LI)shape_row[3], shape_has_n = (LI)shape_row[4];
    if (tris.any_quads) {  // a quad's hit as its triangle's (EmbreeAccel::quad_hit)
      const LI quad = alive & (geom >= 0) & (LI)shape_row[1];
      const LI second = quad & (hu + hv > 1);
      prim = quad ? prim + prim + (second & 1) : prim;
      const LF qu = second ? 1 - hv : 1 - hu - hv, qv = second ? hu + hv - 1 : hu;
      hu = quad ? qu : hu, hv = quad ? qv : hv;
    }
    ray_count += alive & 1;
    const LI escaped = alive & (geom == -1);
    if (s.n_infinite_lights > 0 && any(escaped)) {
      // The infinite lights as trace_path's escaped_radiance: an environment image across
      // the lanes for the paths that have bounced, the rest lane by lane.
      const LI bounced = escaped & (load(P.depth) > 0);
      for (int i = 0; i < s.n_infinite_lights; ++i) {
        const int li = s.infinite_lights[i];
        const Light& l = s.lights[li];
        const bool image = l.type == LightType::EnvMap;
        if (image && any(escaped & ~bounced)) add_env_seen_directly(l, d, escaped & ~bounced, outs);
        const LF* Le_constant = l.type == LightType::EnvConstant && any(bounced)
                                    ? spectra.constant_environment(l, li, cols) : nullptr;
        if (Le_constant) add_constant_escaped(s, cfg, l, li, Le_constant, bounced, P);
        // The rest lane by lane: the camera rays (add_seen_directly), and the paths that
        // escape into another kind of infinite light.
        for (int bits = mask_bits(image ? LI{} : Le_constant ? escaped & ~bounced : escaped); bits;) {
          const int k = next_lane(&bits);
          P.add(k, path_detail::escaped_radiance_of(s, cfg, P.state(k), li, lane(d, k), lambda[k], &outs[k].rgb_exact),
                ContributionKind::Emission);
        }
        if (image && any(bounced)) {
          if (!spectra.ready) spectra.prepare(cols, l.illuminant);
          add_env_escaped(s, l, li, tris.env[li], d, spectra, bounced, P);
        }
      }
    }
    alive &= ~escaped;  // an escaped path ends
    store(alive, P.alive);
    if (!any(alive)) break;

    // The surface at the hits (triangle_hit), across the lanes; spheres and disks lane by
    // lane below.
    const LI mesh = alive & (shape_first >= 0);
    const LI tri = mesh ? shape_first + prim : LI{};
    const LF w = 1 - hu - hv;
    LF row[16];  // LaneTriangleRow
    load_columns(tris.triangles, tri, 0, row);
    load_columns(tris.triangles, tri, 1, row + 8);
    const V3 p0{row[0], row[1], row[2]}, p1{row[3], row[4], row[5]}, p2{row[6], row[7], row[8]};
    V3 p = p0 * w + p1 * hu + p2 * hv;
    V3 ng{row[9], row[10], row[11]};
    V3 ns = ng;
    V3 dpdu{row[12], row[13], row[14]};
    LF uv[2] = {};
    if (tris.uv) {  // scenes without textures skip the uv rows
      LF r[8];
      load_columns(tris.uv, tri, 0, r);
      for (int a = 0; a < 2; ++a) uv[a] = r[a] * w + r[2 + a] * hu + r[4 + a] * hv;
    }
    const LI has_n = shape_has_n & mesh;
    if (any(has_n)) {
      LF r[16];
      load_columns(tris.normals, tri, 0, r);
      load_columns(tris.normals, tri, 1, r + 8);
      const V3 nv = V3{r[0], r[1], r[2]} * w + V3{r[3], r[4], r[5]} * hu + V3{r[6], r[7], r[8]} * hv;
      const LF l2 = dot(nv, nv);
      const V3 nn = nv * (1 / vsqrt(l2 > 0 ? l2 : splat(1)));
      ns = select(has_n & (l2 > 0), select(dot(nn, ng) < 0, -nn, nn), ng);
    }
    const V3 wo = -d;
    alignas(kLaneBytes) int32_t material[W], light[W];
    store(mesh ? shape_material : ~LI{}, material);
    store((mesh & (shape_light >= 0)) ? shape_light + prim : ~LI{}, light);
    V.p.store(p), V.ng.store(ng), V.ns.store(ns), V.wo.store(wo), V.dpdu.store(dpdu);
    store(uv[0], V.uv[0]), store(uv[1], V.uv[1]);
    // A group down to half its lanes or fewer hands its paths over at kLaneBsdf vertices
    // (kBsdfLanesMin), one down to a quarter at its vector lobes' too (kVectorLobeLanesMin),
    // and its last path at any surface (kLambertLanesMin).
    const int live = __builtin_popcount(unsigned(mask_bits(alive)));
    const LI analytic = alive & ~mesh;
    if (any(analytic)) {  // compute_surface_hit lane by lane, but a sphere's across the lanes
      int sphere_lanes = 0;
      for (int bits = mask_bits(analytic); bits;) {
        const int k = next_lane(&bits);
        const int m = shape_material[k];
        if (m >= 0 && handed_over(tris.lane_material[m], live)) {
          material[k] = m, light[k] = -1;  // handed over below, where trace_path finds its surface
          continue;
        }
        if (direct_sphere[k] && !(m >= 0 && s.materials[m].reads_uv)) {  // sphere_hit without uv, below
          material[k] = m, light[k] = shape_light[k];
          sphere_lanes |= 1 << k;
          continue;
        }
        HitRecord h;
        h.t = t[k], h.u = hu[k], h.v = hv[k], h.geom = uint32_t(geom[k]), h.prim = uint32_t(prim[k]);
        const SurfaceHit sh = compute_surface_hit(s, Ray{lane(o, k), lane(d, k), kInfinity}, h);
        V.p.set(k, sh.p), V.ng.set(k, sh.ng), V.ns.set(k, sh.ns), V.dpdu.set(k, sh.dpdu);
        V.uv[0][k] = sh.uv.x, V.uv[1][k] = sh.uv.y;
        material[k] = sh.material, light[k] = sh.light;
      }
      p = V.p.load(), ng = V.ng.load(), ns = V.ns.load(), dpdu = V.dpdu.load();
      if (sphere_lanes) {  // sphere_hit's steps: the normal at o + t d, the point re-projected onto the sphere
        const LI m = mask_of(sphere_lanes);
        const V3 n = normalize((o + d * t) - sphere_c);
        const LI flat = (n.y * n.y + n.x * n.x) == 0;  // ∂p/∂u = (−n.y, n.x, 0), or (1, 0, 0) where its length² is 0
        p = select(m, sphere_c + n * sphere_r, p);
        ng = select(m, n, ng), ns = select(m, n, ns);
        dpdu = select(m, V3{flat ? splat(1) : -n.y, flat ? LF{} : n.x, LF{}}, dpdu);
        V.p.store(p), V.ng.store(ng), V.ns.store(ns), V.dpdu.store(dpdu);
      }
    }

    // Per lane: emission, the light choice, the BSDF's albedo, the sampler's values.
    store(LI{}, V.scatter), store(LI{}, V.conductor), store(LI{}, V.dielectric), store(LI{}, V.specular);
    store(LI{}, V.nee), store(LI{}, V.env);
    store(LI{}, G.active), store(LI{}, G.nee);
    // Next-event estimation's light for lane k (chosen by `lc`): a triangle's row and
    // point and an image's direction are taken across the lanes below.
    auto nee_light = [&](int k, const path_detail::LightChoice& lc) {
      if (!(lc.light >= 0 && lc.pmf > 0)) return;
      const Light& l = s.lights[lc.light];
      V.nee[k] = -1;
      V.light_pmf[k] = lc.pmf;
      if (l.type == LightType::Triangle) {  // its row and its point across the lanes below
        V.light_dir[k] = V.light_delta[k] = 0;
        V.u_light[0][k] = lc.u.x, V.u_light[1][k] = lc.u.y;
        V.light_index[k] = lc.light;
        V.Le.set(k, light_emission(l, lambda[k], &P.emission[k]));
      } else if (l.type == LightType::EnvMap) {  // its direction across the lanes below
        V.light_dir[k] = V.env[k] = -1;
        V.light_delta[k] = 0;
        V.u_light[0][k] = lc.u.x, V.u_light[1][k] = lc.u.y;
        V.light_index[k] = lc.light;
      } else if (const LF* Le_c = l.type == LightType::EnvConstant && has_light_density(l, kNextEventDensity)
                                      ? spectra.constant_environment(l, lc.light, cols) : nullptr) {
        // sample_light of a constant environment, its radiance from the group's columns
        V.light_dir[k] = -1;
        V.light_delta[k] = 0;
        V.light_index[k] = 0;
        V.light_wi.set(k, sample_uniform_sphere(lc.u));
        V.light_pdf[k] = uniform_sphere_pdf();
        V.Le.set(k, lane_spectrum(Le_c, k));
      } else {  // another infinite light (path_lanes_supported): a direction, sampled here
        const LightSample ls = sample_light(l, V.p.get(k), lc.u, lambda[k], kNextEventDensity, &P.emission[k]);
        V.light_dir[k] = -1;
        V.light_delta[k] = ls.delta ? -1 : 0;
        V.light_index[k] = 0;
        V.light_wi.set(k, ls.wi);
        V.light_pdf[k] = ls.pdf;
        V.Le.set(k, ls.L);
      }
    };
    // The lanes whose light the tree chooses after this loop, and their samples for it.
    int tree_lanes[W], n_tree_lanes = 0;
    // The conductor lobe whose columns each lane takes across the lanes after it (−1: none).
    alignas(kLaneBytes) int32_t conductor_lobe[W];
    store(~LI{}, conductor_lobe);
    Vec2 tree_u[W];
    for (int bits = mask_bits(alive); bits;) {
      const int k = next_lane(&bits);
      PathOutput& out = outs[k];
      const int hmat = material[k], hlight = light[k];
      const LaneMaterial lm = hmat >= 0 ? LaneMaterial(tris.lane_material[hmat]) : kLaneLambert;
      if (hmat >= 0 && handed_over(lm, live)) {  // hand the path over
        HitRecord h;
        h.t = t[k], h.u = hu[k], h.v = hv[k], h.geom = uint32_t(geom[k]), h.prim = uint32_t(prim[k]);
        const PathState st = P.state(k);
        trace_path(s, accel, cfg, Ray{lane(o, k), lane(d, k), kInfinity}, lambda[k], samplers[k], &out, &h, true, &st);
        --out.rays;  // the ray to this hit is in the lane's count
        handed |= 1 << k;
        P.alive[k] = 0;
        continue;
      }
      const bool scatters = hmat >= 0 && P.depth[k] < cfg.max_depth && !P.last_segment[k];
      // The bounce's pairs at once: the light choice's, the lobe and roulette's, the
      // direction's (get_2d_n). trace_path draws all three wherever the vertex scatters,
      // at a BSDF without lobes too (its sample then fails).
      Vec2 u[3];
      if (scatters) samplers[k].get_2d_n(u, 3);
      // The light tree weighs the lights by the point and its normal, for the group's lanes
      // together after this loop (tree_lanes), except at a BSDF lane, which reads its
      // choice here. The power distribution reads neither, and the lane's values stay in
      // their vectors.
      const bool tree_later = tree && lm != kLaneBsdf;
      path_detail::LightChoice lc;
      if (scatters && !tree_later)
        lc = path_detail::choose_light(s, cfg, tree ? V.p.get(k) : Point3{}, tree ? V.ns.get(k) : Normal3{}, u[0]);
      if (P.depth[k] == 0) {
        out.hit = true;
        out.normal = V.ns.get(k);
        out.depth = t[k] * kauri::dot(-V.wo.get(k), s.camera_forward);
      }
      if (hlight >= 0) {
        const Normal3 hng = V.ng.get(k);
        const Vec3 hwo = V.wo.get(k);
        if (!(P.depth[k] == 0 && path_detail::add_area_seen_directly(s.lights[hlight], hng, hwo, &out.rgb_exact))) {
          const Light& l = s.lights[hlight];
          const SampledSpectrum Le = area_light_L(l, hng, hwo, lambda[k], &P.emission[k]);
          if (!Le.is_black()) {
            const PathState st = P.state(k);
            const Float wm = path_detail::emitter_mis_weight(s, cfg, st, hlight, -hwo, V.p.get(k), hng);
            P.add(k, st.beta * Le * wm, ContributionKind::Emission);
          }
        }
      }
      if (hmat < 0) {  // pure emitter: black surface
        P.alive[k] = 0;
        continue;
      }
      const MaterialView& mat = s.materials[hmat];
      if (lm == kLaneBsdf) {  // its BSDF lane by lane
        if (bsdf_vertex(s, cfg, mat, V, k, lambda[k], u, lc, scatters, &P, &out, &G)) G.active[k] = -1;
        else P.alive[k] = 0;
        continue;
      }
      const LobeParams& lobe = s.lobes[mat.first_lobe];
      const Float w_b = clamp(s.node_weights[mat.first_weight].value, 0, 1);
      // build_single_lobe's albedo: the texture's at the hit's uv, or the lobe's own.
      auto albedo = [&] {
        return (lobe.a_texture < 0 ? lobe.a.sample(lambda[k])
                                   : s.textures[lobe.a_texture].albedo(Vec2{V.uv[0][k], V.uv[1][k]}, lambda[k])) *
               w_b;
      };
      const bool conductor = lm == kLaneConductor, dielectric = lm == kLaneDielectric, specular = lm == kLaneSpecular;
      // The albedo output takes the first vertex with a non-specular lobe (or the last).
      const bool aov = cfg.albedo_aov && !out.albedo_set &&
                       ((w_b > 0 && !specular) || P.depth[k] + 1 >= cfg.max_depth);
      SampledSpectrum a(0);
      if (w_b > 0 && (aov || scatters)) {
        if (conductor && !aov && conductor_columns_apply(lobe)) {  // its columns across the lanes below
          conductor_lobe[k] = mat.first_lobe;
          C.w_b[k] = w_b;
        } else {
          a = conductor    ? lobe_lane(s, lobe, w_b, V, k, lambda[k], aov, &C)
              : dielectric ? lobe_lane(s, lobe, w_b, V, k, lambda[k], aov, &Dv)
              : specular   ? lobe_lane(s, lobe, w_b, V, k, lambda[k], aov, &S)
                           : albedo();
        }
      }
      if (aov) {
        out.albedo = a;
        out.albedo_set = true;
      }
      if (!scatters || !(w_b > 0)) {  // a budget is spent, or a BSDF without lobes
        P.alive[k] = 0;
        continue;
      }
      V.scatter[k] = -1;
      if (conductor || dielectric || specular) {
        (conductor ? V.conductor : dielectric ? V.dielectric : V.specular)[k] = -1;
        V.u_lobe[k] = u[1].x;
      } else {
        V.albedo.set(k, a);
      }
      if (specular) {  // a delta lobe: no next-event estimate (trace_path's has_non_specular)
        V.u_rr[k] = u[1].y;
        continue;
      }
      if (tree_later) {
        tree_lanes[n_tree_lanes++] = k;
        tree_u[k] = u[0];
      } else {
        nee_light(k, lc);
      }
      V.u_rr[k] = u[1].y;
      V.u_bsdf[0][k] = u[2].x, V.u_bsdf[1][k] = u[2].y;
    }
    if (n_tree_lanes > 0) {  // choose_light's steps (`tree`: the scene has lights), the descents interleaved
      static_assert(W <= kLightTreeBatch, "a group's lanes fit one batch of the tree's descents");
      Float ux[W], pmf[W], u_remapped[W];
      Point3 lp[W];
      Normal3 lns[W];
      int chosen[W];
      for (int j = 0; j < n_tree_lanes; ++j) {
        const int k = tree_lanes[j];
        ux[j] = tree_u[k].x, lp[j] = V.p.get(k), lns[j] = V.ns.get(k);
      }
      s.select_lights_tree(n_tree_lanes, ux, lp, lns, chosen, pmf, u_remapped);
      for (int j = 0; j < n_tree_lanes; ++j) {
        const int k = tree_lanes[j];
        nee_light(k, path_detail::LightChoice{chosen[j], pmf[j], Vec2{u_remapped[j], tree_u[k].y}});
      }
    }
    for (LI todo = load(conductor_lobe) >= 0; any(todo);) {  // one lobe at a time
      int li;
      const LI m = take_equal_lanes(conductor_lobe, &todo, &li);
      conductor_columns(s.lobes[li], cols, m, &C);
    }
    const LI scatter = load(V.scatter), bsdf_lanes = load(G.active);
    if (!any(scatter | bsdf_lanes)) break;  // every path ended at this bounce

    // Across the lanes: the shading frame and ω_o in it.
    V3 fx, fy;
    shading_frames(ns, dpdu, &fx, &fy);
    const V3& fz = ns;
    const V3 wo_l{dot(wo, fx), dot(wo, fy), dot(wo, fz)};
    const LF wo_ng = dot(wo, ng);
    LF albedo[kSpectrumSamples];
    for (int i = 0; i < kSpectrumSamples; ++i) albedo[i] = load(V.albedo.v[i]) * kInvPi;
    // A direction's BSDF value is albedo/π where ω_o and ω_i are on one side of the surface
    // by both normals (BSDF::shading_normal_correction) and of the shading frame.
    auto lambert_mask = [&](const V3& wi, const V3& wi_l) {
      const LI same = wo_l.z * wi_l.z > 0;
      const LI geo = wo_ng * dot(wi, ng) > 0;
      return same & ~(same ^ geo) & (wo_l.z != 0);
    };
    // shading_normal_correction: ω_o, ω_i on one side by the geometric normal as by the
    // shading frame (both reflection, or both not).
    auto same_side = [&](const V3& wi, const V3& wi_l) {
      return ~((wo_l.z * wi_l.z > 0) ^ (wo_ng * dot(wi, ng) > 0));
    };
    const LI conductor_lanes = load(V.conductor), dielectric_lanes = load(V.dielectric);
    const LI specular_lanes = load(V.specular);

    // Next-event estimation (sample_direct): a point on the chosen triangle, or the
    // direction an infinite light's sample took.
    if (any(load(V.env))) sample_env_lights(s, tris, cols, spectra, V);
    const LI nee = load(V.nee), bsdf_nee = load(G.nee) & bsdf_lanes;
    if (any(nee | bsdf_nee)) {
      const LI dir = nee & load(V.light_dir);
      const LF ux = load(V.u_light[0]), uy = load(V.u_light[1]);
      const LI lower = ux < uy;
      const LF h = (lower ? ux : uy) / 2;
      const LF b0 = lower ? h : ux - h, b1 = lower ? uy - h : h;
      LF lr[16];  // LaneLightRow
      const LI light_row = (nee & ~dir) ? load(V.light_index) : LI{};
      load_columns(tris.lights, light_row, 0, lr);
      load_columns(tris.lights, light_row, 1, lr + 8);
      const V3 pl = V3{lr[0], lr[1], lr[2]} * b0 + V3{lr[3], lr[4], lr[5]} * b1 + V3{lr[6], lr[7], lr[8]} * (1 - b0 - b1);
      const V3 nl{lr[9], lr[10], lr[11]};
      const V3 dl = pl - p;
      const LF d2 = dot(dl, dl);
      const V3 wi_tri = dl * (1 / vsqrt(d2 > 0 ? d2 : splat(1)));
      const LF nd = vabs(dot(nl, dl));
      const LF pdf_tri = nd > 0 ? lr[12] * (d2 / (nd > 0 ? nd : splat(1))) * vsqrt(d2) : LF{};
      const V3 wi = select(dir, V.light_wi.load(), wi_tri);
      const LF pdf_l = dir ? load(V.light_pdf) : pdf_tri;
      const LI emits = dir | (LI)lr[13] | (dot(nl, -wi) > 0);
      const V3 wi_l{dot(wi, fx), dot(wi, fy), dot(wi, fz)};
      const LI reflects = lambert_mask(wi, wi_l);
      LF pdf_b = (wo_l.z * wi_l.z > 0) ? vabs(wi_l.z) * kInvPi : LF{};
      const LF cos_i = vabs(dot(wi, fz));
      LF f_nee[kSpectrumSamples];  // f |cos θ_i|
      for (int i = 0; i < kSpectrumSamples; ++i) f_nee[i] = reflects ? albedo[i] * cos_i : LF{};
      const LI nee_conductor = nee & conductor_lanes;
      if (any(nee_conductor)) {
        LF f_c[kSpectrumSamples], pdf_c;
        conductor_eval_pdf(C, wo_l, wi_l, nee_conductor, same_side(wi, wi_l), f_c, &pdf_c);
        pdf_b = nee_conductor ? pdf_c : pdf_b;
        for (int i = 0; i < kSpectrumSamples; ++i) f_nee[i] = nee_conductor ? f_c[i] * cos_i : f_nee[i];
      }
      const LI nee_dielectric = nee & dielectric_lanes;
      if (any(nee_dielectric)) {
        LF f_d, pdf_d;
        dielectric_eval_pdf(Dv, wo_l, wi_l, nee_dielectric, same_side(wi, wi_l), &f_d, &pdf_d);
        pdf_b = nee_dielectric ? pdf_d : pdf_b;
        for (int i = 0; i < kSpectrumSamples; ++i) f_nee[i] = nee_dielectric ? f_d * cos_i : f_nee[i];
      }
      const LF p_light = load(V.light_pmf) * pdf_l;
      const LF w_mis = (dir & load(V.light_delta)) ? splat(1) : power_heuristic(p_light, pdf_b);
      const LF wm = w_mis / (p_light > 0 ? p_light : splat(1));
      LI any_f{}, any_L{};
      LF c[kSpectrumSamples];
      for (int i = 0; i < kSpectrumSamples; ++i) {
        const LF f = f_nee[i];
        const LF Le = load(V.Le.v[i]);
        any_f |= f != 0;
        any_L |= Le != 0;
        c[i] = f * Le * wm;
      }
      if (any(bsdf_nee))
        for (int i = 0; i < kSpectrumSamples; ++i) c[i] = bsdf_nee ? load(G.c.v[i]) : c[i];
      const LI test = (nee & (dir | (d2 > 0)) & (pdf_l > 0) & emits & any_f & any_L) | bsdf_nee;
      if (any(test)) {
        ray_count += test & 1;
        // spawn_ray_to: from the offset origin to just short of the light point; spawn_ray
        // towards an infinite light. The BSDF lanes' rays as direct_sample spawned them.
        V3 so = offset_ray_origin(p, side_normal(ng, select(dir, wi, dl)));
        V3 sd = select(dir, wi, pl - so);
        LF stmax = dir ? splat(kInfinity) : splat(1 - 1e-4f);
        if (any(bsdf_nee)) {
          so = select(bsdf_nee, G.shadow_o.load(), so), sd = select(bsdf_nee, G.shadow_d.load(), sd);
          stmax = bsdf_nee ? load(G.shadow_tmax) : stmax;
        }
        put(shadow.org_x, so.x), put(shadow.org_y, so.y), put(shadow.org_z, so.z);
        put(shadow.dir_x, sd.x), put(shadow.dir_y, sd.y), put(shadow.dir_z, sd.z);
        put(shadow.tfar, stmax);
        // As EmbreeAccel::occluded: a direct shape answers first.
        LI unblocked = test;
        for (size_t i = 0; i < n_direct; ++i) {
          LF ti;
          unblocked &= ~intersect_direct(direct_shapes[i], so, sd, stmax, &ti);
        }
        store(unblocked, valid);
        accel.occluded_lanes(valid, &shadow);
        // Paths::add of β·c across the lanes: light reached from the first vertex is direct.
        const LI lit = load(valid) & (load(shadow.tfar) >= 0);
        const LI first_vertex = load(P.depth) == 0;
        for (int i = 0; i < kSpectrumSamples; ++i) {
          const LF add = lit ? load(P.beta.v[i]) * c[i] : LF{};
          store(load(P.L_direct.v[i]) + (first_vertex ? add : LF{}), P.L_direct.v[i]);
          store(load(P.L.v[i]) + (first_vertex ? LF{} : add), P.L.v[i]);
        }
      }
    }

    // The BSDF sample: a cosine-weighted direction on ω_o's side.
    const LF ux = load(V.u_bsdf[0]), uy = load(V.u_bsdf[1]);
    V3 wi_l = sample_cosine_hemisphere(ux, uy);
    wi_l.z = wo_l.z < 0 ? -wi_l.z : wi_l.z;
    LF pdf = vabs(wi_l.z) * kInvPi;
    V3 wi = fx * wi_l.x + fy * wi_l.y + fz * wi_l.z;
    const LI reflects = lambert_mask(wi, wi_l) & (pdf > 0);
    // A conductor's sample (GGXConductorLobe::sample), valued at its direction.
    const LI sample_conductor = scatter & conductor_lanes;
    LF f_sample[kSpectrumSamples];
    for (int i = 0; i < kSpectrumSamples; ++i) f_sample[i] = reflects ? albedo[i] : LF{};
    if (any(sample_conductor)) {
      LF f_c[kSpectrumSamples];
      V3 wc_l;
      const LI ok = conductor_sample(C, wo_l, load(V.u_lobe), ux, uy, sample_conductor, &wc_l);
      const V3 wc = fx * wc_l.x + fy * wc_l.y + fz * wc_l.z;
      LF pdf_c;
      conductor_eval_pdf(C, wo_l, wc_l, ok, same_side(wc, wc_l), f_c, &pdf_c);
      const LI valid = ok & (pdf_c > 0);
      for (int i = 0; i < kSpectrumSamples; ++i)
        f_sample[i] = sample_conductor ? (valid ? f_c[i] : LF{}) : f_sample[i];
      wi_l = select(sample_conductor, wc_l, wi_l), wi = select(sample_conductor, wc, wi);
      pdf = sample_conductor ? pdf_c : pdf;
    }
    // A rough dielectric's (RoughDielectricLobe::sample), likewise; a refraction scales η.
    const LI sample_dielectric = scatter & dielectric_lanes;
    LI refracted{};
    LF eta_scale = load(P.eta_scale);
    if (any(sample_dielectric)) {
      V3 wd_l;
      const LI ok = dielectric_sample(Dv, wo_l, load(V.u_lobe), ux, uy, sample_dielectric, &wd_l, &refracted);
      const V3 wd = fx * wd_l.x + fy * wd_l.y + fz * wd_l.z;
      LF f_d, pdf_d;
      dielectric_eval_pdf(Dv, wo_l, wd_l, ok, same_side(wd, wd_l), &f_d, &pdf_d);
      const LI valid = ok & (pdf_d > 0);
      for (int i = 0; i < kSpectrumSamples; ++i) f_sample[i] = sample_dielectric ? (valid ? f_d : LF{}) : f_sample[i];
      wi_l = select(sample_dielectric, wd_l, wi_l), wi = select(sample_dielectric, wd, wi);
      pdf = sample_dielectric ? pdf_d : pdf;
      // s.eta = e (relative_eta) for a refraction; eta_scale *= e² once the path goes on.
      const LF eta = load(Dv.eta), e = wo_l.z > 0 ? eta : 1 / eta;
      refracted &= valid;
      eta_scale = refracted ? eta_scale * (e * e) : eta_scale;
    }
    // A mirror's or smooth glass's (the specular lanes'), likewise.
    const LI sample_specular = scatter & specular_lanes;
    if (any(sample_specular)) {
      V3 ws_l;
      LF f_s[kSpectrumSamples], pdf_s, eta_s;
      LI refr;
      const LI ok = specular_sample(S, wo_l, load(V.u_lobe), sample_specular, &ws_l, f_s, &pdf_s, &refr, &eta_s);
      const V3 ws = fx * ws_l.x + fy * ws_l.y + fz * ws_l.z;
      const LI valid = ok & same_side(ws, ws_l);
      for (int i = 0; i < kSpectrumSamples; ++i) f_sample[i] = sample_specular ? (valid ? f_s[i] : LF{}) : f_sample[i];
      wi_l = select(sample_specular, ws_l, wi_l), wi = select(sample_specular, ws, wi);
      pdf = sample_specular ? pdf_s : pdf;
      refr &= valid;
      refracted |= refr;
      eta_scale = refr ? eta_scale * (eta_s * eta_s) : eta_scale;
    }
    const LF cos_over_pdf = vabs(dot(wi, fz)) / (pdf > 0 ? pdf : splat(1));
    LF beta[kSpectrumSamples];
    LI any_f{};
    LF beta_max{};
    for (int i = 0; i < kSpectrumSamples; ++i) {
      const LF f = f_sample[i];
      any_f |= f != 0;
      beta[i] = load(P.beta.v[i]) * (f * cos_over_pdf);
      beta_max = i == 0 ? beta[i] : vmax(beta_max, beta[i]);
    }
    alive = scatter & any_f;
    // record_scatter of a diffuse (Lambert), glossy (a conductor's, a dielectric's
    // reflection) or transmission event, then Russian roulette (trace_path).
    const LI depth = load(P.depth) + (alive & 1);
    const LI glossy_event = (sample_conductor | sample_dielectric | sample_specular) & ~refracted;
    const LI diffuse = load(P.diffuse_depth) + (alive & ~(sample_conductor | sample_dielectric | sample_specular) & 1);
    const LI glossy = load(P.glossy_depth) + (alive & glossy_event & 1);
    const LI transmission = load(P.transmission_depth) + (alive & refracted & 1);
    const LI last = load(P.last_segment) | (alive & ~((diffuse <= cfg.max_diffuse) & (glossy <= cfg.max_glossy) &
                                                        (transmission <= cfg.max_transmission)));
    const LI roulette = alive & ~last & (diffuse >= cfg.rr_min_depth);
    eta_scale = alive ? eta_scale : load(P.eta_scale);
    const LF q = rr_survival(beta_max * eta_scale);  // refraction's scale removed
    alive &= ~(roulette & ~(load(V.u_rr) < q));
    const LF inv_q = roulette ? 1 / (q > 0 ? q : splat(1)) : splat(1);
    LI finite = ~LI{};
    for (int i = 0; i < kSpectrumSamples; ++i) {
      beta[i] = roulette ? beta[i] * inv_q : beta[i];
      finite &= vabs(beta[i]) < kInfinity;
      store(beta[i], P.beta.v[i]);
    }
    alive &= finite;
    store(alive, P.alive);
    store(depth, P.depth);
    store(diffuse, P.diffuse_depth);
    store(glossy, P.glossy_depth);
    store(transmission, P.transmission_depth);
    store(eta_scale, P.eta_scale);
    store(last, P.last_segment);
    store(alive & sample_specular, P.specular);
    store(load(P.any_non_specular) | (alive & ~sample_specular), P.any_non_specular);
    store(alive ? pdf : load(P.prev_pdf), P.prev_pdf);
    P.prev_p.store(p);
    P.prev_n.store(ns);
    V3 wi_next = wi;
    if (any(bsdf_lanes)) {  // the BSDF lanes' paths go on from their sampled states
      P.take(bsdf_lanes, G.next);
      store(bsdf_lanes ? load(G.alive) : alive, P.alive);
      wi_next = select(bsdf_lanes, G.wi.load(), wi);
    }
    // spawn_ray: the next ray leaves the offset origin on ω_i's side.
    o = offset_ray_origin(p, side_normal(ng, wi_next));
    d = wi_next;
  }
  alignas(kLaneBytes) int32_t ray_lane[W];
  store(ray_count, ray_lane);
  for (int k = 0; k < n; ++k) outs[k].rays += uint32_t(ray_lane[k]);
  for (int bits = handed; bits;) {  // what a handed-over path's trace_path gathered
    const int k = next_lane(&bits);
    P.L.set(k, P.L.get(k) + outs[k].L);
    P.L_direct.set(k, P.L_direct.get(k) + outs[k].L_direct_first);
  }
  for (int i = 0; i < kSpectrumSamples; ++i) {
    store(load(P.L.v[i]), cols.L[i]);
    store(load(P.L_direct.v[i]), cols.L_direct[i]);
  }
}
#endif

}  // namespace kauri
