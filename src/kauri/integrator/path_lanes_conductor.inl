// GGX conductors and rough dielectrics across the path lanes (kLaneConductor and
// kLaneDielectric vertices). Conductors: GGXConductorLobe's
// eval_pdf and sample (Torrance–Sparrow single scattering with the spectral Fresnel of a
// complex IOR, Heitz 2014's height-correlated Smith G2, visible-normal sampling by
// spherical caps (Dupuy & Benyoub 2023), and Kulla & Conty 2017's multiple-scattering
// term with its cosine-sampled share) over the lanes (8 or 16, kPathLanes), with the lone-lobe BSDF's weight and
// shading-normal correction (BSDF::eval_pdf_lobes, BSDF::sample_lobes). The same
// operations as the scalar lobe, lane by lane; each lane's η, κ, α, F_ms and E_avg are the
// scalar lobe's own (instantiate and cache_multiple_scattering, once a vertex in the
// per-lane part). Included by path_lanes.h inside path_lanes_detail.

/// The conductor lanes' lobes of a bounce: what GGXConductorLobe holds, as columns.
struct ConductorVertices {
  SpectrumLanes eta, k, F_ms;
  alignas(kLaneBytes) float alpha_x[W], alpha_y[W], r[W], E_avg[W], w_b[W];
  alignas(kLaneBytes) int32_t compensated[W];  // -1: the Kulla–Conty term
  void set(int lane, const Lobe& l, Float w, int /*lobe*/) {
    const GGXConductorLobe& c = l.conductor;
    eta.set(lane, c.eta), k.set(lane, c.k);
    alpha_x[lane] = c.mf.alpha_x, alpha_y[lane] = c.mf.alpha_y;
    r[lane] = c.table_roughness();
    compensated[lane] = c.compensated() ? -1 : 0;
    E_avg[lane] = c.compensated() ? c.E_avg() : 0;
    F_ms.set(lane, c.compensated() ? c.F_ms(E_avg[lane]) : SampledSpectrum(0));
    w_b[lane] = w;
  }
};

/// Whether the vertices of conductor lobe `lobe` take their columns across the lanes
/// (conductor_columns) instead of lane by lane (lobe_lane: the lobe instantiated, then
/// ConductorVertices::set): η and κ densely sampled (the measured metals), no texture, no
/// Kulla–Conty term (whose F_ms is computed per lane).
inline bool conductor_columns_apply(const LobeParams& lobe) {
  if (lobe.type != LobeType::GGXConductor || lobe.a_texture >= 0 || lobe.artist) return false;
  if (lobe.a.type != SpectrumType::DenselySampled || lobe.b.type != SpectrumType::DenselySampled) return false;
  GGXConductorLobe c;
  c.mf = {lobe.alpha_x, lobe.alpha_y, lobe.microfacet};
  c.compensate = lobe.compensate;
  return !c.compensated();
}
/// ConductorVertices::set for the lanes in `m`, all at vertices of `lobe`
/// (conductor_columns_apply; their w_b set already): η(λ) and κ(λ) at the lanes'
/// wavelengths across the lanes (dense_lanes: the scalar lookup's steps) and the lobe's
/// roughness. Lane by lane this was 2–3% of the glossy scene's render (its two gold spheres).
inline void conductor_columns(const LobeParams& lobe, const BatchColumns& cols, LI m, ConductorVertices* C) {
  GGXConductorLobe c;
  c.mf = {lobe.alpha_x, lobe.alpha_y, lobe.microfacet};
  auto put = [&](float* column, LF v) { store(m ? v : load(column), column); };
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const LF lambda = load(cols.lambda[i]);
    put(C->eta.v[i], dense_lanes(lobe.a.dense, lambda));
    put(C->k.v[i], dense_lanes(lobe.b.dense, lambda));
    put(C->F_ms.v[i], LF{});
  }
  put(C->alpha_x, splat(c.mf.alpha_x));
  put(C->alpha_y, splat(c.mf.alpha_y));
  put(C->r, splat(c.table_roughness()));
  put(C->E_avg, LF{});
  store(m ? LI{} : load(C->compensated), C->compensated);
}

