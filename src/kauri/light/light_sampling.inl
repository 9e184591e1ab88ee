// Sampling routines of light.h (kept apart so the interface stays readable).
#pragma once

namespace kauri {

namespace light_detail {

/// 1 − cosθ_max of the cone a sphere (radius² r2, centre at distance² d2) subtends,
/// as sin²θ_max / (1 + cosθ_max): no cancellation when the sphere is small and far.
KAURI_HOST_DEVICE inline Float sphere_one_minus_cos_max(Float r2, Float d2) {
  Float sin2_max = r2 / d2;
  return sin2_max / (1 + safe_sqrt(1 - sin2_max));
}

KAURI_HOST_DEVICE inline LightSample sample_sphere(const Light& l, Point3 p, Vec2 u, const SampledWavelengths& lambda,
                                                   EmissionCache* cache) {
  LightSample s;
  Vec3 to_c = l.p0 - p;
  Float d2 = length_squared(to_c);
  Float r2 = l.radius * l.radius;
  if (d2 <= r2 * 1.0001f) {
    // Inside the sphere: uniform area sampling.
    Vec3 n = sample_uniform_sphere(u);
    s.p_light = l.p0 + n * l.radius;
    s.n_light = n;
    Vec3 d = s.p_light - p;
    if (length_squared(d) == 0) return s;
    s.wi = normalize(d);
    s.pdf = area_to_solid_angle(1 / l.area, p, s.p_light, n);
  } else {
    // Uniform cone of directions subtended by the sphere; pdf 1/(2π(1−cosθ_max)).
    // 1 − cosθ is carried directly: for small, distant spheres cosθ_max rounds to
    // within a few ulps of 1 and the cone would not match the sphere.
    Float d = std::sqrt(d2);
    Float one_minus_cos_max = sphere_one_minus_cos_max(r2, d2);
    Float one_minus_cos = u.x * one_minus_cos_max;
    Float sin_t = safe_sqrt(one_minus_cos * (2 - one_minus_cos));
    Float phi = 2 * kPi * u.y;
    Frame f = Frame::from_z(to_c / d);
    Vec3 w = f.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), 1 - one_minus_cos});
    // Nearest intersection of the ray with the sphere; the discriminant from the
    // perpendicular offset avoids the cancellation in d² − b² (Haines et al. 2019).
    Float b = dot(w, to_c);
    Float disc = r2 - length_squared(to_c - w * b);
    Float t = b - safe_sqrt(disc);
    s.wi = w;
    s.p_light = p + w * t;
    s.n_light = normalize(s.p_light - l.p0);
    s.pdf = 1 / (2 * kPi * one_minus_cos_max);
  }
  s.L = area_light_L(l, s.n_light, -s.wi, lambda, cache);
  return s;
}

KAURI_HOST_DEVICE inline LightSample sample_area(const Light& l, Point3 p, Vec2 u, const SampledWavelengths& lambda,
                                                 EmissionCache* cache) {
  LightSample s;
  if (l.type == LightType::Triangle) {
    Vec2 b = sample_uniform_triangle(u);
    s.p_light = l.p0 * b.x + l.p1 * b.y + l.p2 * (1 - b.x - b.y);
  } else {
    Vec2 d = sample_uniform_disk(u);
    s.p_light = l.p0 + (l.frame.x * d.x + l.frame.y * d.y) * l.radius;
  }
  s.n_light = l.n;
  Vec3 d = s.p_light - p;
  if (length_squared(d) == 0) return s;
  s.wi = normalize(d);
  s.pdf = area_to_solid_angle(1 / l.area, p, s.p_light, l.n);
  s.L = area_light_L(l, s.n_light, -s.wi, lambda, cache);
  return s;
}

KAURI_HOST_DEVICE inline LightSample sample_env(const Light& l, Point3 p, Vec2 u, const SampledWavelengths& lambda,
                                                LightDensity density) {
  LightSample s;
  s.infinite = true;
  if (!has_light_density(l, density)) return s;
  if (l.type == LightType::EnvConstant) {
    s.wi = sample_uniform_sphere(u);
    s.pdf = uniform_sphere_pdf();
    s.L = infinite_light_Le(l, s.wi, lambda);
  } else {
    Float pdf_uv;
    Vec2 uv = env_distribution(l, density).sample(u, &pdf_uv);
    Float sin_theta;
    const Vec3 w_local = latlong_to_direction(uv, &sin_theta);
    if (pdf_uv == 0 || sin_theta == 0) return s;
    s.wi = l.frame.to_world(w_local);
    s.pdf = pdf_uv / (2 * kPi * kPi * sin_theta);
    // The radiance at the sampled (u, v) itself: taking it from s.wi would turn the
    // direction back into lat-long coordinates (an arctangent and an arccosine).
    s.L = env_texel_radiance(l, uv, lambda);
  }
  s.p_light = p + s.wi * (2 * l.scene_radius + distance(p, l.scene_center));
  return s;
}

}  // namespace light_detail

