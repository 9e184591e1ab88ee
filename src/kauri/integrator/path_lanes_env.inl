// Environment images across the path lanes (included by path_lanes.h), for 8 lanes at
// once: what a path that escapes after its first bounce receives from an image
// (escaped_radiance_of: its radiance and next-event density along the direction, the MIS
// weight), and next-event estimation's samples of an image (sample_env). Lane by lane
// these were the environment scene's largest costs after Embree (perf: 19% and 23% of its
// timer samples; callgrind: 17% and 16% of its instructions). The same
// operations as the scalar functions (light.h, math.h), so the lanes' images equal
// trace_path's up to rounding (tests/cpp/test_path_lanes.cpp). Included inside namespace
// kauri, after the lanes' vector helpers.
#pragma once

namespace path_lanes_detail {

/// atan2_poly over lanes (the same polynomial, fold and quadrant steps).
inline F32x8 atan2_poly(F32x8 y, F32x8 x) {
  const F32x8 ax = vabs(x), ay = vabs(y);
  const I32x8 x_larger = ax > ay;
  const F32x8 hi = x_larger ? ax : ay, lo = x_larger ? ay : ax;
  const F32x8 r = hi > 0 ? lo / (hi > 0 ? hi : splat(1)) : F32x8{};
  const I32x8 fold = r > Float(0.41421356f);  // tan(π/8)
  const F32x8 z = fold ? (r - 1) / (r + 1) : r;
  const F32x8 z2 = z * z;
  const F32x8 p =
      z2 * (-0.33333316f + z2 * (0.19998547f + z2 * (-0.14244778f + z2 * (0.10602067f + z2 * -0.06097298f))));
  F32x8 a = z + z * p + (fold ? splat(0.78539816f) : F32x8{});
  a = ay > ax ? Float(1.57079633f) - a : a;
  a = x < 0 ? Float(3.14159265f) - a : a;
  return (F32x8)((I32x8)a ^ ((I32x8)y & int32_t(0x80000000u)));  // −a where y's sign bit is set
}
/// acos_poly over lanes.
inline F32x8 acos_poly(F32x8 x) {
  x = vmin(vmax(x, splat(-1)), splat(1));
  return atan2_poly(vsqrt((1 - x) * (1 + x)), x);
}

/// table[index] in every lane.
inline F32x8 gather(const float* table, I32x8 index) {
  __m256i i;
  __builtin_memcpy(&i, &index, sizeof i);
  return F32x8(_mm256_i32gather_ps(table, i, 4));
}
/// cos_sin_turns over lanes: (cos 2πt, sin 2πt) from the nearest quarter turn.
inline void cos_sin_turns(F32x8 t, F32x8* cos, F32x8* sin) {
  const F32x8 q = _mm256_floor_ps(4 * t + Float(0.5));
  F32x8 c, s;
  cos_sin_quarter(2 * kPi * (t - Float(0.25) * q), &c, &s);
  const I32x8 k = __builtin_convertvector(q, I32x8) & 3;
  const I32x8 odd = (k & 1) != 0;
  const I32x8 x = (I32x8)(odd ? s : c), y = (I32x8)(odd ? c : s);
  *cos = (F32x8)(x ^ (((k + 1) & 2) << 30));
  *sin = (F32x8)(y ^ ((k & 2) << 30));
}
/// find_interval over lanes, for each lane in the n + 1 entries at cdf + offset: the same
/// halving steps, a gather each.
inline I32x8 find_interval(const float* cdf, I32x8 offset, int n, F32x8 u) {
  I32x8 lo{};
  for (int len = n; len > 1;) {
    const int half = len / 2;
    lo = gather(cdf, offset + lo + half) <= u ? lo + half : lo;
    len -= half;
  }
  return lo;
}
/// Distribution1D::sample_continuous over lanes, each lane's distribution the n bins at
/// cdf + cdf_offset (n + 1 entries) and func + func_offset with ∫ `integral`.
inline F32x8 sample_continuous(const float* cdf, const float* func, I32x8 cdf_offset, I32x8 func_offset, F32x8 integral,
                               int n, F32x8 u, F32x8* pdf, I32x8* bin) {
  const I32x8 i = find_interval(cdf, cdf_offset, n, u);
  const F32x8 c0 = gather(cdf, cdf_offset + i), width = gather(cdf, cdf_offset + i + 1) - c0;
  const F32x8 du = width > 0 ? (u - c0) / (width > 0 ? width : splat(1)) : splat(0.5f);
  *pdf = integral > 0 ? gather(func, func_offset + i) / (integral > 0 ? integral : splat(1)) : F32x8{};
  *bin = i;
  F32x8 x = vmin((__builtin_convertvector(i, F32x8) + du) / Float(n), splat(kOneMinusEpsilon));
  // Rounding can put x in a neighbouring bin: the scalar steps, in the (rare) lanes that need them.
  const I32x8 xi = __builtin_convertvector(x * Float(n), I32x8);
  const I32x8 outside = (xi < i) | ((i < n - 1) & (xi > i));
  for (int bits = mask_bits(outside); bits;) {
    const int k = next_lane(&bits);
    Float xk = x[k];
    while (int(xk * Float(n)) < i[k]) xk = bits_as_float(float_as_bits(xk) + 1);
    while (i[k] < n - 1 && int(xk * Float(n)) > i[k]) xk = bits_as_float(float_as_bits(xk) - 1);
    x[k] = xk;
  }
  return x;
}

/// The path's wavelengths and the working space's illuminant at them, as columns (wavelength
/// i of every lane in [i]): computed once per group, when a path first escapes after a bounce.
struct LaneSpectra {
  bool ready = false;
  F32x8 lambda[kSpectrumSamples] = {}, illuminant[kSpectrumSamples] = {};
  void prepare(const SampledWavelengths* lambdas, int n, const DenselySampled& I) {
    alignas(32) float lam[kSpectrumSamples][W], ill[kSpectrumSamples][W];
    for (int k = 0; k < W; ++k) {
      const SampledWavelengths& w = lambdas[k < n ? k : 0];
      const SampledSpectrum v = sample_dense(I, w);
      for (int i = 0; i < kSpectrumSamples; ++i) lam[i][k] = w.lambda[i], ill[i][k] = v[i];
    }
    for (int i = 0; i < kSpectrumSamples; ++i) lambda[i] = load(lam[i]), illuminant[i] = load(ill[i]);
    ready = true;
  }
};

/// env_texel_radiance over the lanes in `m` at lat-long (u, v): the bilinear blend of the
/// four texels' sigmoid spectra (env_bilinear, env_blend_lanes), times the illuminant.
inline void env_radiance(const Light& l, F32x8 u, F32x8 v, I32x8 m, const LaneSpectra& spectra,
                         F32x8 Le[kSpectrumSamples]) {
  // env_bilinear: the four texels and their weights.
  const F32x8 fx = u * Float(l.width) - Float(0.5), fy = v * Float(l.height) - Float(0.5);
  const F32x8 x0f = _mm256_floor_ps(fx), y0f = _mm256_floor_ps(fy);
  const F32x8 dx = fx - x0f, dy = fy - y0f;
  const I32x8 x0 = __builtin_convertvector(x0f, I32x8), y0 = __builtin_convertvector(y0f, I32x8);
  auto wrap_x = [&](I32x8 x) { return x < 0 ? x + l.width : (x >= l.width ? x - l.width : x); };
  auto clamp_y = [&](I32x8 y) { return y < 0 ? I32x8{} : (y >= l.height ? I32x8{} + (l.height - 1) : y); };
  const I32x8 xa = wrap_x(x0), xb = wrap_x(x0 + 1), ya = clamp_y(y0) * l.width, yb = clamp_y(y0 + 1) * l.width;
  const I32x8 texel[4] = {ya + xa, ya + xb, yb + xa, yb + xb};
  const F32x8 weight[4] = {(1 - dx) * (1 - dy), dx * (1 - dy), (1 - dx) * dy, dx * dy};
  // Σ_k w_k scale_k s_k(λ) (env_blend_lanes per lane), times the illuminant.
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = F32x8{};
  for (int k = 0; k < 4; ++k) {
    __m256 t[4];  // scale, c0, c1, c2 of each lane's texel k
    lanes::load_rows4(&l.texels[0].scale, m ? texel[k] : I32x8{}, t);
    const F32x8 sw = F32x8(t[0]) * weight[k];
    for (int i = 0; i < kSpectrumSamples; ++i) {
      const F32x8 lam = spectra.lambda[i];
      F32x8 x = (F32x8(t[1]) * lam + F32x8(t[2])) * lam + F32x8(t[3]);
      x = vmin(vmax(x, splat(-0x1p60f)), splat(0x1p60f));
      const F32x8 sig = Float(0.5) + x / (2 * vsqrt(x * x + 1));
      Le[i] += sig * sw;
    }
  }
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] *= spectra.illuminant[i];
}