/// 1 / √x as kauri::rsqrt: the estimate and one Newton step, 1 / √x outside the normal range.
inline LF rsqrt_newton(LF x) {
#if KAURI_LANES_AVX512  // AVX2's 12-bit estimate per half, as the scalar rsqrt (rsqrt14 differs)
  const lanes::F32x8 lo = __builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7);
  const lanes::F32x8 hi = __builtin_shufflevector(x, x, 8, 9, 10, 11, 12, 13, 14, 15);
  const LF y = lanes::join(lanes::F32x8(_mm256_rsqrt_ps(__m256(lo))), lanes::F32x8(_mm256_rsqrt_ps(__m256(hi))));
#else
  const LF y = LF(_mm256_rsqrt_ps(__m256(x)));
#endif
  const LF r = y * (Float(1.5f) - Float(0.5f) * x * y * y);
  const LI normal = (x >= Float(1.17549435e-38f)) & (x <= Float(3.40282347e38f));
  if (all(normal)) return r;
  return normal ? r : 1 / vsqrt(x);
}
inline V3 normalize_newton(const V3& a) { return a * rsqrt_newton(dot(a, a)); }

/// microfacet_albedo(GGX, μ, r) across the lanes: the table's bilinear lookup.
inline LF ggx_albedo(LF mu, LF r) {
  auto grid = [](LF x, LI* i, LF* f) {
    const LF g = vmin(vmax(x, LF{}), splat(1)) * Float(kAlbedoTableSize - 1);
    LI k = __builtin_convertvector(g, LI);
    k = k > kAlbedoTableSize - 2 ? LI{} + (kAlbedoTableSize - 2) : k;
    *i = k;
    *f = g - __builtin_convertvector(k, LF);
  };
  LI i, j;
  LF fu, fr;
  grid(mu, &i, &fu);
  grid(r, &j, &fr);
  const float* tab = albedo_table(MicrofacetType::GGX);
  const LI row = j * kAlbedoTableSize + i;
  const LF a = (1 - fu) * gather(tab, row) + fu * gather(tab, row + 1);
  const LF b = (1 - fu) * gather(tab, row + kAlbedoTableSize) + fu * gather(tab, row + kAlbedoTableSize + 1);
  return (1 - fr) * a + fr * b;
}

/// MicrofacetDistribution::sample_visible_normal_ggx across the lanes (ω up): ω stretched,
/// a point on the spherical cap above it, unstretched.
inline V3 sample_visible_normal_ggx(const V3& w, LF ax, LF ay, LF ux, LF uy) {
  V3 ws = normalize_newton(V3{ax * w.x, ay * w.y, w.z});
  ws = select(ws.z < 0, -ws, ws);
  const LF z = (1 - uy) * (1 + ws.z) - ws.z;
  const LF s2 = (1 - z) * (1 + z);
  const LF sin_t = vsqrt(s2 > 0 ? s2 : LF{});
  LF c, s;
  cos_sin_turns(ux, &c, &s);
  const V3 h{ws.x + sin_t * c, ws.y + sin_t * s, ws.z + z};
  return normalize_newton(V3{ax * h.x, ay * h.y, vmax(splat(1e-6f), h.z)});
}

/// GGX D(ω_m) and Λ(ω) (MicrofacetDistribution::D, ::Lambda) across the lanes.
inline LF ggx_D(const V3& wm, LF ax, LF ay) {
  const LF c2 = wm.z * wm.z;
  const LF sx = wm.x / ax, sy = wm.y / ay;
  const LF e = (sx * sx + sy * sy) / c2;
  const LF e1 = 1 + e;
  return c2 <= 0 ? LF{} : 1 / (kPi * ax * ay * c2 * c2 * (e1 * e1));
}
inline LF ggx_Lambda(const V3& w, LF ax, LF ay) {
  const LF c2 = w.z * w.z;
  const LF sx = w.x * ax, sy = w.y * ay;
  const LF a2t2 = (sx * sx + sy * sy) / c2;
  return c2 <= 0 ? splat(kInfinity) : (vsqrt(1 + a2t2) - 1) / 2;
}