/// sample_light() of any kind of light. Out of line, its dispatch cost a triangle light's
/// sample ~45 instructions of call, register saves and switch (a Cornell box render's 1.5%).
KAURI_HOST_DEVICE inline LightSample sample_light_other(const Light& l, Point3 p, Vec2 u,
                                                        const SampledWavelengths& lambda, LightDensity density,
                                                        EmissionCache* cache) {
  LightSample s;
  switch (l.type) {
    case LightType::Point:
    case LightType::Spot: {
      Vec3 d = l.p0 - p;
      Float d2 = length_squared(d);
      if (d2 == 0) return s;
      s.wi = d * rsqrt(d2);
      s.p_light = l.p0;
      s.pdf = 1;
      s.delta = true;
      Float falloff = 1;
      if (l.type == LightType::Spot) {
        // Smoothstep between the outer and inner cone (a common artist falloff).
        Float c = dot(-s.wi, l.n);
        Float t = clamp((c - l.cos_outer) / fmax_(l.cos_inner - l.cos_outer, 1e-6f), 0, 1);
        falloff = t * t * (3 - 2 * t);
      }
      s.L = light_emission(l, lambda, cache) * (falloff / d2);
      return s;
    }
    case LightType::Distant: {
      s.infinite = true;
      if (l.cos_max >= 1) {
        s.wi = -l.n;
        s.pdf = 1;
        s.delta = true;
        s.L = light_emission(l, lambda, cache);
      } else {
        s.wi = l.frame.to_world(sample_uniform_cone(u, l.cos_max));
        s.pdf = uniform_cone_pdf(l.cos_max);
        // Inside the cone by construction: re-testing dot(wi, −n) >= cos_max in float
        // rejects a good part of a small cone's edge (3% of a 0.1° sun).
        s.L = light_emission(l, lambda, cache) / distant_cone_projected_solid_angle(l);
      }
      s.p_light = p + s.wi * (2 * l.scene_radius + distance(p, l.scene_center));
      return s;
    }
    case LightType::Triangle:
    case LightType::Disk: return light_detail::sample_area(l, p, u, lambda, cache);
    case LightType::Sphere: return light_detail::sample_sphere(l, p, u, lambda, cache);
    case LightType::EnvConstant:
    case LightType::EnvMap: return light_detail::sample_env(l, p, u, lambda, density);
  }
  return s;
}

KAURI_HOST_DEVICE KAURI_FORCE_INLINE LightSample sample_light(const Light& l, Point3 p, Vec2 u,
                                                              const SampledWavelengths& lambda, LightDensity density,
                                                              EmissionCache* cache) {
  if (l.type == LightType::Triangle) return light_detail::sample_area(l, p, u, lambda, cache);
  return sample_light_other(l, p, u, lambda, density, cache);
}

/// Solid-angle density with which sample_light() would have produced direction
/// `wi` from `p`; `p_light`/`n_light` describe where that direction meets an area light.
KAURI_HOST_DEVICE inline Float light_pdf(const Light& l, Point3 p, Vec3 wi, Point3 p_light, Normal3 n_light,
                                        LightDensity density) {
  if (!has_light_density(l, density)) return 0;
  switch (l.type) {
    case LightType::Triangle:
    case LightType::Disk: return area_to_solid_angle(1 / l.area, p, p_light, n_light);
    case LightType::Sphere: {
      Float d2 = length_squared(l.p0 - p), r2 = l.radius * l.radius;
      if (d2 <= r2 * 1.0001f) return area_to_solid_angle(1 / l.area, p, p_light, n_light);
      return 1 / (2 * kPi * light_detail::sphere_one_minus_cos_max(r2, d2));
    }
    case LightType::Distant:
      if (distant_cone_contains(l, wi)) return uniform_cone_pdf(l.cos_max);
      return 0;
    case LightType::EnvConstant: return uniform_sphere_pdf();
    case LightType::EnvMap: return env_pdf(l, env_direction(l, wi), density);
    default: return 0;
  }
}

/// infinite_light_Le(l, w, lambda) and, where `pdf` is not null, light_pdf() of direction
/// `w` for `density`: an escaped ray's emission and its MIS weight's density. An
/// environment map finds w's lat-long coordinates once for both (apart, the path's
/// escaped rays converted each direction twice).
KAURI_HOST_DEVICE inline SampledSpectrum infinite_light_Le_pdf(const Light& l, Vec3 w, const SampledWavelengths& lambda,
                                                               LightDensity density, Float* pdf) {
  if (l.type != LightType::EnvMap) {
    if (pdf) *pdf = light_pdf(l, Point3{}, w, Point3{}, Normal3{}, density);
    return infinite_light_Le(l, w, lambda);
  }
  const EnvDirection e = env_direction(l, w);
  if (pdf) *pdf = has_light_density(l, density) ? env_pdf(l, e, density) : 0;
  return env_texel_radiance(l, e.uv, lambda);
}

}  // namespace kauri
