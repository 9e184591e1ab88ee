// The camera and film stages of a pixel's sample group, one sample per vector lane.
//
// The render loop takes a pixel's samples in groups of 8 (EmbreeAccel::kPacketSize):
// camera rays, their closest hits as one Embree packet, then each path on its own. The
// work before and after the paths is the same for every sample and has no branches
// worth the name, yet done one sample at a time it was ~1500 instructions a sample (a
// callgrind profile of the hangar with every camera ray escaping): a third of the
// hangar's render and a seventh of the Cornell box's. Here the group's 8 samples run in
// the lanes of AVX2 vectors:
//   - camera stage: film positions, the 4 wavelengths of each path (inverse-CDF table
//     lookups as gathers) and pinhole rays (other cameras ray by ray);
//   - film stage: each path's XYZ Monte Carlo weights (CIE table rows), its direct
//     and indirect XYZ and the RGB with the indirect clamp.
// The values are the scalar functions' (camera_sample / SampledXYZWeights /
// SceneView::to_rgb): the same operations in the same order, equal to float rounding
// (whether GCC contracts a multiply and an add into an FMA depends on the surrounding
// code), which tests/cpp/test_sample_lanes.cpp checks. Host CPU code of the render loop;
// a CUDA build runs one sample per thread through the scalar functions.
#pragma once

#include <vector>

#include "kauri/integrator/path_state.h"
#include "kauri/sampler/sampler_lanes.h"
#include "kauri/scene/scene_view.h"
#include "kauri/film/film.h"

#define KAURI_SAMPLE_LANES KAURI_LANES_AVX2

