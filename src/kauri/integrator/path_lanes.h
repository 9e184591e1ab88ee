// A pixel's group of camera paths traced together, one path per vector lane: the first
// stage of the vector integrator (docs/benchmarks.md, "Where kauri's time goes").
//
// trace_paths_lanes() takes the same inputs and gives the same outputs as calling
// trace_path() on each path of the group: the same sampler dimensions, the same estimators
// (next-event estimation with MIS, Russian roulette, bounce budgets), the same operations
// up to rounding (a reciprocal square root or a contracted multiply-add may differ in
// the last bit, and where such a bit decides a comparison two paths part ways; the
// images agree within noise, tests/cpp/test_path_lanes.cpp). What runs across the lanes
// is the arithmetic of a bounce: the shading frame, next-event estimation's light point,
// densities, BSDF value and MIS weight, the cosine-weighted BSDF sample, the throughput,
// roulette; the Embree queries go as packets of the live lanes' rays (rtcIntersect8,
// rtcOccluded8). Per lane, one by one: the hit's surface geometry, the light tree's
// choice, the sampler's values, emission found by a BSDF sample.
//
// It covers the scenes whose every vertex is this kind (path_lanes_supported): triangle
// meshes of the root group, materials of one untextured Lambert lobe, triangle area lights
// with their own emission, no environment. Other scenes take trace_path() one path at a
// time. Host CPU code (GCC/Clang vector types, AVX2); a CUDA build runs trace_path().
#pragma once

#include "kauri/core/lanes.h"
#include "kauri/integrator/path_tracer.h"

#define KAURI_PATH_LANES KAURI_LANES_AVX2

namespace kauri {

/// Paths a group traces together: one AVX2 vector of floats.
inline constexpr int kPathLanes = 8;

/// Whether every vertex a path of `s` can reach is of the kind trace_paths_lanes() runs
/// (see above), and the build has the vector types. Host code, once per render.
bool path_lanes_supported(const SceneView& s);

#if KAURI_PATH_LANES
namespace path_lanes_detail {
using lanes::F32x8;
using lanes::I32x8;
constexpr int W = kPathLanes;

struct V3 {
  F32x8 x, y, z;
};
inline F32x8 splat(Float v) { return F32x8{} + v; }
inline V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(const V3& a, F32x8 s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator-(const V3& a) { return {-a.x, -a.y, -a.z}; }
inline F32x8 dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline F32x8 vsqrt(F32x8 x) { return __builtin_ia32_sqrtps256(x); }
inline F32x8 vabs(F32x8 x) { return (F32x8)((I32x8)x & 0x7fffffff); }
inline F32x8 vmax(F32x8 a, F32x8 b) { return a > b ? a : b; }
inline F32x8 vmin(F32x8 a, F32x8 b) { return a < b ? a : b; }
inline V3 normalize(const V3& a) { return a * (1 / vsqrt(dot(a, a))); }
inline V3 select(I32x8 m, const V3& a, const V3& b) { return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z}; }
inline bool any(I32x8 m) { return _mm256_movemask_ps((__m256)m) != 0; }

/// A float array of W lanes as one vector and back.
inline F32x8 load(const float* a) {
  F32x8 v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
inline void store(F32x8 v, float* a) { __builtin_memcpy(a, &v, sizeof v); }
inline I32x8 load(const int32_t* a) {
  I32x8 v;
  __builtin_memcpy(&v, a, sizeof v);
  return v;
}
inline void store(I32x8 v, int32_t* a) { __builtin_memcpy(a, &v, sizeof v); }

/// Three float arrays (x, y, z) of W lanes.
struct V3Lanes {
  alignas(32) float x[W], y[W], z[W];
  void set(int k, Vec3 v) { x[k] = v.x, y[k] = v.y, z[k] = v.z; }
  Vec3 get(int k) const { return {x[k], y[k], z[k]}; }
  V3 load() const { return {path_lanes_detail::load(x), path_lanes_detail::load(y), path_lanes_detail::load(z)}; }
  void store(const V3& v) {
    path_lanes_detail::store(v.x, x), path_lanes_detail::store(v.y, y), path_lanes_detail::store(v.z, z);
  }
};
/// A spectrum per lane: wavelength i of every lane in v[i].
struct SpectrumLanes {
  alignas(32) float v[kSpectrumSamples][W];
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
inline void cos_sin_quarter(F32x8 phi, F32x8* c, F32x8* s) {
  const F32x8 x2 = phi * phi;
  *c = 1 + x2 * (-1.0f / 2 + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320 - x2 * (1.0f / 3628800)))));
  *s = phi * (1 + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880)))));
}

