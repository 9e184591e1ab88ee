// Environment images across the path lanes (included by path_lanes.h), for all lanes at
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
inline LF atan2_poly(LF y, LF x) {
  const LF ax = vabs(x), ay = vabs(y);
  const LI x_larger = ax > ay;
  const LF hi = x_larger ? ax : ay, lo = x_larger ? ay : ax;
  const LF r = hi > 0 ? lo / (hi > 0 ? hi : splat(1)) : LF{};
  const LI fold = r > Float(0.41421356f);  // tan(π/8)
  const LF z = fold ? (r - 1) / (r + 1) : r;
  const LF z2 = z * z;
  const LF p =
      z2 * (-0.33333316f + z2 * (0.19998547f + z2 * (-0.14244778f + z2 * (0.10602067f + z2 * -0.06097298f))));
  LF a = z + z * p + (fold ? splat(0.78539816f) : LF{});
  a = ay > ax ? Float(1.57079633f) - a : a;
  a = x < 0 ? Float(3.14159265f) - a : a;
  return (LF)((LI)a ^ ((LI)y & int32_t(0x80000000u)));  // −a where y's sign bit is set
}
/// acos_poly over lanes.
inline LF acos_poly(LF x) {
  x = vmin(vmax(x, splat(-1)), splat(1));
  return atan2_poly(vsqrt((1 - x) * (1 + x)), x);
}

/// SigmoidPolynomial::sigmoid over lanes (the same clamp), 1/2 + x/(2√(x² + 1)), with
/// 1/√(x² + 1) from the reciprocal square-root estimate and one Newton step (relative error
/// ~2⁻²³, where the scalar's square root and division round once each): the division and
/// square root of every lane's four wavelengths were the environment scene's costliest
/// instructions (an image's four texels' spectra per lookup). Not rsqrt_newton
/// (path_lanes_conductor.inl): x² + 1 is always a normal float, and no scalar twin asks for
/// AVX2's estimate, so AVX-512's own (rsqrt14) and no range test (rsqrt_newton here read
/// 1.017× the environment scene's time).
inline LF sigmoid_lanes(LF x) {
  x = vmin(vmax(x, splat(-0x1p60f)), splat(0x1p60f));
  const LF a = x * x + 1;
#if KAURI_LANES_AVX512
  LF r = LF(_mm512_rsqrt14_ps(__m512(a)));
#else
  LF r = LF(_mm256_rsqrt_ps(__m256(a)));
#endif
  r = r * (Float(1.5f) - Float(0.5f) * a * r * r);
  return Float(0.5) + Float(0.5) * x * r;
}