/// fresnel_conductor across the lanes, for one wavelength.
inline LF fresnel_conductor(LF cos_i, LF eta, LF k) {
  cos_i = vmin(vmax(vabs(cos_i), LF{}), splat(1));
  const LF cos2 = cos_i * cos_i, sin2 = 1 - cos2;
  const LF eta2 = eta * eta, k2 = k * k;
  const LF t0 = eta2 - k2 - sin2;
  const LF s0 = t0 * t0 + 4 * eta2 * k2;
  const LF a2b2 = vsqrt(s0 > 0 ? s0 : LF{});
  const LF s1 = (a2b2 + t0) / 2;
  const LF a = vsqrt(s1 > 0 ? s1 : LF{});
  const LF t1 = a2b2 + cos2, t2 = 2 * a * cos_i;
  const LF rs = (t1 - t2) / (t1 + t2);
  const LF t3 = cos2 * a2b2 + sin2 * sin2, t4 = t2 * sin2;
  const LF rp = rs * (t3 - t4) / (t3 + t4);
  const LF r = (rs + rp) / 2;
  const LI finite = vabs(r) < kInfinity;  // NaN compares false
  return finite ? vmin(vmax(r, LF{}), splat(1)) : splat(1);
}

/// BSDF::eval_pdf of the lanes' lone conductor lobes (the lanes in `m`) for local ω_o, ω_i:
/// f (without the cosine; times w_b) and the density, both 0 off the lanes or where the
/// lobe has no value. `geo`: the lanes whose directions are on one side of the surface by
/// the geometric normal as by the shading one (shading_normal_correction).
inline void conductor_eval_pdf(const ConductorVertices& C, V3 wo, V3 wi, LI m, LI geo,
                               LF f[kSpectrumSamples], LF* pdf) {
  const LF ax = load(C.alpha_x), ay = load(C.alpha_y);
  LI ok = m & (wo.z * wi.z > 0);  // same_hemisphere (so ω_o.z ≠ 0, as BSDF::eval_pdf_lobes needs)
  const LI below = wo.z < 0;      // mirrored to ω_o's side
  wo = select(below, -wo, wo), wi = select(below, -wi, wi);
  ok &= (wo.z != 0) & (wi.z > 0);
  const V3 h = wo + wi;
  const LF l2 = dot(h, h);
  const LI has_m = ok & (l2 > 0);
  const V3 wm = h * rsqrt_newton(has_m ? l2 : splat(1));
  const LF D = ggx_D(wm, ax, ay), lambda_o = ggx_Lambda(wo, ax, ay);
  const LF g = D / ((1 + lambda_o + ggx_Lambda(wi, ax, ay)) * 4 * wo.z * wi.z);
  const LF p_ss = has_m ? D / ((1 + lambda_o) * 4 * wo.z) : LF{};
  const LF cos_om = vabs(dot(wo, wm));
  const LI comp = ok & load(C.compensated);
  LF ms{}, pms{};
  if (any(comp)) {
    const LF r = load(C.r), e_o = ggx_albedo(wo.z, r), ea = load(C.E_avg);
    const LI below_one = comp & (ea < 1);
    const LF msv = (1 - e_o) * (1 - ggx_albedo(wi.z, r)) / (kPi * (1 - (below_one ? ea : LF{})));
    ms = (below_one & (msv > 0)) ? msv : LF{};
    pms = comp ? vmin(vmax(1 - e_o, LF{}), splat(1)) : LF{};
  }
  *pdf = ok ? (1 - pms) * p_ss + pms * (wi.z * kInvPi) : LF{};
  const LF w = load(C.w_b);
  const LI value = ok & geo;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const LF fs = has_m ? fresnel_conductor(cos_om, load(C.eta.v[i]), load(C.k.v[i])) * g : LF{};
    const LF fi = fs + load(C.F_ms.v[i]) * ms;
    f[i] = value ? fi * w : LF{};
  }
}