namespace kauri {

/// Clamps the indirect part of a sample to luminance `clamp` (hue preserved; 0: off).
inline Vec3 clamp_luminance(Vec3 rgb, Float y, Float clamp) {
  if (clamp <= 0 || y <= clamp) return rgb;
  return rgb * (clamp / y);
}

#if KAURI_SAMPLE_LANES
namespace lanes_detail {
using lanes::F32x8;
using lanes::I32x8;

inline F32x8 broadcast(Float v) { return F32x8{} + v; }
inline F32x8 gather(const float* table, I32x8 i) {
  __m256i idx;
  __builtin_memcpy(&idx, &i, sizeof idx);
  const __m256 v = _mm256_i32gather_ps(table, idx, 4);
  F32x8 r;
  __builtin_memcpy(&r, &v, sizeof r);
  return r;
}
/// m ? a : b per lane (m: all-ones or zero lanes, as vector comparisons give).
inline F32x8 select(I32x8 m, F32x8 a, F32x8 b) { return m ? a : b; }

/// Vec3 over lanes, with the scalar operators' expression shapes (so contraction into
/// FMAs is the same).
struct Vec3x8 {
  F32x8 x, y, z;
};
inline F32x8 dot(const Vec3x8& a, const Vec3x8& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3x8 normalize(const Vec3x8& a) {
  const F32x8 len = __builtin_ia32_sqrtps256(dot(a, a));
  const F32x8 r = 1 / len;
  return {a.x * r, a.y * r, a.z * r};
}
/// Transform::apply.
inline Vec3x8 apply(const Float a[3][4], const Vec3x8& v, Float w_) {
  const F32x8 w = broadcast(w_);
  return {a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z + a[0][3] * w,
          a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z + a[1][3] * w,
          a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z + a[2][3] * w};
}
/// SceneView::to_rgb.
inline Vec3x8 to_rgb(const Float m[3][3], const Vec3x8& xyz) {
  return {m[0][0] * xyz.x + m[0][1] * xyz.y + m[0][2] * xyz.z, m[1][0] * xyz.x + m[1][1] * xyz.y + m[1][2] * xyz.z,
          m[2][0] * xyz.x + m[2][1] * xyz.y + m[2][2] * xyz.z};
}

/// The 4 columns of 8 rows of 4 floats (row k at `base` + k · stride bytes, unaligned):
/// column[i][k] = row k's float i. An 8 × 4 transpose in shuffles; element by element it
/// was ~2 instructions a value.
inline void load_columns4(const void* base, size_t stride, F32x8 column[4]) {
  const char* p = static_cast<const char*>(base);
  auto rows = [&](int a) {  // rows a and a + 4 in the two 128-bit halves
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(reinterpret_cast<const float*>(p + a * stride))),
                                _mm_loadu_ps(reinterpret_cast<const float*>(p + (a + 4) * stride)), 1);
  };
  const __m256 t0 = rows(0), t1 = rows(1), t2 = rows(2), t3 = rows(3);
  const __m256 u0 = _mm256_unpacklo_ps(t0, t1), u1 = _mm256_unpackhi_ps(t0, t1);
  const __m256 u2 = _mm256_unpacklo_ps(t2, t3), u3 = _mm256_unpackhi_ps(t2, t3);
  const __m256 c[4] = {_mm256_shuffle_ps(u0, u2, 0x44), _mm256_shuffle_ps(u0, u2, 0xEE),
                       _mm256_shuffle_ps(u1, u3, 0x44), _mm256_shuffle_ps(u1, u3, 0xEE)};
  __builtin_memcpy(column, c, sizeof c);
}
/// The inverse of load_columns4: row k's float i = column[i][k].
inline void store_columns4(const F32x8 column[4], void* base, size_t stride) {
  char* p = static_cast<char*>(base);
  __m256 c[4];
  __builtin_memcpy(c, column, sizeof c);
  const __m256 u0 = _mm256_unpacklo_ps(c[0], c[1]), u1 = _mm256_unpackhi_ps(c[0], c[1]);
  const __m256 u2 = _mm256_unpacklo_ps(c[2], c[3]), u3 = _mm256_unpackhi_ps(c[2], c[3]);
  const __m256 r[4] = {_mm256_shuffle_ps(u0, u2, 0x44), _mm256_shuffle_ps(u0, u2, 0xEE),
                       _mm256_shuffle_ps(u1, u3, 0x44), _mm256_shuffle_ps(u1, u3, 0xEE)};
  for (int a = 0; a < 4; ++a) {  // r[a] holds rows a and a + 4
    _mm_storeu_ps(reinterpret_cast<float*>(p + a * stride), _mm256_castps256_ps128(r[a]));
    _mm_storeu_ps(reinterpret_cast<float*>(p + (a + 4) * stride), _mm256_extractf128_ps(r[a], 1));
  }
}

/// WavelengthDistribution::sample over lanes.
inline F32x8 sample_wavelength(const WavelengthDistribution& d, F32x8 u, F32x8* pdf) {
  const F32x8 t = u * Float(d.n - 1);
  const I32x8 k = t >= Float(d.n - 2) ? I32x8{} + (d.n - 2) : __builtin_convertvector(t, I32x8);
  const F32x8 a = gather(d.knots, k), b = gather(d.knots + 1, k);
  *pdf = 1 / (Float(d.n - 1) * (b - a));
  return a + (t - __builtin_convertvector(k, F32x8)) * (b - a);
}

/// The CIE table as rows {x̄, ȳ, z̄ at knot i, x̄, ȳ, z̄ at knot i + 1}: a lane's six values in
/// one 32-byte row, 8 lanes loaded and transposed (lanes::load_columns8) instead of six
/// gathers (microcoded: ~2.5x slower than row loads on the Zen 4 of docs/benchmarks.md).
struct alignas(32) CieRow {
  float v[8];
};
inline const CieRow* cie_rows() {
  static const std::vector<CieRow> rows = [] {
    std::vector<CieRow> r(tables::kCieSamples - 1);
    for (int i = 0; i + 1 < tables::kCieSamples; ++i)
      r[size_t(i)] = CieRow{{tables::kCieX[i], tables::kCieY[i], tables::kCieZ[i], tables::kCieX[i + 1],
                             tables::kCieY[i + 1], tables::kCieZ[i + 1], 0, 0}};
    return r;
  }();
  return rows.data();
}

/// cie_xyz_bar over lanes (0 outside the table).
inline Vec3x8 cie_xyz_bar(F32x8 lambda) {
  const F32x8 t = lambda - tables::kCieLambdaMin;
  const Float last = Float(tables::kCieSamples - 1);
  const I32x8 valid = (t >= 0) & ~(t > last);
  I32x8 i = t >= last ? I32x8{} + (tables::kCieSamples - 2) : __builtin_convertvector(t, I32x8);
  i = valid ? i : I32x8{};  // a row in the table; the lane is zeroed below
  const F32x8 f = t - __builtin_convertvector(i, F32x8);
  __m256 row[8];
  lanes::load_columns8(cie_rows()[0].v, 8, i, 0, row);
  auto lerp8 = [&](int c) {
    F32x8 a, b;
    __builtin_memcpy(&a, &row[c], sizeof a);
    __builtin_memcpy(&b, &row[3 + c], sizeof b);
    return select(valid, (1 - f) * a + f * b, F32x8{});
  };
  return {lerp8(0), lerp8(1), lerp8(2)};
}
}  // namespace lanes_detail
#endif

