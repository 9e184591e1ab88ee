// Film reconstruction: filter splatting weights, clipping, the flat-field property of
// the weighted estimator, and the tile phases that keep splats race-free.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kauri/film/film.h"
#include "kauri/film/splat_lanes.h"
#include "kauri/render/renderer.h"
#include "kauri/scene/scene.h"

namespace kauri {
namespace {

struct TestFilm {
  int w, h;
  std::vector<PixelAccum> px;
  TestFilm(int w_, int h_) : w(w_), h(h_), px(size_t(w_) * size_t(h_)) {}
  FilmView view() { return FilmView{px.data(), w, h}; }
  const PixelAccum& at(int x, int y) const { return px[size_t(y) * size_t(w) + size_t(x)]; }
};

TEST(FilmSplat, MarginCoversTheFilterSupport) {
  PixelFilter f;
  f.radius = 0.5f;
  EXPECT_EQ(f.margin(), 0);
  f.radius = 1.0f;
  EXPECT_EQ(f.margin(), 1);
  f.radius = 2.0f;
  EXPECT_EQ(f.margin(), 2);
  f.radius = 2.6f;
  EXPECT_EQ(f.margin(), 3);
}

TEST(FilmSplat, BoxOfHalfAPixelIsOnePixelPerSample) {
  PixelFilter f;
  f.type = FilterType::Box;
  f.radius = 0.5f;
  TestFilm film(6, 5);
  // Including positions exactly on pixel edges: the half-open support gives them to one pixel.
  const Vec2 positions[] = {{2.0f, 3.0f}, {2.999f, 3.5f}, {0.0f, 0.0f}, {5.99f, 4.99f}};
  for (Vec2 p : positions) splat_sample(film.view(), f, p, Vec3{1, 2, 3}, 1);
  double total = 0;
  for (const PixelAccum& a : film.px) total += a.weight;
  EXPECT_DOUBLE_EQ(total, 4.0);
  EXPECT_DOUBLE_EQ(film.at(2, 3).weight, 2.0);
  EXPECT_DOUBLE_EQ(film.at(0, 0).weight, 1.0);
  EXPECT_DOUBLE_EQ(film.at(5, 4).weight, 1.0);
  EXPECT_DOUBLE_EQ(film.at(2, 3).rgb[2], 6.0);
}

TEST(FilmSplat, GaussianWeightsFollowTheFilter) {
  PixelFilter f;  // σ 0.5, radius 2
  TestFilm film(16, 16);
  const Vec2 p{8.25f, 7.5f};  // a quarter pixel left of pixel (8, 7)'s centre
  splat_sample(film.view(), f, p, Vec3{1, 1, 1}, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      double dx = double(p.x) - (x + 0.5), dy = double(p.y) - (y + 0.5);
      bool inside = dx >= -2 && dx < 2 && dy >= -2 && dy < 2;
      double want = inside ? std::exp(-(dx * dx + dy * dy) / (2 * 0.25)) : 0;
      EXPECT_NEAR(film.at(x, y).weight, want, 1e-6 * want + 1e-12) << x << ", " << y;
      EXPECT_DOUBLE_EQ(film.at(x, y).alpha, film.at(x, y).weight);
    }
}

// The radius-2 Gaussian's fixed 4×4 splat (splat_gaussian_4x4) and the general path it
// falls back to near the edges must both put the filter's weight on exactly the pixels
// of the half-open support: random positions, positions on pixel edges and centres (where a
// support boundary falls on a pixel centre) and one float step either side of them.
TEST(FilmSplat, EverySplatFollowsTheFilter) {
  PixelFilter f;  // σ 0.5, radius 2
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 12);
  std::vector<Vec2> positions;
  for (int k = 0; k < 300; ++k) positions.push_back({u(rng), u(rng)});
  for (float c : {0.0f, 0.5f, 2.0f, 2.5f, 5.0f, 5.5f, 9.5f, 11.5f, 11.0f})
    for (float x : {c, std::nextafter(c, 0.0f), std::nextafter(c, 20.0f)})
      if (x >= 0 && x < 12) positions.push_back({x, std::fmod(x * 7.3f, 12.0f)});
  int fast = 0;
  for (Vec2 p : positions) {
    TestFilm film(12, 12);
    splat_sample(film.view(), f, p, Vec3{1, 2, 3}, 1);
    int x0, y0;
    Float w4[4];
    fast += film_detail::gaussian_weights4(f, gaussian_step_ratio(f), p.x, &x0, w4) &&
            film_detail::gaussian_weights4(f, gaussian_step_ratio(f), p.y, &y0, w4) && x0 >= 0 && y0 >= 0 &&
            x0 + 3 < 12 && y0 + 3 < 12;
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 12; ++x) {
        const double dx = double(p.x - (Float(x) + 0.5f)), dy = double(p.y - (Float(y) + 0.5f));
        const bool inside = dx >= -2 && dx < 2 && dy >= -2 && dy < 2;
        const double want = inside ? std::exp(-(dx * dx + dy * dy) / (2 * 0.25)) : 0;
        const PixelAccum& a = film.at(x, y);
        ASSERT_NEAR(a.weight, want, 1e-5 * want + 1e-30) << p.x << ", " << p.y << " at " << x << ", " << y;
        ASSERT_EQ(a.weight > 0, inside) << p.x << ", " << p.y << " at " << x << ", " << y;
        ASSERT_NEAR(a.rgb[2], 3 * a.weight, 1e-12);
      }
  }
  EXPECT_GT(fast, 100);  // both paths were taken
  EXPECT_LT(fast, int(positions.size()));
}