/// GGXConductorLobe::sample of the lanes in `m` for local ω_o and the vertex's samples (uc
/// picks the cosine-sampled multiple-scattering share, (ux, uy) the direction): the local
/// ω_i and the lanes whose sample is valid (ω_i above ω_o's side, density > 0). The value
/// and density follow from conductor_eval_pdf at ω_i, as the scalar lobe evaluates them.
inline LI conductor_sample(const ConductorVertices& C, const V3& wo, LF uc, LF ux, LF uy, LI m,
                              V3* wi_out) {
  // α of the other lanes is 1: their columns hold no lobe (nothing reads their results, but
  // the normalisations below branch on their values).
  const LF ax = m ? load(C.alpha_x) : splat(1), ay = m ? load(C.alpha_y) : splat(1);
  const LF flip = wo.z < 0 ? splat(-1) : splat(1);
  const V3 wo_up = wo * flip;
  LI ok = m & (wo_up.z != 0);
  LF pms{};
  const LI comp = ok & load(C.compensated);
  if (any(comp)) pms = comp ? vmin(vmax(1 - ggx_albedo(wo_up.z, load(C.r)), LF{}), splat(1)) : LF{};
  // BSDF::sample_lobes rescales uc within the one lobe's share (1): min(uc, 1 − ε).
  const LI cosine = vmin(uc, splat(kOneMinusEpsilon)) < pms;
  const V3 wi_cos = sample_cosine_hemisphere(ux, uy);
  const V3 wm = sample_visible_normal_ggx(wo_up, ax, ay, ux, uy);
  const V3 wi_vndf = -wo_up + wm * (2 * dot(wo_up, wm));
  const V3 wi_up = select(cosine, wi_cos, wi_vndf);
  *wi_out = wi_up * flip;
  return ok & (wi_up.z > 0);
}

/// A dielectric albedo table's key (DielAlbedoKey) per lane, and as vectors.
struct DielKeyLanes {
  alignas(kLaneBytes) int32_t side[W], k[W], j[W];
  alignas(kLaneBytes) float fk[W], fr[W];
  void set(int lane, const DielAlbedoKey& key) {
    side[lane] = key.side, k[lane] = key.k, j[lane] = key.j, fk[lane] = key.fk, fr[lane] = key.fr;
  }
};
struct DielKey {
  LI side, k, j;
  LF fk, fr;
};
/// Lane by lane the key `a` where `m`, else `b`.
inline DielKey select_key(LI m, const DielKeyLanes& a, const DielKeyLanes& b) {
  return {m ? load(a.side) : load(b.side), m ? load(a.k) : load(b.k), m ? load(a.j) : load(b.j),
          m ? load(a.fk) : load(b.fk), m ? load(a.fr) : load(b.fr)};
}
inline DielKey select_key(LI m, const DielKey& a, const DielKey& b) {
  return {m ? a.side : b.side, m ? a.k : b.k, m ? a.j : b.j, m ? a.fk : b.fk, m ? a.fr : b.fr};
}
/// diel_albedo across the lanes: the trilinear E(μ, r, e) of `tab` at each lane's key.
inline LF diel_albedo(const float* tab, const DielKey& key, LF mu) {
  const LF g = vmin(vmax(mu, LF{}), splat(1)) * Float(kDielAlbedoMu - 1);
  LI i = __builtin_convertvector(g, LI);
  i = i > kDielAlbedoMu - 2 ? LI{} + (kDielAlbedoMu - 2) : i;
  const LF fu = g - __builtin_convertvector(i, LF);
  const LI base = key.side * kDielAlbedoSide + i;
  auto row = [&](LI k, LI j) {
    const LI p = base + (k * kDielAlbedoR + j) * kDielAlbedoMu;
    return (1 - fu) * gather(tab, p) + fu * gather(tab, p + 1);
  };
  const LF a = (1 - key.fr) * row(key.k, key.j) + key.fr * row(key.k, key.j + 1);
  const LF b = (1 - key.fr) * row(key.k + 1, key.j) + key.fr * row(key.k + 1, key.j + 1);
  return (1 - key.fk) * a + key.fk * b;
}

/// The rough dielectric lanes' lobes of a bounce (RoughDielectricLobe without dispersion):
/// η inside / outside, α, the weight, and where compensated (ggx_dielectric@2) its
/// multiple-scattering terms (RoughDielectricLobe::ms_terms) for ω_o outside [0] and inside
/// [1]: the table keys of ω_o's side and the far side, their E_avg, the transmitted share
/// t_o and the relative IOR e.
struct DielectricVertices {
  alignas(kLaneBytes) float eta[W], alpha_x[W], alpha_y[W], w_b[W];
  alignas(kLaneBytes) int32_t compensated[W];  // -1: the Kulla–Conty terms
  DielKeyLanes key_o[2], key_i[2];
  alignas(kLaneBytes) float ea_o[2][W], ea_i[2][W], t_o[2][W];
  const RoughDielectricLobe::MS* terms = nullptr;  // LaneTriangles::dielectric_ms
  void set(int lane, const Lobe& l, Float w, int lobe) {
    const RoughDielectricLobe& d = l.rough_dielectric;
    eta[lane] = d.eta[0], alpha_x[lane] = d.mf.alpha_x, alpha_y[lane] = d.mf.alpha_y, w_b[lane] = w;
    compensated[lane] = d.compensated() ? -1 : 0;
    if (!d.compensated()) return;
    for (int side = 0; side < 2; ++side) {
      const RoughDielectricLobe::MS& m = terms[2 * lobe + side];
      key_o[side].set(lane, m.key_o), key_i[side].set(lane, m.key_i);
      ea_o[side][lane] = m.ea_o, ea_i[side][lane] = m.ea_i, t_o[side][lane] = m.t_o;
    }
  }
};