/// The camera stage of a group: samplers s[0 … n) started by start_pixel_samples_lanes on
/// pixel (x, y); each gets the film position, wavelengths and camera ray camera_sample
/// would give it, and is left at the dimension camera_sample leaves it at (5: film pair,
/// lens pair, wavelength). `splat`: film positions uniform in the pixel (else drawn from
/// `filter` around its centre). Every array holds kSampleLanes entries, initialised;
/// entries n … kSampleLanes − 1 of `rays` and `lambda` are overwritten with values to ignore.
/// With `cols` the rays go to its entries col0 … col0 + kSampleLanes − 1 instead of `rays`
/// (col0 + kSampleLanes ≤ kBatchColumns), for the path lanes, and the wavelengths there too.
inline void camera_rays_lanes(const Camera& cam, const WavelengthDistribution& wl, bool splat, const PixelFilter& filter,
                              int x, int y, Sampler* s, int n, Ray* rays, Vec2* film_pos, SampledWavelengths* lambda,
                              BatchColumns* cols = nullptr, int col0 = 0) {
  for (int k = 0; k < n; ++k) {
    film_pos[k] = sample_film_position(splat, filter, x, y, Vec2{s[k].batch[0], s[k].batch[kSobolBatch]});
    s[k].dimension = 5;
  }
#if KAURI_SAMPLE_LANES
  using namespace lanes_detail;
  // Wavelength i of each path at u + i/N (mod 1), u = the first coordinate of pair 2.
  // Lanes ≥ n are computed and dropped: fixed trip counts let the compiler build and
  // split the vectors in registers (with a trip count of n, lane by lane through memory).
  F32x8 u_lambda{};
  for (int k = 0; k < kSampleLanes; ++k) u_lambda[k] = k < n ? s[k].batch[2] : Float(0);
  static_assert(kSpectrumSamples == 4, "the wavelengths move as 8 x 4 transposes");
  F32x8 l[kSpectrumSamples], pdf[kSpectrumSamples];
  for (int i = 0; i < kSpectrumSamples; ++i) {
    F32x8 ui = u_lambda + Float(i) / kSpectrumSamples;
    ui = select(ui >= 1, ui - 1, ui);
    l[i] = sample_wavelength(wl, ui, &pdf[i]);
  }
  store_columns4(l, lambda[0].lambda, sizeof(SampledWavelengths));
  store_columns4(pdf, lambda[0].pdf, sizeof(SampledWavelengths));
  if (cols)
    for (int i = 0; i < kSpectrumSamples; ++i) __builtin_memcpy(cols->lambda[i] + col0, &l[i], sizeof(F32x8));
  if (cam.type == CameraType::Perspective && !(cam.lens_radius > 0)) {
    F32x8 fx{}, fy{};
    for (int k = 0; k < kSampleLanes; ++k) fx[k] = film_pos[k].x, fy[k] = film_pos[k].y;
    const F32x8 sx = 2 * fx / Float(cam.width) - 1;
    const F32x8 sy = 1 - 2 * fy / Float(cam.height);
    const Vec3x8 d_cam = normalize(Vec3x8{sx * cam.tan_half_x, sy * cam.tan_half_y, broadcast(-1)});
    const Vec3x8 d = normalize(apply(cam.camera_to_world.m, d_cam, 0));
    const Point3 o = cam.camera_to_world.point(Point3{0, 0, 0});
    if (cols) {
      const F32x8 oc[3] = {broadcast(o.x), broadcast(o.y), broadcast(o.z)}, dc[3] = {d.x, d.y, d.z};
      const F32x8 tmax = broadcast(kInfinity);
      for (int a = 0; a < 3; ++a) {
        __builtin_memcpy(cols->o[a] + col0, &oc[a], sizeof(F32x8));
        __builtin_memcpy(cols->d[a] + col0, &dc[a], sizeof(F32x8));
      }
      __builtin_memcpy(cols->tmax + col0, &tmax, sizeof(F32x8));
      return;
    }
    for (int k = 0; k < kSampleLanes; ++k) {
      rays[k] = Ray{};
      rays[k].o = o;
      rays[k].d = Vec3{d.x[k], d.y[k], d.z[k]};
    }
    return;
  }
#else
  for (int k = 0; k < n; ++k) {
    lambda[k] = sample_wavelengths(wl, s[k].batch[2]);
    if (cols) cols->set_wavelengths(col0 + k, lambda[k]);
  }
#endif
  for (int k = 0; k < n; ++k) {
    const Ray r = cam.generate_ray(film_pos[k], Vec2{s[k].batch[1], s[k].batch[kSobolBatch + 1]});
    if (cols) cols->set_ray(col0 + k, r);
    else rays[k] = r;
  }
}