// The two-exponential recurrence must match weight_1d, including narrow Gaussians on
// wide supports (where it falls back to one exponential per pixel).
TEST(FilmSplat, PolynomialExpMatchesExp) {
  // exp_poly (the splat's exponentials) over its whole domain |x| <= 80.
  double worst = 0;
  for (int i = -800000; i <= 800000; ++i) {
    const float x = float(i) * 1e-4f;
    const double want = std::exp(double(x)), got = double(exp_poly(x));
    worst = std::max(worst, std::fabs(got - want) / want);
  }
  EXPECT_LT(worst, 4e-7) << worst;
  EXPECT_EQ(exp_poly(0.0f), 1.0f);
}

TEST(FilmSplat, RecurrenceWeightsMatchTheFilter) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  for (float sigma : {0.1f, 0.3f, 0.5f, 1.0f, 3.0f})
    for (float radius : {0.5f, 1.0f, 2.0f, 3.3f, 8.0f}) {
      PixelFilter f;
      f.sigma = sigma;
      f.radius = radius;
      for (int k = 0; k < 200; ++k) {
        const float p = 20 + u(rng);
        const int i0 = 20 - f.margin(), i1 = 20 + f.margin();
        float w[18];
        filter_weights(f, p, i0, i1, w);
        for (int i = i0; i <= i1; ++i) {
          const float want = f.weight_1d(p - (float(i) + 0.5f));
          ASSERT_NEAR(w[i - i0], want, 1e-5f * want + 1e-30f) << sigma << " " << radius << " " << p << " " << i;
          ASSERT_TRUE(std::isfinite(w[i - i0]));
        }
      }
    }
}