/// table[index] in every lane.
inline LF gather(const float* table, LI index) {
#if KAURI_LANES_AVX512
  return LF(_mm512_i32gather_ps(__m512i(index), table, 4));
#else
  return LF(_mm256_i32gather_ps(table, __m256i(index), 4));
#endif
}
/// table[index] in every lane, for a table of ints.
inline LI gather_int(const int32_t* table, LI index) {
#if KAURI_LANES_AVX512
  return LI(_mm512_i32gather_epi32(__m512i(index), table, 4));
#else
  return LI(_mm256_i32gather_epi32(table, __m256i(index), 4));
#endif
}
/// lanes::load_rows4 at the lanes' width.
inline void load_rows4(const float* table, LI index, LF column[4]) {
#if KAURI_LANES_AVX512
  lanes::load_rows4(table, index, column);
#else
  __m256 c[4];
  lanes::load_rows4(table, index, c);
  for (int j = 0; j < 4; ++j) column[j] = LF(c[j]);
#endif
}
/// cos_sin_turns over lanes: (cos 2πt, sin 2πt) from the nearest quarter turn.
inline void cos_sin_turns(LF t, LF* cos, LF* sin) {
  const LF q = vfloor(4 * t + Float(0.5));
  LF c, s;
  cos_sin_quarter(2 * kPi * (t - Float(0.25) * q), &c, &s);
  const LI k = __builtin_convertvector(q, LI) & 3;
  const LI odd = (k & 1) != 0;
  const LI x = (LI)(odd ? s : c), y = (LI)(odd ? c : s);
  *cos = (LF)(x ^ (((k + 1) & 2) << 30));
  *sin = (LF)(y ^ ((k & 2) << 30));
}
/// find_interval over lanes, for each lane in the n + 1 entries at cdf + offset, from the
/// bracket its guide table gives (the G + 1 entries at guide + guide_offset, LaneEnvTables):
/// the same halving steps within [guide[j], guide[j + 1]], j = ⌊u G⌋, until every lane's
/// bracket is one bin. The same bin as halving all n (find_interval), which the bracket
/// holds.
inline LI find_interval_guided(const float* cdf, LI offset, const int32_t* guide, LI guide_offset, int G, LF u) {
  LI j = __builtin_convertvector(u * Float(G), LI);
  j = guide_offset + (j < 0 ? LI{} : (j >= G ? LI{} + (G - 1) : j));  // lanes outside the mask may hold any u
  LI lo = gather_int(guide, j), len = gather_int(guide, j + 1) - lo + 1;
  for (LI more = len > 1; any(more); more = len > 1) {
    const LI half = len >> 1;  // 0 in the lanes already done: cdf[lo] ≤ u keeps lo
    lo = gather(cdf, offset + lo + half) <= u ? lo + half : lo;
    len -= half;
  }
  return lo;
}
/// Distribution1D::sample_continuous over lanes, each lane's distribution the n bins at
/// cdf + cdf_offset (n + 1 entries) and func + func_offset with ∫ `integral`.
inline LF sample_continuous(const float* cdf, const float* func, LI cdf_offset, LI func_offset, LF integral,
                               int n, const int32_t* guide, LI guide_offset, int G, LF u, LF* pdf, LI* bin) {
  const LI i = find_interval_guided(cdf, cdf_offset, guide, guide_offset, G, u);
  const LF c0 = gather(cdf, cdf_offset + i), width = gather(cdf, cdf_offset + i + 1) - c0;
  const LF du = width > 0 ? (u - c0) / (width > 0 ? width : splat(1)) : splat(0.5f);
  *pdf = integral > 0 ? gather(func, func_offset + i) / (integral > 0 ? integral : splat(1)) : LF{};
  *bin = i;
  LF x = vmin((__builtin_convertvector(i, LF) + du) / Float(n), splat(kOneMinusEpsilon));
  // Rounding can put x in a neighbouring bin: the scalar steps, in the (rare) lanes that need them.
  const LI xi = __builtin_convertvector(x * Float(n), LI);
  const LI outside = (xi < i) | ((i < n - 1) & (xi > i));
  for (int bits = mask_bits(outside); bits;) {
    const int k = next_lane(&bits);
    Float xk = x[k];
    while (int(xk * Float(n)) < i[k]) xk = bits_as_float(float_as_bits(xk) + 1);
    while (i[k] < n - 1 && int(xk * Float(n)) > i[k]) xk = bits_as_float(float_as_bits(xk) - 1);
    x[k] = xk;
  }
  return x;
}

/// DenselySampled::operator() over lanes (the same steps: the knot interval's lerp, 0
/// outside the table).
inline LF dense_lanes(const DenselySampled& d, LF lambda) {
  const LF t = (lambda - d.lambda_min) / d.step;
  const LI inside = (t >= 0) & (t <= Float(d.count - 1));  // false for NaN
  const LF tc = inside ? t : LF{};
  LI i = __builtin_convertvector(tc, LI);
  i = i < d.count - 2 ? i : LI{} + (d.count - 2);
  const LF f = tc - __builtin_convertvector(i, LF);
  const LF v = (1 - f) * gather(d.values, i) + f * gather(d.values, i + 1);
  return inside ? v : LF{};
}