/// escaped_radiance_of for environment image `l` (light `li`) over the lanes in `m`, whose
/// paths have bounced at least once (depth > 0: the MIS weight applies, but after a
/// specular bounce, emission_needs_mis): Le (env_texel_radiance) and the density (env_pdf, from the light's
/// LaneEnvTables `t`) along `w`, then β · Le · w_MIS added to the paths as emission
/// (Paths::add).
__attribute__((noinline)) inline void add_env_escaped(const SceneView& s, const Light& l, int li,
                                                      const LaneEnvTables& t, const V3& w, const LaneSpectra& spectra,
                                                      I32x8 m, Paths& P) {
  // env_direction: lat-long coordinates and sin θ of the local direction.
  const V3 d{dot(w, splat3(l.frame.x)), dot(w, splat3(l.frame.y)), dot(w, splat3(l.frame.z))};
  F32x8 u = atan2_poly(d.x, -d.z) * kInv2Pi;
  u = u < 0 ? u + 1 : u;
  const F32x8 v = acos_poly(d.y) * kInvPi;
  const F32x8 sin_theta = vsqrt(d.x * d.x + d.z * d.z);
  // env_pdf (Distribution2D::pdf: the cell's value over the integral, its indices clamped).
  F32x8 pdf{};
  if (t.conditional_func) {
    I32x8 iu = __builtin_convertvector(u * Float(t.nu), I32x8), iv = __builtin_convertvector(v * Float(t.nv), I32x8);
    iu = iu < 0 ? I32x8{} : (iu >= t.nu ? I32x8{} + (t.nu - 1) : iu);
    iv = iv < 0 ? I32x8{} : (iv >= t.nv ? I32x8{} + (t.nv - 1) : iv);
    const F32x8 pdf_uv = gather(t.conditional_func, m ? iv * t.nu + iu : I32x8{}) / t.marginal_integral;
    pdf = sin_theta == 0 ? F32x8{} : pdf_uv / (2 * kPi * kPi * (sin_theta == 0 ? splat(1) : sin_theta));
  }
  F32x8 Le[kSpectrumSamples];
  env_radiance(l, u, v, m, spectra, Le);
  // The MIS weight against next-event estimation, and Paths::add (emission after one
  // bounce is direct).
  const F32x8 w_mis = load(P.specular) ? splat(1) : power_heuristic(load(P.prev_pdf), s.light_distribution.discrete_pmf(li) * pdf);
  const I32x8 direct = load(P.depth) <= 1;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const F32x8 add = m ? load(P.beta.v[i]) * Le[i] * w_mis : F32x8{};
    store(load(P.L_direct.v[i]) + (direct ? add : F32x8{}), P.L_direct.v[i]);
    store(load(P.L.v[i]) + (direct ? F32x8{} : add), P.L.v[i]);
  }
}

