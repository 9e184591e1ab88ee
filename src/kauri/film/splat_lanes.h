// Splatting a pixel's group of samples at once (the render loop's film stage).
//
// With the default filter (Gaussian, radius 2) every sample of pixel (x, y) lands on
// pixels of the 5 × 5 window around it. Added one at a time (splat_sample) each sample
// costs 16 updates of the film's double sums, ~400 instructions a sample with the weights.
// Here a group of up to 8 samples, one per vector lane, is reduced per window pixel first:
//   S(i, j) = Σ_k w_x,k(i) w_y,k(j) (r, g, b, α)_k   and   W(i, j) = Σ_k w_x,k(i) w_y,k(j),
// in float across the lanes, then each of the 25 window pixels is updated once. The weights
// are weight_1d's (exp_poly instead of splat_sample's two-exponential recurrence, so pixel
// values move by float rounding, ~1e-6 relative). Host CPU code; false where it does not
// apply (another filter or radius, no AVX2): the caller splats sample by sample.
#pragma once

#include <type_traits>

#include "kauri/core/lanes.h"
#include "kauri/film/film.h"

#define KAURI_SPLAT_LANES KAURI_LANES_AVX2

namespace kauri {

/// Samples a group splat holds at most.
inline constexpr int kSplatLanes = 8;

#if KAURI_SPLAT_LANES
namespace film_detail {
using lanes::F32x8;
using lanes::I32x8;

/// round(x) toward −∞, lane by lane.
inline F32x8 floor_lanes(F32x8 x) { return __builtin_ia32_roundps256(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
#if KAURI_LANES_AVX512
inline lanes::F32x16 floor_lanes(lanes::F32x16 x) {
  return lanes::F32x16(_mm512_roundscale_ps(__m512(x), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
}
#endif

/// exp_poly (core/math.h) over the lanes of F (8 or 16 floats), I its integer vector.
template <class F, class I>
inline F exp_poly_lanes(F x) {
  const F n = floor_lanes(x * 1.44269504f + 0.5f);
  const I e = (__builtin_convertvector(n, I) + 127) << 23;
  F scale;  // 2^n
  __builtin_memcpy(&scale, &e, sizeof scale);
  return exp_poly_reduced(x, n) * scale;
}

/// Filter weights of window pixels c − 2 … c + 2 (along one axis) for the lanes' positions
/// p: weight_1d(p − (c − 2 + i + ½)), 0 outside the support [−r, r).
template <class F, class I>
inline void window_weights(const PixelFilter& f, int c, F p, F w[5]) {
  const Float a = 1 / (2 * f.sigma * f.sigma);
  for (int i = 0; i < 5; ++i) {
    const F d = p - (Float(c - 2 + i) + 0.5f);
    const I inside = (d >= -f.radius) & (d < f.radius);
    const F x = -a * d * d;  // outside the support possibly below exp_poly's range: clamped, then dropped
    w[i] = inside ? exp_poly_lanes<F, I>(x < -80 ? F{} - 80 : x) : F{};
  }
}

/// (Σ a, Σ b, Σ c, Σ d) over the 8 lanes of each.
inline __m128 lane_sums4(__m256 a, __m256 b, __m256 c, __m256 d) {
  const __m256 ab = _mm256_hadd_ps(a, b), cd = _mm256_hadd_ps(c, d);
  const __m256 abcd = _mm256_hadd_ps(ab, cd);  // per 128-bit half: partial sums of a, b, c, d
  return _mm_add_ps(_mm256_castps256_ps128(abcd), _mm256_extractf128_ps(abcd, 1));
}

/// Σ a over the 8 lanes by lane_sums4's tree, ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7)):
/// the film's weight sum, so that Σ w α ≤ Σ w holds in float as it does in reals for
/// α ≤ 1 (float addition is monotone; another tree could round Σ w one ulp below Σ w α
/// and give a pixel an alpha above 1).
inline float lane_sum_pairwise(__m256 a) {
  const __m256 h = _mm256_hadd_ps(a, a);
  const __m256 hh = _mm256_hadd_ps(h, h);
  return _mm_cvtss_f32(_mm_add_ss(_mm256_castps256_ps128(hh), _mm256_extractf128_ps(hh, 1)));
}

/// SplatWindow's lanes: one vector of floats, 16 in the x86-64-v4 core (AVX-512).
inline constexpr int kWindowLanes = KAURI_LANES_AVX512 ? 16 : 8;
using WindowF = std::conditional_t<kWindowLanes == 16, lanes::F32x16, F32x8>;
using WindowI = std::conditional_t<kWindowLanes == 16, lanes::I32x16, I32x8>;

/// The lanes as one AVX2 register: 16 lanes folded onto 8 (lane k plus lane k + 8), the
/// same fold for every sum, so that the trees above stay one order for all of them.
inline __m256 fold8(const float* a) {
#if KAURI_LANES_AVX512
  if constexpr (kWindowLanes == 16) return _mm256_add_ps(_mm256_load_ps(a), _mm256_load_ps(a + 8));
#endif
  return _mm256_load_ps(a);
}
}  // namespace film_detail
#endif

/// Adds samples k < n of pixel (x, y) (film_pos[k] inside that pixel, beauty v[k] = r, g, b,
/// α) to the film as n splat_sample<kAddWeight> calls would, up to float rounding. False,
/// with nothing added, unless the filter is the radius-2 Gaussian and vectors are available.
template <bool kAddWeight = true>
inline bool splat_group(const FilmView& film, const PixelFilter& f, int x, int y, const Vec2* film_pos,
                        const float (*v)[4], int n) {
#if KAURI_SPLAT_LANES
  using namespace film_detail;
  if (f.type != FilterType::Gaussian || f.radius != 2 || n < 1 || n > kSplatLanes) return false;
  constexpr int kWindow = 5;  // pixels x − 2 … x + 2: the centres a radius-2 support can hold
  if (f.radius * f.radius / (2 * f.sigma * f.sigma) > 80) return false;  // exp_poly's range inside the support
  // Weights per window column / row and lane; lanes ≥ n, placed four radii away, weigh 0.
  F32x8 px_pos, py_pos;
  for (int k = 0; k < kSplatLanes; ++k) {
    px_pos[k] = k < n ? film_pos[k].x : Float(x) + 4 * f.radius;
    py_pos[k] = k < n ? film_pos[k].y : Float(y) + 4 * f.radius;
  }
  F32x8 wx[kWindow], wy[kWindow];
  window_weights<F32x8, I32x8>(f, x, px_pos, wx);
  window_weights<F32x8, I32x8>(f, y, py_pos, wy);
  // The beauty's channels across the lanes (lanes ≥ n: 0).
  alignas(32) float vc[4][kSplatLanes];
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < kSplatLanes; ++k) vc[c][k] = k < n ? v[k][c] : 0.0f;
  const __m256 r = _mm256_load_ps(vc[0]), g = _mm256_load_ps(vc[1]), b = _mm256_load_ps(vc[2]),
               alpha = _mm256_load_ps(vc[3]);
  for (int j = 0; j < kWindow; ++j) {
    const int py = y - 2 + j;
    if (py < 0 || py >= film.height) continue;
    const __m256 wrow = __m256(wy[j]);
    for (int i = 0; i < kWindow; ++i) {
      const int px = x - 2 + i;
      if (px < 0 || px >= film.width) continue;
      const __m256 w = _mm256_mul_ps(wrow, __m256(wx[i]));
      const float w_sum = lane_sum_pairwise(w);
      if (w_sum == 0) continue;  // no sample reaches this pixel
      const __m128 s = lane_sums4(_mm256_mul_ps(w, r), _mm256_mul_ps(w, g), _mm256_mul_ps(w, b),
                                  _mm256_mul_ps(w, alpha));
      PixelAccum& p = film.at(px, py);
      // rgb and alpha are adjacent doubles (PixelAccum): one 4-wide double addition.
      _mm256_storeu_pd(p.rgb, _mm256_add_pd(_mm256_loadu_pd(p.rgb), _mm256_cvtps_pd(s)));
      if (kAddWeight) p.weight += double(w_sum);
    }
  }
  return true;
#else
  (void)film, (void)f, (void)x, (void)y, (void)film_pos, (void)v, (void)n;
  return false;
#endif
}

/// A pixel's samples splatted group by group into sums per window pixel, channel and lane
/// (float; kWindowLanes = 8, or 16 in the x86-64-v4 core), added to the film once at the end
/// (flush): the reduction across the lanes, the conversion to double and the film's loads
/// and stores once per pixel instead of once per group of 8 (splat_group). A group then
/// costs its weights and 25 × 5 vector multiply-adds. The film gets the same sums as from
/// splat_group per group, up to float rounding (each lane's sum runs over the pixel's
/// groups in float before the tree across lanes); every lane adds w · α and w in the same
/// order, so Σ w α ≤ Σ w still holds (see lane_sum_pairwise). A render's pixel sums at
/// most kMaxGroups groups before a flush, so that float sums of long renders stay within
/// ~10⁻⁵ of the double ones.
class SplatWindow {
 public:
  static constexpr int kMaxGroups = 64;

  /// Whether add() applies to filter `f` (the radius-2 Gaussian, vectors available).
  static bool applies(const PixelFilter& f) {
#if KAURI_SPLAT_LANES
    return f.type == FilterType::Gaussian && f.radius == 2 && !(f.radius * f.radius / (2 * f.sigma * f.sigma) > 80);
#else
    (void)f;
    return false;
#endif
  }
  /// Samples add() takes at once.
#if KAURI_SPLAT_LANES
  static constexpr int kLanes = film_detail::kWindowLanes;
#else
  static constexpr int kLanes = 8;
#endif
  /// Adds samples k < n ≤ kLanes of pixel (x, y) as splat_group would (applies(f) must hold);
  /// flushes into `film` first when kMaxGroups groups are waiting.
  void add(const FilmView& film, const PixelFilter& f, int x, int y, const Vec2* film_pos, const float (*v)[4], int n);
  /// Adds the sums to the film's pixels around (x, y) and starts again from zero.
  void flush(const FilmView& film, int x, int y);

 private:
#if KAURI_SPLAT_LANES
  alignas(64) float sum_[5][5][5][kLanes];  // [row j][column i][r, g, b, α, w][lane]
#endif
  int groups_ = 0;
};

#if KAURI_SPLAT_LANES
inline void SplatWindow::add(const FilmView& film, const PixelFilter& f, int x, int y, const Vec2* film_pos,
                             const float (*v)[4], int n) {
  using namespace film_detail;
  if (groups_ == kMaxGroups) flush(film, x, y);
  if (groups_ == 0) __builtin_memset(sum_, 0, sizeof sum_);
  ++groups_;
  WindowF px_pos, py_pos;  // lanes ≥ n, placed four radii away, weigh 0
  for (int k = 0; k < kLanes; ++k) {
    px_pos[k] = k < n ? film_pos[k].x : Float(x) + 4 * f.radius;
    py_pos[k] = k < n ? film_pos[k].y : Float(y) + 4 * f.radius;
  }
  WindowF wx[5], wy[5];
  window_weights<WindowF, WindowI>(f, x, px_pos, wx);
  window_weights<WindowF, WindowI>(f, y, py_pos, wy);
  WindowF c[4] = {};
  for (int k = 0; k < n; ++k) c[0][k] = v[k][0], c[1][k] = v[k][1], c[2][k] = v[k][2], c[3][k] = v[k][3];
  auto accumulate = [](float* sum, WindowF add) {
    WindowF a;
    __builtin_memcpy(&a, sum, sizeof a);
    a += add;
    __builtin_memcpy(sum, &a, sizeof a);
  };
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      const WindowF w = wy[j] * wx[i];
      for (int ch = 0; ch < 4; ++ch) accumulate(sum_[j][i][ch], w * c[ch]);
      accumulate(sum_[j][i][4], w);
    }
}

inline void SplatWindow::flush(const FilmView& film, int x, int y) {
  using namespace film_detail;
  if (groups_ == 0) return;
  groups_ = 0;
  for (int j = 0; j < 5; ++j) {
    const int py = y - 2 + j;
    if (py < 0 || py >= film.height) continue;
    for (int i = 0; i < 5; ++i) {
      const int px = x - 2 + i;
      if (px < 0 || px >= film.width) continue;
      const float (*a)[kLanes] = sum_[j][i];
      const float w_sum = lane_sum_pairwise(fold8(a[4]));
      if (w_sum == 0) continue;  // no sample reaches this pixel
      const __m128 s = lane_sums4(fold8(a[0]), fold8(a[1]), fold8(a[2]), fold8(a[3]));
      PixelAccum& p = film.at(px, py);
      _mm256_storeu_pd(p.rgb, _mm256_add_pd(_mm256_loadu_pd(p.rgb), _mm256_cvtps_pd(s)));
      p.weight += double(w_sum);
    }
  }
}
#else
inline void SplatWindow::add(const FilmView&, const PixelFilter&, int, int, const Vec2*, const float (*)[4], int) {}
inline void SplatWindow::flush(const FilmView&, int, int) {}
#endif

}  // namespace kauri