/// sample_cosine_hemisphere over lanes.
inline V3 sample_cosine_hemisphere(F32x8 ux, F32x8 uy) {
  const F32x8 a = 2 * ux - 1, b = 2 * uy - 1;
  const F32x8 abs_a = vabs(a), abs_b = vabs(b);
  const I32x8 wedge_a = abs_b < abs_a;
  const F32x8 r = wedge_a ? a : b, q = wedge_a ? b : a;
  const I32x8 centre = (a == 0) & (b == 0);
  F32x8 c, s;
  cos_sin_quarter(kPiOver4 * (q / (centre ? splat(1) : r)), &c, &s);
  const F32x8 dx = centre ? F32x8{} : r * (wedge_a ? c : s);
  const F32x8 dy = centre ? F32x8{} : r * (wedge_a ? s : c);
  const F32x8 rr = vmax(abs_a, abs_b);
  const F32x8 z2 = (1 - rr) * (1 + rr);
  return {dx, dy, vsqrt(z2 > 0 ? z2 : F32x8{})};
}

/// power_heuristic over lanes.
inline F32x8 power_heuristic(F32x8 pa, F32x8 pb) {
  const F32x8 a = pa * pa, b = pb * pb;
  const F32x8 s = a + b;
  const F32x8 w = s > 0 ? a / (s > 0 ? s : splat(1)) : F32x8{};
  return a < kInfinity ? w : splat(1);
}

/// path_detail::rr_survival over lanes (cbrt_unit's bit guess and two Newton steps).
inline F32x8 rr_survival(F32x8 beta_max) {
  const F32x8 x = vmax(beta_max, splat(1.17549435e-38f));
  F32x8 y = (F32x8)((I32x8)((lanes::U32x8)x / 3u + 709921077u));
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  y = vmin(y, splat(1));
  return beta_max > 0 ? (beta_max >= 1 ? splat(1) : y) : F32x8{};
}

/// The shading frame Frame::from_zx(n, dpdu) over lanes; lanes whose tangent degenerates
/// take Frame::from_z one by one.
inline void shading_frames(const V3& n, const V3& dpdu, V3* fx, V3* fy) {
  const V3 t = dpdu - n * dot(n, dpdu);
  const F32x8 l2 = dot(t, t);
  const I32x8 ok = l2 > 1e-12f;
  *fx = t * (1 / vsqrt(ok ? l2 : splat(1)));
  if (!_mm256_testc_si256((__m256i)ok, _mm256_set1_epi32(-1))) {
    for (int k = 0; k < W; ++k)
      if (!ok[k]) {
        const Frame f = Frame::from_z(Vec3{n.x[k], n.y[k], n.z[k]});
        fx->x[k] = f.x.x, fx->y[k] = f.x.y, fx->z[k] = f.x.z;
      }
  }
  *fy = cross(n, *fx);
  // from_z's second tangent is coordinate_system's, not n × x in general: take it too.
  if (!_mm256_testc_si256((__m256i)ok, _mm256_set1_epi32(-1))) {
    for (int k = 0; k < W; ++k)
      if (!ok[k]) {
        const Frame f = Frame::from_z(Vec3{n.x[k], n.y[k], n.z[k]});
        fy->x[k] = f.y.x, fy->y[k] = f.y.y, fy->z[k] = f.y.z;
      }
  }
}

/// The lanes' path state between bounces (PathState's fields that Lambert vertices use:
/// no specular, glossy or transmission events, η scale 1).
struct Paths {
  alignas(32) int32_t alive[W];  // -1: the path goes on; 0: it has ended
  alignas(32) int32_t depth[W], diffuse_depth[W], last_segment[W];
  alignas(32) float prev_pdf[W];
  V3Lanes prev_p, prev_n;
  SpectrumLanes beta, L, L_direct;
  EmissionCache emission[W];
  /// PathState of lane k, for the per-lane code shared with trace_path.
  PathState state(int k) const {
    PathState st;
    st.beta = beta.get(k);
    st.depth = depth[k];
    st.diffuse_depth = diffuse_depth[k];
    st.any_non_specular = depth[k] > 0;
    st.last_segment = last_segment[k] != 0;
    st.prev_pdf = prev_pdf[k];
    st.prev_p = prev_p.get(k);
    st.prev_n = prev_n.get(k);
    return st;
  }
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
  alignas(32) int32_t scatter[W];   // -1: the lane samples light and its BSDF
  alignas(32) int32_t nee[W];       // -1: next-event estimation has a light
  V3Lanes p, ng, ns, dpdu, wo;
  SpectrumLanes albedo;              // w_b · ρ(λ)
  alignas(32) float u_light[2][W], u_rr[W], u_bsdf[2][W];
  alignas(32) float light_pmf[W], light_inv_area[W];
  alignas(32) int32_t light_two_sided[W];
  V3Lanes light_p0, light_p1, light_p2, light_n;
  SpectrumLanes Le;
};
}  // namespace path_lanes_detail