/// The compensation's terms of the lanes `comp` for ω_o on the side `outside`, as vectors;
/// the other lanes' keys are the table's first cell (their columns hold no key: gathers
/// must not read beyond the tables).
struct DielectricMS {
  DielKey key_o, key_i;
  LF ea_o, ea_i, t_o;
};
inline DielectricMS dielectric_ms(const DielectricVertices& Dv, LI outside, LI comp) {
  const DielKey none{};
  return {select_key(comp, select_key(outside, Dv.key_o[0], Dv.key_o[1]), none),
          select_key(comp, select_key(outside, Dv.key_i[0], Dv.key_i[1]), none),
          outside ? load(Dv.ea_o[0]) : load(Dv.ea_o[1]), outside ? load(Dv.ea_i[0]) : load(Dv.ea_i[1]),
          outside ? load(Dv.t_o[0]) : load(Dv.t_o[1])};
}
/// ms_sampling: the compensation strategy's probability 1 − E(μ_o) (clamped to 0.99).
inline LF dielectric_p_ms(const DielectricMS& m, LF mu_o) {
  return vmin(vmax(1 - diel_albedo(kGGXDielectricAlbedo, m.key_o, mu_o), LF{}), splat(0.99f));
}

/// fresnel_dielectric across the lanes (cos_i < 0: from the inside, η inverted).
inline LF fresnel_dielectric(LF cos_i, LF eta) {
  cos_i = vmin(vmax(cos_i, splat(-1)), splat(1));
  const LI inside = cos_i < 0;
  eta = inside ? 1 / eta : eta;
  cos_i = inside ? -cos_i : cos_i;
  const LF sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  const LI tir = sin2_t >= 1;
  const LF c2 = 1 - sin2_t;
  const LF cos_t = vsqrt(c2 > 0 ? c2 : LF{});
  const LF r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const LF r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return tir ? splat(1) : (r_par * r_par + r_perp * r_perp) / 2;
}