/// The film stage's colour of a group: the RGB each path's output adds to the film, its
/// direct part and the colour of the lights its camera ray met (rgb_exact) as they are,
/// and the indirect clamped to luminance `clamp` (0: off), as the scalar render path
/// computed it. The paths' radiance sums are entries col0 … col0 + kSampleLanes − 1 of
/// `cols` (col0 + kSampleLanes ≤ kBatchColumns), their rgb_exact in `out`. Arrays of
/// kSampleLanes initialised entries; rgb[n …] are to be ignored.
inline void sample_rgb_lanes(const SceneView& sv, Float clamp, const BatchColumns& cols, int col0,
                             const PathOutput* out, const SampledWavelengths* lambda, int n, Vec3* rgb) {
#if KAURI_SAMPLE_LANES
  using namespace lanes_detail;
  const Float norm = 1 / (Float(kSpectrumSamples) * tables::kCieYIntegral);
  Vec3x8 direct{}, indirect{};
  F32x8 ls[kSpectrumSamples], pdfs[kSpectrumSamples], Ls[kSpectrumSamples], Lds[kSpectrumSamples];
  load_columns4(lambda[0].lambda, sizeof(SampledWavelengths), ls);
  load_columns4(lambda[0].pdf, sizeof(SampledWavelengths), pdfs);
  I32x8 radiance{};  // lanes with a radiance sum other than 0 (NaN included)
  for (int i = 0; i < kSpectrumSamples; ++i) {
    __builtin_memcpy(&Ls[i], cols.L[i] + col0, sizeof(F32x8));
    __builtin_memcpy(&Lds[i], cols.L_direct[i] + col0, sizeof(F32x8));
    radiance |= (Ls[i] != 0) | (Lds[i] != 0);
  }
  // A group whose paths gathered nothing (camera rays into the sky, whose colour is in
  // rgb_exact): the sums below would add zeros. ~1% of the environment scene's render.
  if (_mm256_testz_si256(__m256i(radiance), __m256i(radiance))) {
    for (int k = 0; k < kSampleLanes; ++k) rgb[k] = out[k].rgb_exact;
    return;
  }
  for (int i = 0; i < kSpectrumSamples; ++i) {
    const F32x8 l = ls[i], pdf = pdfs[i], L = Ls[i], Ld = Lds[i];
    const I32x8 has_pdf = pdf != 0;
    const F32x8 scale = select(has_pdf, norm / select(has_pdf, pdf, broadcast(1)), F32x8{});
    const Vec3x8 bar = cie_xyz_bar(l);
    const Vec3x8 c{select(has_pdf, bar.x * scale, F32x8{}), select(has_pdf, bar.y * scale, F32x8{}),
                   select(has_pdf, bar.z * scale, F32x8{})};
    direct = {direct.x + c.x * Ld, direct.y + c.y * Ld, direct.z + c.z * Ld};
    indirect = {indirect.x + c.x * L, indirect.y + c.y * L, indirect.z + c.z * L};
  }
  const Vec3x8 d = to_rgb(sv.xyz_to_rgb, direct), ind = to_rgb(sv.xyz_to_rgb, indirect);
  // clamp_luminance, lane by lane.
  const I32x8 clamped = (broadcast(clamp) > 0) & ~(indirect.y <= clamp);
  const F32x8 f = clamp / select(clamped, indirect.y, broadcast(1));
  const Vec3x8 r{d.x + select(clamped, ind.x * f, ind.x), d.y + select(clamped, ind.y * f, ind.y),
                 d.z + select(clamped, ind.z * f, ind.z)};
  for (int k = 0; k < kSampleLanes; ++k) rgb[k] = Vec3{r.x[k], r.y[k], r.z[k]} + out[k].rgb_exact;
#else
  for (int k = 0; k < n; ++k) {
    SampledSpectrum L, L_direct;
    for (int i = 0; i < kSpectrumSamples; ++i) L[i] = cols.L[i][col0 + k], L_direct[i] = cols.L_direct[i][col0 + k];
    const SampledXYZWeights to_xyz(lambda[k]);
    const Vec3 indirect_xyz = to_xyz(L);
    rgb[k] = sv.to_rgb(to_xyz(L_direct)) + out[k].rgb_exact +
             clamp_luminance(sv.to_rgb(indirect_xyz), indirect_xyz.y, clamp);
  }
#endif
}

}  // namespace kauri