TEST(FilmSplat, GroupSplatEqualsSampleBySample) {
  // splat_group against splat_sample, per group size, on pixels inside the image and on
  // its corners and edges (clipped windows), with positions on pixel edges among them.
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const PixelFilter f;
  const int w = 9, h = 7;
  const int pixels[][2] = {{4, 3}, {0, 0}, {8, 6}, {1, 5}, {7, 0}, {2, 3}};
  for (auto [x, y] : pixels) {
    for (int n = 1; n <= kSplatLanes; ++n) {
      TestFilm group(w, h), single(w, h);
      Vec2 pos[kSplatLanes];
      float v[kSplatLanes][4];
      for (int k = 0; k < n; ++k) {
        Float ux = uni(rng), uy = uni(rng);
        if (k == 1) ux = 0.5f;         // centre of the window's middle column
        if (k == 2) uy = 0;            // the pixel's top edge
        if (k == 3) ux = kOneMinusEpsilon;
        pos[k] = {Float(x) + ux, Float(y) + uy};
        for (int c = 0; c < 4; ++c) v[k][c] = c == 3 ? float(k % 2) : 3 * uni(rng);
        splat_sample(single.view(), f, pos[k], Vec3{v[k][0], v[k][1], v[k][2]}, v[k][3]);
      }
      ASSERT_TRUE(splat_group(group.view(), f, x, y, pos, v, n));
      for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
          const PixelAccum &a = group.at(px, py), &b = single.at(px, py);
          SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y << " n " << n << " at " << px << "," << py);
          EXPECT_NEAR(a.weight, b.weight, 2e-6 * (1 + b.weight));
          EXPECT_EQ(a.weight == 0, b.weight == 0);  // the same pixels reached
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.rgb[c], b.rgb[c], 2e-6 * (1 + std::fabs(b.rgb[c])));
          EXPECT_NEAR(a.alpha, b.alpha, 2e-6 * (1 + b.alpha));
        }
    }
  }
  // Filters it does not cover are left to splat_sample, with nothing added.
  TestFilm film(w, h);
  PixelFilter box;
  box.type = FilterType::Box;
  Vec2 pos[1] = {{4.5f, 3.5f}};
  const float v[1][4] = {{1, 1, 1, 1}};
  EXPECT_FALSE(splat_group(film.view(), box, 4, 3, pos, v, 1));
  PixelFilter wide;
  wide.radius = 3;
  EXPECT_FALSE(splat_group(film.view(), wide, 4, 3, pos, v, 1));
  for (const PixelAccum& p : film.px) EXPECT_EQ(p.weight, 0);
}

TEST(FilmSplat, GroupAlphaNeverExceedsItsWeight) {
  // A sample's alpha is 0 or 1, so a pixel's Σ w α must not exceed its Σ w, in float as in
  // reals: alpha = Σ w α / Σ w would otherwise land an ulp above 1 (the weight summed over
  // the lanes in another order than the products did that). All-1 groups: equal bit for bit.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const PixelFilter f;
  const int w = 7, h = 7;
  for (int trial = 0; trial < 400; ++trial) {
    TestFilm film(w, h);
    Vec2 pos[kSplatLanes];
    float v[kSplatLanes][4];
    const bool all_hit = trial % 2 == 0;
    for (int k = 0; k < kSplatLanes; ++k) {
      pos[k] = {3 + uni(rng), 3 + uni(rng)};
      v[k][0] = v[k][1] = v[k][2] = uni(rng);
      v[k][3] = all_hit || uni(rng) < 0.7f ? 1.0f : 0.0f;
    }
    ASSERT_TRUE(splat_group(film.view(), f, 3, 3, pos, v, kSplatLanes));
    for (const PixelAccum& p : film.px) {
      if (all_hit)
        ASSERT_EQ(p.alpha, p.weight) << "trial " << trial;
      else
        ASSERT_LE(p.alpha, p.weight) << "trial " << trial;
    }
  }
}

TEST(FilmSplat, ClipsAtTheImageEdges) {
  PixelFilter f;
  f.radius = 3.0f;
  TestFilm film(3, 2);
  splat_sample(film.view(), f, Vec2{0.01f, 1.99f}, Vec3{1, 1, 1}, 1);
  splat_sample(film.view(), f, Vec2{2.99f, 0.0f}, Vec3{1, 1, 1}, 1);
  for (const PixelAccum& a : film.px) EXPECT_GT(a.weight, 0);
}