/// sample_env of environment image `l` (its LaneEnvTables `t`) over the lanes in `m`, for
/// their 2D samples (ux, uy): Distribution2D::sample, latlong_to_direction and the radiance
/// there. *pdf is 0 (and Le black) where the sample fails, as sample_env leaves it.
inline void sample_env(const Light& l, const LaneEnvTables& t, F32x8 ux, F32x8 uy, I32x8 m, const LaneSpectra& spectra,
                       V3* wi, F32x8* pdf, F32x8 Le[kSpectrumSamples]) {
  *pdf = F32x8{};
  *wi = V3{};
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = F32x8{};
  if (!t.conditional_func) return;
  F32x8 pdf_v, pdf_u;
  I32x8 row, column;
  const F32x8 y = sample_continuous(t.marginal_cdf, t.marginal_func, I32x8{}, I32x8{}, splat(t.marginal_integral), t.nv,
                                    uy, &pdf_v, &row);
  const F32x8 x = sample_continuous(t.conditional_cdf, t.conditional_func, row * (t.nu + 1), row * t.nu,
                                    gather(t.marginal_func, row), t.nu, ux, &pdf_u, &column);
  const F32x8 pdf_uv = pdf_v * pdf_u;
  F32x8 cos_phi, sin_phi, cos_theta, sin_theta;  // φ = 2π u, θ = π v
  cos_sin_turns(x, &cos_phi, &sin_phi);
  cos_sin_turns(Float(0.5) * y, &cos_theta, &sin_theta);
  const I32x8 ok = m & (pdf_uv != 0) & (sin_theta != 0);
  if (!any(ok)) return;
  const V3 local{sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi};
  *wi = splat3(l.frame.x) * local.x + splat3(l.frame.y) * local.y + splat3(l.frame.z) * local.z;
  *pdf = ok ? pdf_uv / (2 * kPi * kPi * (ok ? sin_theta : splat(1))) : F32x8{};
  env_radiance(l, x, y, ok, spectra, Le);
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = ok ? Le[i] : F32x8{};
}

/// The next-event samples of the lanes marked in V.env (environment images, light
/// V.light_index): sample_env per image among them, into V's light direction, density and
/// radiance. Out of line, as add_env_escaped: inlined, the two left the path loop's
/// registers to scenes without an image too (the Cornell box: +2.7% instructions, 1.036x
/// the time).
__attribute__((noinline)) inline void sample_env_lights(const SceneView& s, const LaneTriangles& tris,
                                                        const SampledWavelengths* lambda, int n, LaneSpectra& spectra,
                                                        Vertices& V) {
  const I32x8 which = load(V.light_index);
  const F32x8 ux = load(V.u_light[0]), uy = load(V.u_light[1]);
  for (I32x8 todo = load(V.env); any(todo);) {  // one image at a time: the first left's
    const int li = which[__builtin_ctz(unsigned(mask_bits(todo)))];
    const I32x8 m = todo & (which == li);
    const Light& l = s.lights[li];
    if (!spectra.ready) spectra.prepare(lambda, n, l.illuminant);
    V3 wi;
    F32x8 pdf, Le[kSpectrumSamples];
    sample_env(l, tris.env[li], ux, uy, m, spectra, &wi, &pdf, Le);
    V.light_wi.store(select(m, wi, V.light_wi.load()));
    store(m ? pdf : load(V.light_pdf), V.light_pdf);
    for (int i = 0; i < kSpectrumSamples; ++i) store(m ? Le[i] : load(V.Le.v[i]), V.Le.v[i]);
    todo &= ~m;
  }
}

}  // namespace path_lanes_detail