/// BSDF::eval_pdf of the lanes' lone rough dielectric lobes (lanes `m`) for local ω_o,
/// ω_i on either side (RoughDielectricLobe::ss_up, Walter et al. 2007 eqs. 20–21, radiance
/// transport, plus eval_ms_up / with_ms_pdf where compensated): f (without the cosine; times w_b; the same at every wavelength) and the
/// density. `geo`: shading_normal_correction's agreement of the two normals.
inline void dielectric_eval_pdf(const DielectricVertices& Dv, V3 wo, V3 wi, LI m, LI geo, LF* f,
                                LF* pdf) {
  const LF ax = load(Dv.alpha_x), ay = load(Dv.alpha_y);
  LI ok = m & (wo.z != 0) & (wi.z != 0);
  const LI outside = wo.z > 0;
  wo = select(outside, wo, -wo), wi = select(outside, wi, -wi);
  const LF eta = load(Dv.eta);
  const LF e = outside ? eta : 1 / eta;  // relative_eta
  // half_vector: ω_o + ω_i (reflection) or ω_o + e ω_i (refraction), turned up.
  const LI refl = wi.z > 0;
  V3 h = wo + wi * (refl ? splat(1) : e);
  const LF l2 = dot(h, h);
  LI has_m = ok & (l2 > 0);  // half_vector: the single-scattering term's ω_m exists
  h = h * rsqrt_newton(has_m ? l2 : splat(1));
  h = select(h.z < 0, -h, h);
  has_m &= h.z != 0;
  const LF dot_o = dot(wo, h), dot_i = dot(wi, h);
  has_m &= (dot_o > 0) & (refl ? dot_i > 0 : dot_i < 0);
  const LF F = fresnel_dielectric(dot_o, e);
  const LF D = ggx_D(h, ax, ay), lambda_o = ggx_Lambda(wo, ax, ay);
  const LF DG = D / (1 + lambda_o + ggx_Lambda(wi, ax, ay));
  const LF D_vis = D * dot_o / ((1 + lambda_o) * wo.z);
  const LF sum = dot_o + e * dot_i, denom = sum * sum;
  const LF abs_i = vabs(dot_i);
  const LF p_r = D_vis / (4 * dot_o) * F, f_r = DG * F / (4 * wo.z * wi.z);
  const LF p_t = D_vis * (1 - F) * e * e * abs_i / denom;
  const LF f_t = DG * (1 - F) * dot_o * abs_i / (wo.z * vabs(wi.z) * denom);
  LF p = ok & has_m ? (refl ? p_r : p_t) : LF{};
  LF v = ok & has_m ? (refl ? f_r : f_t) : LF{};
  const LI comp = ok & load(Dv.compensated);
  if (any(comp)) {  // eval_ms_up and with_ms_pdf
    const DielectricMS ms = dielectric_ms(Dv, outside, comp);
    const LF lo = vmax(1 - diel_albedo(kGGXDielectricAlbedo, ms.key_o, wo.z), LF{});
    const LF li = vmax(1 - diel_albedo(kGGXDielectricAlbedo, select_key(refl, ms.key_o, ms.key_i), vabs(wi.z)), LF{});
    const LF ea = refl ? ms.ea_o : ms.ea_i;
    const LI below_one = ea < 1;
    const LF one_minus = 1 - (below_one ? ea : LF{});
    const LF f_ms_r = (1 - ms.t_o) * lo * li / (kPi * one_minus);
    const LF f_ms_t = ms.t_o * lo * li / (kPi * one_minus) / (e * e);
    const LF f_ms = below_one ? (refl ? f_ms_r : f_ms_t) : LF{};
    v = comp ? v + f_ms : v;
    const LF pms = dielectric_p_ms(ms, wo.z);
    p = comp ? (1 - pms) * p + pms * (refl ? 1 - ms.t_o : ms.t_o) * vabs(wi.z) * kInvPi : p;
  }
  *pdf = p;
  *f = (ok & geo) ? v * load(Dv.w_b) : LF{};
}

/// RoughDielectricLobe::sample of the lanes in `m` for local ω_o: the compensation's cosine
/// strategy with probability P_ms, else a visible normal, then reflection with probability
/// F (uc rescaled) or refraction through it. The local ω_i and the
/// lanes whose sample is valid; `refracted`: the lanes that crossed the surface.
inline LI dielectric_sample(const DielectricVertices& Dv, const V3& wo, LF uc, LF ux, LF uy, LI m,
                               V3* wi_out, LI* refracted) {
  const LI outside = wo.z > 0;
  const V3 wo_up = select(outside, wo, -wo);
  const LF eta = load(Dv.eta);
  const LF e = outside ? eta : 1 / eta;
  // BSDF::sample_lobes rescales uc within the one lobe's share (1): min(uc, 1 − ε).
  uc = vmin(uc, splat(kOneMinusEpsilon));
  // The compensation's cosine strategy (ms_sampling): with probability P_ms, on the
  // transmission side with probability t_o of those.
  const LI comp = m & load(Dv.compensated);
  LF pms{}, t{};
  if (any(comp)) {
    const DielectricMS ms = dielectric_ms(Dv, outside, comp);
    pms = comp ? dielectric_p_ms(ms, wo_up.z) : LF{};
    t = comp ? ms.t_o : LF{};
  }
  const LI cosine = uc < pms;
  V3 wc = sample_cosine_hemisphere(ux, uy);
  wc.z = uc < pms * t ? -wc.z : wc.z;
  uc = (uc - pms) / (1 - pms);
  const V3 wm = sample_visible_normal_ggx(wo_up, m ? load(Dv.alpha_x) : splat(1), m ? load(Dv.alpha_y) : splat(1), ux, uy);
  const LF dot_o = dot(wo_up, wm);
  LI ok = m & (wo.z != 0) & (cosine ? wc.z != 0 : dot_o > 0);
  const LI reflect = uc < fresnel_dielectric(dot_o, e);
  const V3 wr = -wo_up + wm * (2 * dot_o);
  // refract(ω_o, ω_m, e): cos_i = ω_m·ω_o > 0 here.
  const LF sin2_t = vmax(LF{}, 1 - dot_o * dot_o) / (e * e);
  const LF c2 = 1 - sin2_t;
  const LF cos_t = vsqrt(c2 > 0 ? c2 : LF{});
  const V3 wt = V3{-wo_up.x / e, -wo_up.y / e, -wo_up.z / e} + wm * (dot_o / e - cos_t);
  ok &= cosine | (reflect ? wr.z > 0 : (sin2_t < 1) & (wt.z < 0));
  const V3 wi_up = select(cosine, wc, select(reflect, wr, wt));
  *wi_out = select(outside, wi_up, -wi_up);
  *refracted = ok & (wi_up.z < 0);  // reflect_it = ω_i up
  return ok;
}