// The weighted estimator Σ w L / Σ w is exact for a constant image, edges included.
TEST(FilmSplat, FlatFieldStaysFlatEverywhere) {
  PixelFilter f;
  TestFilm film(9, 7);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1);
  for (int y = 0; y < film.h; ++y)
    for (int x = 0; x < film.w; ++x)
      for (int s = 0; s < 4; ++s)
        splat_sample(film.view(), f, Vec2{Float(x) + u(rng), Float(y) + u(rng)}, Vec3{0.25f, 0.5f, 2.0f}, 1);
  for (const PixelAccum& a : film.px) {
    ASSERT_GT(a.weight, 0);
    EXPECT_NEAR(a.rgb[0] / a.weight, 0.25, 1e-6);
    EXPECT_NEAR(a.rgb[1] / a.weight, 0.5, 1e-6);
    EXPECT_NEAR(a.rgb[2] / a.weight, 2.0, 1e-6);
    EXPECT_NEAR(a.alpha / a.weight, 1.0, 1e-6);
  }
}

// Tiles of one phase, grown by the filter margin, must not overlap (no two threads
// write one pixel), and every tile must be in exactly one phase.
void expect_disjoint_phases(int w, int h, float radius, FilmReconstruction rec) {
  RenderSettings cfg;
  cfg.width = w;
  cfg.height = h;
  cfg.filter.radius = radius;
  cfg.reconstruction = rec;
  TileGrid g = make_tile_grid(cfg);
  const int m = rec == FilmReconstruction::Splat ? cfg.filter.margin() : 0;
  std::vector<int> seen(size_t(g.nx * g.ny), 0);
  for (const std::vector<int>& phase : g.phases) {
    std::vector<int> owner(size_t(w) * size_t(h), -1);
    for (int t : phase) {
      ++seen[size_t(t)];
      int x0 = (t % g.nx) * g.size, y0 = (t / g.nx) * g.size;
      for (int y = std::max(0, y0 - m); y < std::min(h, y0 + g.size + m); ++y)
        for (int x = std::max(0, x0 - m); x < std::min(w, x0 + g.size + m); ++x) {
          int& o = owner[size_t(y) * size_t(w) + size_t(x)];
          ASSERT_EQ(o, -1) << "tiles " << o << " and " << t << " share pixel " << x << ", " << y << " (" << w << "x"
                           << h << ", radius " << radius << ")";
          o = t;
        }
    }
  }
  for (int c : seen) EXPECT_EQ(c, 1);
}

TEST(TileGrid, SplatPhasesNeverShareAPixel) {
  for (FilmReconstruction rec : {FilmReconstruction::Splat, FilmReconstruction::FilterImportance})
    for (float radius : {0.5f, 1.5f, 2.0f, 4.0f, 8.0f})
      for (auto [w, h] : {std::pair{32, 32}, {33, 17}, {1, 1}, {640, 480}, {5, 300}})
        expect_disjoint_phases(w, h, radius, rec);
}

// A splat's footprint is bounded by kMaxFilterRadius: render() refuses larger filters
// instead of dropping samples.
TEST(FilmSplat, RenderRefusesFiltersWiderThanTheLimit) {
  Scene scene;
  scene.set_camera(CameraDesc{});  // an empty scene: every ray misses
  auto compiled = scene.compile(8, 8);
  RenderSettings cfg;
  cfg.width = cfg.height = 8;
  cfg.spp = 1;
  cfg.progress = false;
  cfg.filter.radius = kMaxFilterRadius + 1;
  EXPECT_THROW(render(*compiled, cfg), std::invalid_argument);
  cfg.filter.radius = kMaxFilterRadius;
  EXPECT_NO_THROW(render(*compiled, cfg));
}

TEST(TileGrid, SmallImagesGetEnoughTilesPerPhase) {
  RenderSettings cfg;
  cfg.width = cfg.height = 32;
  TileGrid g = make_tile_grid(cfg);
  ASSERT_EQ(g.phases.size(), 4u);
  for (const auto& phase : g.phases) EXPECT_GE(phase.size(), 16u);
}