/// Spectrum::sample of an RGB illuminant spectrum (an RGB light's or environment's
/// emission) over lanes: sigmoid · scale · illuminant, the scalar expression's order.
inline LF rgb_illuminant_lanes(const Spectrum::RGBData& rgb, LF lambda) {
  const SigmoidPolynomial& p = rgb.poly;
  return sigmoid_lanes((p.c0 * lambda + p.c1) * lambda + p.c2) * rgb.scale * dense_lanes(rgb.illuminant, lambda);
}

/// The path's wavelengths and the working space's illuminant at them, as columns (wavelength
/// i of every lane in [i]): computed once per group, when a path first meets an environment
/// image after a bounce. Lane by lane (sample_dense per lane) this was ~2% of the
/// environment scene's render.
struct LaneSpectra {
  bool ready = false;  // lambda and illuminant are set (not before: a group zeroes none of them)
  LF lambda[kSpectrumSamples], illuminant[kSpectrumSamples];
  int constant_light = -1;  // the constant environment whose radiance constant_Le holds
  LF constant_Le[kSpectrumSamples];
  void prepare(const BatchColumns& cols, const DenselySampled& I) {
    for (int i = 0; i < kSpectrumSamples; ++i) lambda[i] = load(cols.lambda[i]), illuminant[i] = dense_lanes(I, lambda[i]);
    ready = true;
  }
  /// The radiance of constant environment `l` (light `li`) at the lanes' wavelengths, as
  /// columns: Spectrum::sample of its RGB illuminant spectrum (sigmoid · scale · illuminant)
  /// across the lanes, once per group; null for another kind of spectrum (taken lane by
  /// lane). Lane by lane, the glossy scene's next-event samples of its sky and its paths
  /// escaping into it evaluated it ~4% of its render.
  const LF* constant_environment(const Light& l, int li, const BatchColumns& cols) {
    if (l.Le.type != SpectrumType::RGBIlluminant) return nullptr;
    if (constant_light != li) {
      for (int i = 0; i < kSpectrumSamples; ++i) constant_Le[i] = rgb_illuminant_lanes(l.Le.rgb, load(cols.lambda[i]));
      constant_light = li;
    }
    return constant_Le;
  }
};
/// Lane k of a spectrum held as columns.
inline SampledSpectrum lane_spectrum(const LF* v, int k) {
  SampledSpectrum s;
  for (int i = 0; i < kSpectrumSamples; ++i) s[i] = v[i][k];
  return s;
}

/// env_bilinear over lanes: the four texels lat-long (u, v) blends and their weights.
inline void env_bilinear_lanes(const Light& l, LF u, LF v, LI texel[4], LF weight[4]) {
  const LF fx = u * Float(l.width) - Float(0.5), fy = v * Float(l.height) - Float(0.5);
  const LF x0f = vfloor(fx), y0f = vfloor(fy);
  const LF dx = fx - x0f, dy = fy - y0f;
  const LI x0 = __builtin_convertvector(x0f, LI), y0 = __builtin_convertvector(y0f, LI);
  auto wrap_x = [&](LI x) { return x < 0 ? x + l.width : (x >= l.width ? x - l.width : x); };
  auto clamp_y = [&](LI y) { return y < 0 ? LI{} : (y >= l.height ? LI{} + (l.height - 1) : y); };
  const LI xa = wrap_x(x0), xb = wrap_x(x0 + 1), ya = clamp_y(y0) * l.width, yb = clamp_y(y0 + 1) * l.width;
  texel[0] = ya + xa, texel[1] = ya + xb, texel[2] = yb + xa, texel[3] = yb + xb;
  weight[0] = (1 - dx) * (1 - dy), weight[1] = dx * (1 - dy), weight[2] = (1 - dx) * dy, weight[3] = dx * dy;
}

/// direction_to_latlong over lanes, for direction w in the frame of environment image `l`
/// (and sin θ there where `sin_theta` is given).
inline void env_latlong(const Light& l, const V3& w, LF* u, LF* v, LF* sin_theta = nullptr) {
  const V3 d{dot(w, splat3(l.frame.x)), dot(w, splat3(l.frame.y)), dot(w, splat3(l.frame.z))};
  const LF a = atan2_poly(d.x, -d.z) * kInv2Pi;
  *u = a < 0 ? a + 1 : a;
  *v = acos_poly(d.y) * kInvPi;
  if (sin_theta) *sin_theta = vsqrt(d.x * d.x + d.z * d.z);
}