/// The specular lanes' lobes of a bounce (kLaneSpecular): a smooth conductor (a mirror:
/// GGXConductorLobe below α 1e-3) or a smooth dielectric without dispersion
/// (SmoothDielectricLobe), their spectral η (and κ) and the weight.
struct SpecularVertices {
  SpectrumLanes eta, k;
  alignas(kLaneBytes) float w_b[W];
  alignas(kLaneBytes) int32_t dielectric[W];  // -1: a smooth dielectric; 0: a mirror
  void set(int lane, const Lobe& l, Float w, int /*lobe*/) {
    const bool glass = l.type == LobeType::SmoothDielectric;
    eta.set(lane, glass ? l.dielectric.eta : l.conductor.eta);
    k.set(lane, glass ? SampledSpectrum(0) : l.conductor.k);
    dielectric[lane] = glass ? -1 : 0;
    w_b[lane] = w;
  }
};

/// The specular lanes' samples (SmoothDielectricLobe::sample, GGXConductorLobe::sample of a
/// mirror, then BSDF::sample_lobes' weight and shading-normal correction) for local ω_o:
/// ω_i, f (without the cosine) per wavelength and the discrete probability; the lanes
/// whose sample is valid, and those that refracted (with the relative η crossed).
inline LI specular_sample(const SpecularVertices& S, const V3& wo, LF uc, LI m, V3* wi,
                             LF f[kSpectrumSamples], LF* pdf, LI* refracted, LF* eta_crossed) {
  uc = vmin(uc, splat(kOneMinusEpsilon));  // BSDF::sample_lobes' rescale within its one lobe
  const LI glass = m & load(S.dielectric);
  const LF e = load(S.eta.v[0]);
  const LF F = fresnel_dielectric(wo.z, e);
  // refract(ω_o, +z, e): from the inside the normal and η turn round.
  const LI inside = wo.z < 0;
  const LF eta = inside ? 1 / e : e, cos_i = inside ? -wo.z : wo.z, n = inside ? splat(-1) : splat(1);
  const LF sin2_t = vmax(LF{}, 1 - cos_i * cos_i) / (eta * eta);
  const LF c2 = 1 - sin2_t;
  const LF cos_t = vsqrt(c2 > 0 ? c2 : LF{});
  const LF t = (cos_i / eta - cos_t) * n;
  const V3 wt{-wo.x / eta, -wo.y / eta, -wo.z / eta + t};
  const LI refract = glass & ~(uc < F) & (sin2_t < 1);
  const V3 wr{-wo.x, -wo.y, wo.z};
  *wi = select(refract, wt, wr);
  const LF cos_wi = vabs(wi->z);
  *pdf = glass ? (refract ? 1 - F : ((uc < F) ? F : splat(1))) : splat(1);
  const LF w = load(S.w_b);
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const LF ei = load(S.eta.v[i]);
    const LF Fi = fresnel_dielectric(wo.z, ei);
    const LF erel = wo.z > 0 ? ei : 1 / ei;
    const LF v_glass = refract ? (1 - Fi) / (erel * erel) / cos_wi : Fi / cos_wi;
    const LF v_mirror = fresnel_conductor(vabs(wo.z), ei, load(S.k.v[i])) / cos_wi;
    f[i] = (glass ? v_glass : v_mirror) * w;
  }
  *refracted = refract;
  *eta_crossed = eta;
  return m & (wo.z != 0) & (*pdf > 0) & (wi->z != 0);
}