TEST(FilmSplat, WindowOfManyGroupsEqualsSampleBySample) {
  // SplatWindow: a pixel's groups (full and partial, more than kMaxGroups so that it
  // flushes in between) summed per window pixel and lane, added once, against splat_sample
  // sample by sample; pixels inside the image and on its corners and edges.
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const PixelFilter f;
  ASSERT_TRUE(SplatWindow::applies(f));
  const int w = 9, h = 7;
  const int pixels[][2] = {{4, 3}, {0, 0}, {8, 6}, {1, 5}};
  for (auto [x, y] : pixels) {
    TestFilm window_film(w, h), single(w, h);
    SplatWindow window;
    const int groups = SplatWindow::kMaxGroups + 7;
    for (int g = 0; g < groups; ++g) {
      constexpr int L = SplatWindow::kLanes;  // 8, or 16 in the v4 core
      const int n = g % 3 == 2 ? 1 + g % L : L;
      Vec2 pos[SplatWindow::kLanes];
      float v[SplatWindow::kLanes][4];
      for (int k = 0; k < n; ++k) {
        pos[k] = {Float(x) + uni(rng), Float(y) + (g == 0 && k == 0 ? 0.0f : uni(rng))};
        for (int c = 0; c < 4; ++c) v[k][c] = c == 3 ? float((g + k) % 2) : 3 * uni(rng);
        splat_sample(single.view(), f, pos[k], Vec3{v[k][0], v[k][1], v[k][2]}, v[k][3]);
      }
      window.add(window_film.view(), f, x, y, pos, v, n);
    }
    window.flush(window_film.view(), x, y);
    window.flush(window_film.view(), x, y);  // nothing waiting: adds nothing
    for (int py = 0; py < h; ++py)
      for (int px = 0; px < w; ++px) {
        const PixelAccum &a = window_film.at(px, py), &b = single.at(px, py);
        SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y << " at " << px << "," << py);
        EXPECT_NEAR(a.weight, b.weight, 1e-5 * (1 + b.weight));
        EXPECT_EQ(a.weight == 0, b.weight == 0);  // the same pixels reached
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.rgb[c], b.rgb[c], 1e-5 * (1 + std::fabs(b.rgb[c])));
        EXPECT_NEAR(a.alpha, b.alpha, 1e-5 * (1 + b.alpha));
        EXPECT_LE(a.alpha, a.weight);
      }
  }
  PixelFilter box;
  box.type = FilterType::Box;
  EXPECT_FALSE(SplatWindow::applies(box));
  PixelFilter wide;
  wide.radius = 3;
  EXPECT_FALSE(SplatWindow::applies(wide));
}

TEST(FilmSplat, WindowAlphaNeverExceedsItsWeight) {
  // As GroupAlphaNeverExceedsItsWeight, summed over several groups before the flush.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const PixelFilter f;
  for (int trial = 0; trial < 200; ++trial) {
    TestFilm film(7, 7);
    SplatWindow window;
    const bool all_hit = trial % 2 == 0;
    for (int g = 0; g < 1 + trial % 9; ++g) {
      Vec2 pos[SplatWindow::kLanes];
      float v[SplatWindow::kLanes][4];
      for (int k = 0; k < SplatWindow::kLanes; ++k) {
        pos[k] = {3 + uni(rng), 3 + uni(rng)};
        v[k][0] = v[k][1] = v[k][2] = uni(rng);
        v[k][3] = all_hit || uni(rng) < 0.7f ? 1.0f : 0.0f;
      }
      window.add(film.view(), f, 3, 3, pos, v, SplatWindow::kLanes);
    }
    window.flush(film.view(), 3, 3);
    for (const PixelAccum& p : film.px) {
      if (all_hit)
        ASSERT_EQ(p.alpha, p.weight) << "trial " << trial;
      else
        ASSERT_LE(p.alpha, p.weight) << "trial " << trial;
    }
  }
}

}  // namespace
}  // namespace kauri