/// trace_path() for the n ≤ kPathLanes paths of a group, in vector lanes: camera rays
/// `rays`, their closest hits `primary` / `primary_found`, wavelengths, samplers (left at
/// the dimension trace_path leaves each) and outputs as trace_path's. The scene must be
/// path_lanes_supported(); `accel` answers intersect_stream() and occluded_stream().
template <class Accel>
void trace_paths_lanes(const SceneView& s, const Accel& accel, const IntegratorSettings& cfg, const Ray* rays,
                       const SampledWavelengths* lambda, Sampler* samplers, PathOutput* outs, const HitRecord* primary,
                       const bool* primary_found, int n) {
  using namespace path_lanes_detail;
  Paths P;
  Vertices V{};
  Ray ray[W];
  HitRecord hit_rec[W];
  bool found[W];
  for (int k = 0; k < W; ++k) {
    P.alive[k] = k < n ? -1 : 0;
    P.depth[k] = P.diffuse_depth[k] = P.last_segment[k] = 0;
    P.prev_pdf[k] = 0;
    P.prev_p.set(k, Vec3{0, 0, 0});
    P.prev_n.set(k, Vec3{0, 0, 0});
    P.beta.set(k, SampledSpectrum(1));
    P.L.set(k, SampledSpectrum(0));
    P.L_direct.set(k, SampledSpectrum(0));
    if (k < n) {
      ray[k] = rays[k];
      hit_rec[k] = primary[k];
      found[k] = primary_found[k];
    }
  }
  for (bool first = true;; first = false) {
    int live[W], m = 0;
    for (int k = 0; k < W; ++k)
      if (P.alive[k]) live[m++] = k;
    if (m == 0) break;
    for (int k = 0; k < W; ++k) V.scatter[k] = V.nee[k] = 0;
    if (!first) {
      Ray r[W];
      HitRecord h[W];
      bool f[W];
      for (int j = 0; j < m; ++j) r[j] = ray[live[j]];
      accel.intersect_stream(r, size_t(m), W, h, f);
      for (int j = 0; j < m; ++j) hit_rec[live[j]] = h[j], found[live[j]] = f[j];
    }
    // Per lane: surface geometry, emission, the light choice, the BSDF's albedo.
    for (int j = 0; j < m; ++j) {
      const int k = live[j];
      PathOutput& out = outs[k];
      Sampler& sampler = samplers[k];
      ++out.rays;
      if (!found[k]) {  // no environment: the path ends
        P.alive[k] = 0;
        continue;
      }
      const SurfaceHit hit = compute_surface_hit(s, ray[k], hit_rec[k]);
      const Vec3 wo = -ray[k].d;
      const bool scatters = hit.material >= 0 && P.depth[k] < cfg.max_depth && !P.last_segment[k];
      path_detail::LightChoice lc;
      if (scatters) lc = path_detail::choose_light(s, cfg, hit.p, hit.ns, sampler.get_2d());
      if (P.depth[k] == 0) {
        out.hit = true;
        out.normal = hit.ns;
        out.depth = hit.t * kauri::dot(ray[k].d, s.camera_forward);
      }
      if (hit.light >= 0 &&
          !(P.depth[k] == 0 && path_detail::add_area_seen_directly(s.lights[hit.light], hit.ng, wo, &out.rgb_exact))) {
        const Light& l = s.lights[hit.light];
        const SampledSpectrum Le = area_light_L(l, hit.ng, wo, lambda[k], &P.emission[k]);
        if (!Le.is_black()) {
          const PathState st = P.state(k);
          const Float w = path_detail::emitter_mis_weight(s, cfg, st, hit.light, ray[k].d, hit.p, hit.ng);
          P.add(k, st.beta * Le * w, ContributionKind::Emission);
        }
      }
      if (hit.material < 0) {  // pure emitter: black surface
        P.alive[k] = 0;
        continue;
      }
      const MaterialView& mat = s.materials[hit.material];
      const LobeParams& lobe = s.lobes[mat.first_lobe];
      const Float w_b = clamp(s.node_weights[mat.first_weight].value, 0, 1);
      if (cfg.albedo_aov && !out.albedo_set && (w_b > 0 || P.depth[k] + 1 >= cfg.max_depth)) {
        out.albedo = w_b > 0 ? lobe.a.sample(lambda[k]) * w_b : SampledSpectrum(0);
        out.albedo_set = true;
      }
      if (!scatters || !(w_b > 0)) {  // a budget is spent, or a BSDF without lobes
        P.alive[k] = 0;
        continue;
      }
      V.scatter[k] = -1;
      V.p.set(k, hit.p);
      V.ng.set(k, hit.ng);
      V.ns.set(k, hit.ns);
      V.dpdu.set(k, hit.dpdu);
      V.wo.set(k, wo);
      V.albedo.set(k, lobe.a.sample(lambda[k]) * w_b);
      if (lc.light >= 0 && lc.pmf > 0) {
        const Light& l = s.lights[lc.light];
        V.nee[k] = -1;
        V.u_light[0][k] = lc.u.x, V.u_light[1][k] = lc.u.y;
        V.light_pmf[k] = lc.pmf;
        V.light_inv_area[k] = 1 / l.area;
        V.light_two_sided[k] = l.two_sided ? -1 : 0;
        V.light_p0.set(k, l.p0), V.light_p1.set(k, l.p1), V.light_p2.set(k, l.p2), V.light_n.set(k, l.n);
        V.Le.set(k, light_emission(l, lambda[k], &P.emission[k]));
      }
      const Vec2 u_lobe_rr = sampler.get_2d(), u = sampler.get_2d();
      V.u_rr[k] = u_lobe_rr.y;
      V.u_bsdf[0][k] = u.x, V.u_bsdf[1][k] = u.y;
    }
    const I32x8 scatter = load(V.scatter);
    if (!any(scatter)) continue;  // every path ended at this bounce

    // Across the lanes: the shading frame and ω_o in it.
    const V3 p = V.p.load(), ng = V.ng.load(), ns = V.ns.load(), wo = V.wo.load();
    V3 fx, fy;
    shading_frames(ns, V.dpdu.load(), &fx, &fy);
    const V3& fz = ns;
    const V3 wo_l{dot(wo, fx), dot(wo, fy), dot(wo, fz)};
    const F32x8 wo_ng = dot(wo, ng);
    F32x8 albedo[kSpectrumSamples];
    for (int i = 0; i < kSpectrumSamples; ++i) albedo[i] = load(V.albedo.v[i]) * kInvPi;
    // A direction's BSDF value is albedo/π where ω_o and ω_i are on one side of the surface
    // by both normals (BSDF::shading_normal_correction) and of the shading frame.
    auto lambert_mask = [&](const V3& wi, const V3& wi_l) {
      const I32x8 same = wo_l.z * wi_l.z > 0;
      const I32x8 geo = wo_ng * dot(wi, ng) > 0;
      return same & ~(same ^ geo) & (wo_l.z != 0);
    };

    // Next-event estimation (sample_direct): a point on the chosen triangle.
    const I32x8 nee = load(V.nee);
    if (any(nee)) {
      const F32x8 ux = load(V.u_light[0]), uy = load(V.u_light[1]);
      const I32x8 lower = ux < uy;
      const F32x8 h = (lower ? ux : uy) / 2;
      const F32x8 b0 = lower ? h : ux - h, b1 = lower ? uy - h : h;
      const V3 pl = V.light_p0.load() * b0 + V.light_p1.load() * b1 + V.light_p2.load() * (1 - b0 - b1);
      const V3 nl = V.light_n.load();
      const V3 d = pl - p;
      const F32x8 d2 = dot(d, d);
      const V3 wi = d * (1 / vsqrt(d2 > 0 ? d2 : splat(1)));
      const F32x8 nd = vabs(dot(nl, d));
      const F32x8 pdf_l = nd > 0 ? load(V.light_inv_area) * (d2 / (nd > 0 ? nd : splat(1))) * vsqrt(d2) : F32x8{};
      const I32x8 emits = load(V.light_two_sided) | (dot(nl, -wi) > 0);
      const V3 wi_l{dot(wi, fx), dot(wi, fy), dot(wi, fz)};
      const I32x8 reflects = lambert_mask(wi, wi_l);
      const F32x8 pdf_b = (wo_l.z * wi_l.z > 0) ? vabs(wi_l.z) * kInvPi : F32x8{};
      const F32x8 cos_i = vabs(dot(wi, fz));
      const F32x8 p_light = load(V.light_pmf) * pdf_l;
      const F32x8 w = power_heuristic(p_light, pdf_b) / (p_light > 0 ? p_light : splat(1));
      I32x8 any_f{}, any_L{};
      F32x8 c[kSpectrumSamples];
      for (int i = 0; i < kSpectrumSamples; ++i) {
        const F32x8 f = reflects ? albedo[i] * cos_i : F32x8{};
        const F32x8 Le = load(V.Le.v[i]);
        any_f |= f != 0;
        any_L |= Le != 0;
        c[i] = f * Le * w;
      }
      const I32x8 shadow = nee & (d2 > 0) & (pdf_l > 0) & emits & any_f & any_L;
      alignas(32) int32_t shadow_lane[W];
      store(shadow, shadow_lane);
      Ray r[W];
      int lane_of[W], ns_ = 0;
      for (int k = 0; k < W; ++k)
        if (shadow_lane[k]) {
          ++outs[k].rays;
          lane_of[ns_] = k;
          r[ns_++] = spawn_ray_to(V.p.get(k), V.ng.get(k), Point3{pl.x[k], pl.y[k], pl.z[k]});
        }
      if (ns_ > 0) {
        bool blocked[W];
        accel.occluded_stream(r, size_t(ns_), W, blocked);
        for (int j = 0; j < ns_; ++j) {
          const int k = lane_of[j];
          if (blocked[j]) continue;
          SampledSpectrum Ld;
          for (int i = 0; i < kSpectrumSamples; ++i) Ld[i] = c[i][k];
          P.add(k, P.beta.get(k) * Ld, ContributionKind::DirectLight);
        }
      }
    }

    // The BSDF sample: a cosine-weighted direction on ω_o's side.
    V3 wi_l = sample_cosine_hemisphere(load(V.u_bsdf[0]), load(V.u_bsdf[1]));
    wi_l.z = wo_l.z < 0 ? -wi_l.z : wi_l.z;
    const F32x8 pdf = vabs(wi_l.z) * kInvPi;
    const V3 wi = fx * wi_l.x + fy * wi_l.y + fz * wi_l.z;
    const I32x8 reflects = lambert_mask(wi, wi_l) & (pdf > 0);
    const F32x8 cos_over_pdf = vabs(dot(wi, fz)) / (pdf > 0 ? pdf : splat(1));
    F32x8 beta[kSpectrumSamples];
    I32x8 any_f{};
    F32x8 beta_max{};
    for (int i = 0; i < kSpectrumSamples; ++i) {
      const F32x8 f = reflects ? albedo[i] : F32x8{};
      any_f |= f != 0;
      beta[i] = load(P.beta.v[i]) * (f * cos_over_pdf);
      beta_max = i == 0 ? beta[i] : vmax(beta_max, beta[i]);
    }
    I32x8 alive = scatter & any_f;
    // record_scatter of a diffuse reflection, then Russian roulette (trace_path).
    const I32x8 depth = load(P.depth) + (alive & 1), diffuse = load(P.diffuse_depth) + (alive & 1);
    const I32x8 last = load(P.last_segment) | (alive & ~((diffuse <= cfg.max_diffuse) &
                                                        (I32x8{} <= cfg.max_glossy) &
                                                        (I32x8{} <= cfg.max_transmission)));
    const I32x8 roulette = alive & ~last & (diffuse >= cfg.rr_min_depth);
    const F32x8 q = rr_survival(beta_max);
    alive &= ~(roulette & ~(load(V.u_rr) < q));
    const F32x8 inv_q = roulette ? 1 / (q > 0 ? q : splat(1)) : splat(1);
    I32x8 finite = ~I32x8{};
    for (int i = 0; i < kSpectrumSamples; ++i) {
      beta[i] = roulette ? beta[i] * inv_q : beta[i];
      finite &= vabs(beta[i]) < kInfinity;
      store(beta[i], P.beta.v[i]);
    }
    alive &= finite;
    store(alive, P.alive);
    store(depth, P.depth);
    store(diffuse, P.diffuse_depth);
    store(last, P.last_segment);
    store(alive ? pdf : load(P.prev_pdf), P.prev_pdf);
    P.prev_p.store(p);
    P.prev_n.store(ns);
    for (int k = 0; k < W; ++k)
      if (P.alive[k]) ray[k] = spawn_ray(V.p.get(k), V.ng.get(k), Vec3{wi.x[k], wi.y[k], wi.z[k]});
  }
  for (int k = 0; k < n; ++k) {
    outs[k].L = P.L.get(k);
    outs[k].L_direct_first = P.L_direct.get(k);
  }
}
#endif

}  // namespace kauri
