// Unidirectional spectral path tracer with next-event estimation and MIS
// (power heuristic), Russian roulette, per-type bounce budgets and NaN guards.
//
// `Accel` is any type with `bool intersect(const Ray&, HitRecord*) const` and
// `bool occluded(const Ray&) const`: Embree on the CPU, our own BVH on CUDA.
#pragma once

#include "kauri/integrator/path_state.h"
#include "kauri/sampler/sampler.h"
#include "kauri/scene/scene_view.h"

namespace kauri {

namespace path_detail {

/// Radiance an emissive material sends from a point with geometric normal `n` towards `w`.
KAURI_HOST_DEVICE inline SampledSpectrum material_emission(const SceneView& s, int material, Normal3 n, Vec3 w,
                                                           const SampledWavelengths& lambda) {
  SampledSpectrum Le(0);
  const Float no_attrs[kMaxVertexAttributes] = {0, 0, 0, 0};  // emitters have constant weights
  evaluate_material(s.materials[material], s.lobes, s.node_weights, no_attrs, Frame::from_z(n), n, w, lambda,
                    nullptr, &Le);
  return Le;
}

/// Whether emission found by the path's last BSDF sample is MIS-weighted against next-event
/// estimation: not the camera ray's, not after a specular bounce (NEE cannot sample those).
KAURI_HOST_DEVICE inline bool emission_needs_mis(const PathState& st) { return st.depth > 0 && !st.specular_bounce; }

/// MIS weight of emission the last BSDF sample found on `light`, whose NEE solid-angle
/// density for that direction (from st.prev_p) is `pdf_light`.
KAURI_HOST_DEVICE inline Float emitter_mis_weight_given_pdf(const SceneView& s, const IntegratorSettings& cfg,
                                                            const PathState& st, int light, Float pdf_light) {
  if (!emission_needs_mis(st)) return 1;
  return power_heuristic(st.prev_pdf, s.light_pmf(light, st.prev_p, st.prev_n, cfg.light_tree) * pdf_light);
}

/// Emission reaching the camera along a path segment that ended on an emitter.
KAURI_HOST_DEVICE inline Float emitter_mis_weight(const SceneView& s, const IntegratorSettings& cfg,
                                                  const PathState& st, int light, Vec3 wi, Point3 p_light,
                                                  Normal3 n_light) {
  if (!emission_needs_mis(st)) return 1;
  return emitter_mis_weight_given_pdf(
      s, cfg, st, light, light_pdf(s.lights[light], st.prev_p, wi, p_light, n_light, kNextEventDensity));
}

/// The light a next-event estimate at p (shading normal n) samples, and the 2D sample for
/// the point on it.
/// One stratified 2D sample `u` picks the light (u.x) and, with u.x rescaled within that
/// light's share, the point on it: the points stay stratified over all the lights
/// together. A quad emitter is two triangle lights; with the light picked by a dimension of
/// its own, each triangle got a random subset of the points (bench scenes at 256 spp:
/// relMSE cornell +2%, textured +5%, glossy +8% against this).
struct LightChoice {
  int light = -1;
  Float pmf = 0;
  Vec2 u;  // the point's sample on the light
};
KAURI_HOST_DEVICE inline LightChoice choose_light(const SceneView& s, const IntegratorSettings& cfg, Point3 p, Normal3 n,
                                                  Vec2 u) {
  LightChoice c;
  if (s.n_lights == 0) return c;
  c.u = u;
  c.light = s.select_light(u.x, p, n, cfg.light_tree, &c.pmf, &c.u.x);
  return c;
}

/// A next-event estimate before its shadow ray: what it adds if `shadow` is unoccluded.
struct DirectSample {
  SampledSpectrum c;  // f |cos θ_i| Le w / p
  Ray shadow;
};

/// Next-event estimation's sample at a vertex (point p, geometric normal ng) of BSDF `bsdf`,
/// towards the light `c` chose, up to its shadow ray: false where it adds nothing (no light,
/// a zero density or radiance, a zero BSDF value), and no shadow ray is traced. Shared by
/// trace_path and the path lanes (which test the shadow rays of a group in one packet).
KAURI_HOST_DEVICE inline bool direct_sample(const SceneView& s, Point3 p, Normal3 ng, const BSDF& bsdf, Vec3 wo,
                                            const SampledWavelengths& lambda, const LightChoice& c,
                                            EmissionCache* emission, DirectSample* out) {
  const int li = c.light;
  if (li < 0 || !(c.pmf > 0)) return false;
  const Light& light = s.lights[li];
  // A material light's Le is only a power estimate, replaced by its EDFs below: it stays
  // out of the path's cache.
  LightSample ls = sample_light(light, p, c.u, lambda, kNextEventDensity, light.material >= 0 ? nullptr : emission);
  if (light.material >= 0 && ls.pdf > 0) ls.L = material_emission(s, light.material, ls.n_light, -ls.wi, lambda);
  if (!(ls.pdf > 0) || ls.L.is_black()) return false;
  Float bsdf_pdf;
  const SampledSpectrum f = bsdf.eval_pdf(wo, ls.wi, TransportMode::Radiance, &bsdf_pdf) * absdot(ls.wi, bsdf.frame.z);
  if (f.is_black()) return false;
  const Float p_l = c.pmf * ls.pdf;
  const Float w = ls.delta ? Float(1) : power_heuristic(p_l, bsdf_pdf);
  out->c = f * ls.L * (w / p_l);
  out->shadow = ls.infinite ? spawn_ray(p, ng, ls.wi) : spawn_ray_to(p, ng, ls.p_light);
  return true;
}

/// One next-event estimate from `hit` with the BSDF `bsdf`, towards the light `c` chose.
template <class Accel>
KAURI_HOST_DEVICE SampledSpectrum sample_direct(const SceneView& s, const Accel& accel, const SurfaceHit& hit,
                                                const BSDF& bsdf, Vec3 wo, const SampledWavelengths& lambda,
                                                const LightChoice& c, EmissionCache* emission, uint32_t* rays) {
  DirectSample ds;
  if (!direct_sample(s, hit.p, hit.ng, bsdf, wo, lambda, c, emission, &ds)) return SampledSpectrum(0);
  ++*rays;
  return accel.occluded(ds.shadow) ? SampledSpectrum(0) : ds.c;
}

/// A light the camera ray meets directly adds its colour in the output space (Le_rgb), the
/// expected value of its spectral estimate over the path's wavelengths: the same image in
/// expectation, without the colour noise of four wavelengths (a directly seen lamp or sky
/// otherwise carries it at every pixel it covers; the hangar's lamp edges: 20% more error
/// than an RGB renderer's, Mitsuba's spectral variant 120%). Exact for the first vertex
/// only: there the throughput is 1 and the MIS weight 1 at every wavelength. Lights whose
/// radiance is not their `Le` (material EDFs) keep the spectral estimate: false. An
/// environment image adds its texels' colours, blended as their spectra are
/// (env_texel_rgb): the colours the spectra are fitted to, so a backdrop of sky shows no
/// colour noise, as in an RGB renderer.
KAURI_HOST_DEVICE inline bool add_area_seen_directly(const Light& l, Normal3 n, Vec3 wo, Vec3* rgb) {
  if (l.material >= 0) return false;
  if (l.two_sided || dot(n, wo) > 0) *rgb += l.Le_rgb;
  return true;
}
KAURI_HOST_DEVICE inline bool add_seen_directly(const Light& l, Vec3 d, Vec3* rgb) {
  switch (l.type) {
    case LightType::EnvConstant: *rgb += l.Le_rgb; return true;
    case LightType::Distant:
      if (distant_cone_contains(l, d)) *rgb += l.Le_rgb / distant_cone_projected_solid_angle(l);
      return true;
    case LightType::EnvMap: *rgb += env_texel_rgb(l, direction_to_latlong(l.frame.to_local(d))); return true;
    default: return false;
  }
}

/// What a path of state `st` that escapes along `d` receives from infinite light `li`:
/// β · Le · w, MIS-weighted against next-event estimation. A camera ray (depth 0) gives
/// the lights add_seen_directly takes to *rgb_exact instead.
KAURI_HOST_DEVICE inline SampledSpectrum escaped_radiance_of(const SceneView& s, const IntegratorSettings& cfg,
                                                            const PathState& st, int li, Vec3 d,
                                                            const SampledWavelengths& lambda, Vec3* rgb_exact) {
  if (st.depth == 0 && add_seen_directly(s.lights[li], d, rgb_exact)) return SampledSpectrum(0);
  Float pdf_light = 0;
  Float* pdf = emission_needs_mis(st) ? &pdf_light : nullptr;
  const SampledSpectrum Le = infinite_light_Le_pdf(s.lights[li], d, lambda, kNextEventDensity, pdf);
  if (Le.is_black()) return Le;
  return st.beta * Le * emitter_mis_weight_given_pdf(s, cfg, st, li, pdf_light);
}
/// escaped_radiance_of summed over the infinite lights. Shared by trace_path and the path
/// lanes (lane by lane, for the lights they do not take across the lanes).
KAURI_HOST_DEVICE inline SampledSpectrum escaped_radiance(const SceneView& s, const IntegratorSettings& cfg,
                                                         const PathState& st, Vec3 d, const SampledWavelengths& lambda,
                                                         Vec3* rgb_exact) {
  SampledSpectrum L(0);
  for (int i = 0; i < s.n_infinite_lights; ++i)
    L += escaped_radiance_of(s, cfg, st, s.infinite_lights[i], d, lambda, rgb_exact);
  return L;
}

/// x^⅓ for x in (0, 1), to ~2e-6 relative, in (0, 1]: a first guess from the exponent bits
/// (the exponent divided by 3), then two Newton steps y ← (2y + x / y²) / 3. Roulette needs
/// no exact root: any survival probability p in (0, 1] that both the test and the 1/p
/// weight use keeps the estimate unbiased. libm's cbrtf cost 1.1% of a Cornell box render's
/// instructions. Inputs below the smallest normal float are raised to it (the bit guess
/// needs a normal exponent).
KAURI_HOST_DEVICE inline Float cbrt_unit(Float x) {
  x = fmax_(x, Float(1.17549435e-38f));
  Float y = bits_as_float(float_as_bits(x) / 3u + 709921077u);
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  y = (2 * y + x / (y * y)) * Float(1.0f / 3);
  return fmin_(y, Float(1));
}

/// Russian roulette's survival probability for a path of throughput β (max over the
/// wavelengths, refraction's scaling removed): min(1, β^⅓). Survival in proportion to β
/// (pbrt, Mitsuba) makes every survivor carry a throughput of ~1, the variance of a
/// dozen killed paths each; the cube root keeps more of the dim paths, at weights below
/// 1. Measured against min(1, β) after 5 diffuse bounces (bench scenes, 64×64, 64 spp,
/// 10 renders, relMSE × CPU time): with β^⅓ after 4, Cornell box −8%, textured −7%,
/// displaced −3%, glossy, hangar and environment ±0.5%; min(1, β) after 4 was +6% on the
/// Cornell box, β^½ after 4 −6%, β^¼ after 4 as β^⅓.
KAURI_HOST_DEVICE inline Float rr_survival(Float beta_max) {
  if (!(beta_max > 0)) return 0;
  if (beta_max >= 1) return 1;
  return cbrt_unit(beta_max);
}

/// The path's state after its vertex at p (shading normal ns) scattered by the BSDF sample
/// `bs`: throughput, the MIS inputs of the next emitter hit, the bounce budgets, and Russian
/// roulette by `u_rr`. False: the path ends here. Shared by trace_path and the path lanes.
///
/// Russian roulette acts on the throughput, with radiance-scale from refraction removed,
/// once the path has made rr_min_depth diffuse bounces. Glossy and specular bounces do
/// not count: they keep light concentrated, and killing such paths in proportion to
/// their throughput cost the glossy bench scene 18% more variance for 3.5% fewer rays
/// (the bounce budgets still bound them). A last segment (a budget ran out) is traced
/// whatever its throughput, so rr_min_depth > max_diffuse means no roulette at all.
KAURI_HOST_DEVICE inline bool continue_path(const IntegratorSettings& cfg, const BSDFSample& bs, Point3 p, Normal3 ns,
                                            Float u_rr, PathState* st) {
  if (!bs.valid() || bs.f.is_black()) return false;
  st->beta *= bs.f * (absdot(bs.wi, ns) / bs.pdf);
  st->prev_pdf = bs.pdf;
  st->prev_p = p;
  st->prev_n = ns;
  if (bs.transmission) st->eta_scale *= sqr(bs.eta);
  ++st->depth;
  if (!st->record_scatter(bs, cfg)) st->last_segment = true;
  if (!st->last_segment && st->diffuse_depth >= cfg.rr_min_depth) {
    const Float p_survive = rr_survival((st->beta * st->eta_scale).max_value());
    if (!(u_rr < p_survive)) return false;
    st->beta *= 1 / p_survive;
  }
  return st->beta.is_finite();
}

}  // namespace path_detail

/// The colour a camera ray's first vertex adds in the output space (PathOutput::rgb_exact
/// of trace_path): the lights it meets directly whose radiance is their Le_rgb, given the
/// ray's closest hit h (`found`: whether there is one). The render loop's light
/// antialiasing (render/light_aa.h) traces extra camera rays for this term alone.
KAURI_HOST_DEVICE inline Vec3 rgb_seen_directly(const SceneView& s, const Ray& ray, bool found, const HitRecord& h) {
  Vec3 rgb{0, 0, 0};
  if (!found) {
    for (int i = 0; i < s.n_infinite_lights; ++i) path_detail::add_seen_directly(s.lights[s.infinite_lights[i]], ray.d, &rgb);
    return rgb;
  }
  if (!hit_may_emit(s, h)) return rgb;  // most hits: no surface geometry needed
  const SurfaceHit hit = compute_surface_hit(s, ray, h);
  if (hit.light >= 0) path_detail::add_area_seen_directly(s.lights[hit.light], hit.ng, -ray.d, &rgb);
  return rgb;
}

/// Traces one camera path. `primary`: the closest hit of `ray` when the caller has
/// already found it (a pixel's camera rays traced as one packet), with `primary_found`
/// saying whether there was one; null: the path traces its first ray itself. `state`: where
/// the path stands when `ray` is not the camera's (the path lanes hand a path over at a
/// vertex they do not run, with `primary` its hit); null: a camera path's start. The ray
/// of `primary` is counted in out->rays again.
template <class Accel>
KAURI_HOST_DEVICE void trace_path(const SceneView& s, const Accel& accel, const IntegratorSettings& cfg, Ray ray,
                                  SampledWavelengths& lambda, Sampler& sampler, PathOutput* out,
                                  const HitRecord* primary = nullptr, bool primary_found = false,
                                  const PathState* state = nullptr) {
  PathState st = state ? *state : PathState{};
  EmissionCache emission;
  for (;;) {
    HitRecord h;
    ++out->rays;
    bool found;
    if (primary) {
      h = *primary;
      found = primary_found;
      primary = nullptr;
    } else {
      found = accel.intersect(ray, &h);
    }
    if (!found) {
      if (s.n_infinite_lights > 0)
        out->add(path_detail::escaped_radiance(s, cfg, st, ray.d, lambda, &out->rgb_exact), st,
                 ContributionKind::Emission);
      break;
    }
    SurfaceHit hit = compute_surface_hit(s, ray, h);
    Vec3 wo = -ray.d;
    // Dimension layout of a bounce, three pairs: light choice and point; lobe choice and
    // Russian roulette; BSDF direction. The light is chosen here, before the emission and
    // the BSDF are evaluated, which do not depend on it: a light tree's descent is a chain
    // of dependent steps, and the CPU runs that work beside it. A specular vertex discards
    // its choice (the pair is taken either way, so the layout never depends on the material).
    const bool scatters = hit.material >= 0 && st.depth < cfg.max_depth && !st.last_segment;
    path_detail::LightChoice light_choice;
    if (scatters) light_choice = path_detail::choose_light(s, cfg, hit.p, hit.ns, sampler.get_2d());
    if (st.depth == 0) {
      out->hit = true;
      out->normal = hit.ns;
      out->depth = hit.t * dot(ray.d, s.camera_forward);
    }
    if (hit.light >= 0 && !(st.depth == 0 && path_detail::add_area_seen_directly(s.lights[hit.light], hit.ng, wo, &out->rgb_exact))) {
      const Light& l = s.lights[hit.light];
      // Emissive materials evaluate their EDFs in the shading frame; NEE uses the
      // geometric frame (isotropic EDFs and lobe albedos agree up to the normal).
      SampledSpectrum Le = l.material >= 0 ? path_detail::material_emission(s, l.material, hit.ng, wo, lambda)
                                           : area_light_L(l, hit.ng, wo, lambda, &emission);
      if (!Le.is_black()) {
        Float w = path_detail::emitter_mis_weight(s, cfg, st, hit.light, ray.d, hit.p, hit.ng);
        out->add(st.beta * Le * w, st, ContributionKind::Emission);
      }
    }
    if (hit.material < 0) break;  // pure emitter: black surface

    BSDF bsdf;
    const Frame frame = Frame::from_zx(hit.ns, hit.dpdu);
    build_bsdf(s.materials[hit.material], s.lobes, s.node_weights, ShadingInputs(hit.attrs, hit.uv, s.textures), frame, hit.ng, wo, lambda, &bsdf);
    if (cfg.albedo_aov && !out->albedo_set && (bsdf.has_non_specular() || st.depth + 1 >= cfg.max_depth)) {
      out->albedo = bsdf.albedo(frame.to_local(wo));
      out->albedo_set = true;
    }
    if (!scatters) break;  // a bounce budget is spent (pure emitters broke off above)

    if (bsdf.has_non_specular()) {
      SampledSpectrum Ld =
          path_detail::sample_direct(s, accel, hit, bsdf, wo, lambda, light_choice, &emission, &out->rays);
      out->add(st.beta * Ld, st, ContributionKind::DirectLight);
    }

    const Vec2 u_lobe_rr = sampler.get_2d();
    Vec2 u = sampler.get_2d();
    BSDFSample bs = bsdf.sample(wo, u_lobe_rr.x, u, lambda, TransportMode::Radiance);
    if (!path_detail::continue_path(cfg, bs, hit.p, frame.z, u_lobe_rr.y, &st)) break;
    ray = spawn_ray(hit.p, hit.ng, bs.wi);
  }
}

}  // namespace kauri