/// env_texel_radiance over the lanes in `m` at lat-long (u, v): the bilinear blend of the
/// four texels' sigmoid spectra (env_bilinear, env_blend_lanes), times the illuminant.
inline void env_radiance(const Light& l, LF u, LF v, LI m, const LaneSpectra& spectra,
                         LF Le[kSpectrumSamples]) {
  LI texel[4];
  LF weight[4];
  env_bilinear_lanes(l, u, v, texel, weight);
  // Σ_k w_k scale_k s_k(λ) (env_blend_lanes per lane), times the illuminant.
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = LF{};
  for (int k = 0; k < 4; ++k) {
    LF t[4];  // scale, c0, c1, c2 of each lane's texel k
    load_rows4(&l.texels[0].scale, m ? texel[k] : LI{}, t);
    const LF sw = LF(t[0]) * weight[k];
    for (int i = 0; i < kSpectrumSamples; ++i) {
      const LF lam = spectra.lambda[i];
      Le[i] += sigmoid_lanes((LF(t[1]) * lam + LF(t[2])) * lam + LF(t[3])) * sw;
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
                                                      LI m, Paths& P) {
  // env_direction: lat-long coordinates and sin θ of the local direction.
  LF u, v, sin_theta;
  env_latlong(l, w, &u, &v, &sin_theta);
  // env_pdf (Distribution2D::pdf: the cell's value over the integral, its indices clamped).
  LF pdf{};
  if (t.conditional_func) {
    LI iu = __builtin_convertvector(u * Float(t.nu), LI), iv = __builtin_convertvector(v * Float(t.nv), LI);
    iu = iu < 0 ? LI{} : (iu >= t.nu ? LI{} + (t.nu - 1) : iu);
    iv = iv < 0 ? LI{} : (iv >= t.nv ? LI{} + (t.nv - 1) : iv);
    const LF pdf_uv = gather(t.conditional_func, m ? iv * t.nu + iu : LI{}) / t.marginal_integral;
    pdf = sin_theta == 0 ? LF{} : pdf_uv / (2 * kPi * kPi * (sin_theta == 0 ? splat(1) : sin_theta));
  }
  LF Le[kSpectrumSamples];
  env_radiance(l, u, v, m, spectra, Le);
  // The MIS weight against next-event estimation, and Paths::add (emission after one
  // bounce is direct).
  const LF w_mis = load(P.specular) ? splat(1) : power_heuristic(load(P.prev_pdf), s.light_distribution.discrete_pmf(li) * pdf);
  const LI direct = load(P.depth) <= 1;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const LF add = m ? load(P.beta.v[i]) * Le[i] * w_mis : LF{};
    store(load(P.L_direct.v[i]) + (direct ? add : LF{}), P.L_direct.v[i]);
    store(load(P.L.v[i]) + (direct ? LF{} : add), P.L.v[i]);
  }
}

/// add_seen_directly of environment image `l` for the camera rays of the lanes in `m`, which
/// escaped along `w`: env_texel_rgb at their lat-long coordinates (the texels' colours
/// blended with env_texel_radiance's weights) into each lane's rgb_exact. Lane by lane this
/// was ~4% of the environment scene's render (40% of its camera rays see the sky).
__attribute__((noinline)) inline void add_env_seen_directly(const Light& l, const V3& w, LI m, PathOutput* outs) {
  LF u, v;
  env_latlong(l, w, &u, &v);
  LI texel[4];
  LF weight[4];
  env_bilinear_lanes(l, u, v, texel, weight);
  const float* rgb_table = &l.texel_rgb[0].x;
  static_assert(sizeof(Vec3) == 3 * sizeof(float), "texel_rgb rows of three floats");
  LF rgb[3] = {};
  for (int k = 0; k < 4; ++k) {
    const LI row = (m ? texel[k] : LI{}) * 3;
    for (int c = 0; c < 3; ++c) rgb[c] += gather(rgb_table + c, row) * weight[k];
  }
  for (int bits = mask_bits(m); bits;) {
    const int k = next_lane(&bits);
    outs[k].rgb_exact += Vec3{rgb[0][k], rgb[1][k], rgb[2][k]};
  }
}

/// sample_env of environment image `l` (its LaneEnvTables `t`) over the lanes in `m`, for
/// their 2D samples (ux, uy): Distribution2D::sample, latlong_to_direction and the radiance
/// there. *pdf is 0 (and Le black) where the sample fails, as sample_env leaves it.
inline void sample_env(const Light& l, const LaneEnvTables& t, LF ux, LF uy, LI m, const LaneSpectra& spectra,
                       V3* wi, LF* pdf, LF Le[kSpectrumSamples]) {
  *pdf = LF{};
  *wi = V3{};
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = LF{};
  if (!t.conditional_func) return;
  LF pdf_v, pdf_u;
  LI row, column;
  const LF y = sample_continuous(t.marginal_cdf, t.marginal_func, LI{}, LI{}, splat(t.marginal_integral), t.nv,
                                    t.marginal_guide, LI{}, t.gv, uy, &pdf_v, &row);
  const LF x = sample_continuous(t.conditional_cdf, t.conditional_func, row * (t.nu + 1), row * t.nu,
                                    gather(t.marginal_func, row), t.nu, t.conditional_guide, row * (t.gu + 1), t.gu,
                                    ux, &pdf_u, &column);
  const LF pdf_uv = pdf_v * pdf_u;
  LF cos_phi, sin_phi, cos_theta, sin_theta;  // φ = 2π u, θ = π v
  cos_sin_turns(x, &cos_phi, &sin_phi);
  cos_sin_turns(Float(0.5) * y, &cos_theta, &sin_theta);
  const LI ok = m & (pdf_uv != 0) & (sin_theta != 0);
  if (!any(ok)) return;
  const V3 local{sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi};
  *wi = splat3(l.frame.x) * local.x + splat3(l.frame.y) * local.y + splat3(l.frame.z) * local.z;
  *pdf = ok ? pdf_uv / (2 * kPi * kPi * (ok ? sin_theta : splat(1))) : LF{};
  env_radiance(l, x, y, ok, spectra, Le);
  for (int i = 0; i < kSpectrumSamples; ++i) Le[i] = ok ? Le[i] : LF{};
}

/// The next-event samples of the lanes marked in V.env (environment images, light
/// V.light_index): sample_env per image among them, into V's light direction, density and
/// radiance. Out of line, as add_env_escaped: inlined, the two left the path loop's
/// registers to scenes without an image too (the Cornell box: +2.7% instructions, 1.036x
/// the time).
__attribute__((noinline)) inline void sample_env_lights(const SceneView& s, const LaneTriangles& tris,
                                                        const BatchColumns& cols, LaneSpectra& spectra,
                                                        Vertices& V) {
  const LF ux = load(V.u_light[0]), uy = load(V.u_light[1]);
  for (LI todo = load(V.env); any(todo);) {  // one image at a time
    int li;
    const LI m = take_equal_lanes(V.light_index, &todo, &li);
    const Light& l = s.lights[li];
    if (!spectra.ready) spectra.prepare(cols, l.illuminant);
    V3 wi;
    LF pdf, Le[kSpectrumSamples];
    sample_env(l, tris.env[li], ux, uy, m, spectra, &wi, &pdf, Le);
    V.light_wi.store(select(m, wi, V.light_wi.load()));
    store(m ? pdf : load(V.light_pdf), V.light_pdf);
    for (int i = 0; i < kSpectrumSamples; ++i) store(m ? Le[i] : load(V.Le.v[i]), V.Le.v[i]);
  }
}

}  // namespace path_lanes_detail
