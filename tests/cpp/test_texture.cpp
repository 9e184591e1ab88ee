// Image texture lookups: bilinear reconstruction, wrap modes, orientation, the
// reflectance spectrum of a filtered colour, and the per-texel fit's blend of spectra.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kauri/spectral/color_space.h"
#include "kauri/texture/image_texture.h"

namespace kauri {
namespace {

// 2 × 2 texture: row 0 (top) = red, green; row 1 (bottom) = blue, white.
const std::vector<float> kTexels = {1, 0, 0, 0, 1, 0,  //
                                    0, 0, 1, 1, 1, 1};

ImageTexture make(TextureWrap wrap) {
  return ImageTexture{kTexels.data(), 2, 2, wrap, &rgb_to_spectrum_table(ColorSpaceId::LinearSRGB)};
}

void expect_rgb(Vec3 got, Vec3 want) {
  EXPECT_NEAR(got.x, want.x, 1e-6f);
  EXPECT_NEAR(got.y, want.y, 1e-6f);
  EXPECT_NEAR(got.z, want.z, 1e-6f);
}

TEST(ImageTexture, TexelCentresReturnTexelsWithVUpwards) {
  ImageTexture t = make(TextureWrap::Clamp);
  expect_rgb(t.rgb({0.25f, 0.75f}), {1, 0, 0});  // top-left texel is at v = 3/4
  expect_rgb(t.rgb({0.75f, 0.75f}), {0, 1, 0});
  expect_rgb(t.rgb({0.25f, 0.25f}), {0, 0, 1});
  expect_rgb(t.rgb({0.75f, 0.25f}), {1, 1, 1});
}

TEST(ImageTexture, BilinearBetweenTexelCentres) {
  ImageTexture t = make(TextureWrap::Clamp);
  expect_rgb(t.rgb({0.5f, 0.5f}), {0.5f, 0.5f, 0.5f});       // mean of the four
  expect_rgb(t.rgb({0.5f, 0.75f}), {0.5f, 0.5f, 0});         // between red and green
  expect_rgb(t.rgb({0.25f + 0.125f, 0.25f}), {0.25f, 0.25f, 1});  // a quarter from blue to white
}

TEST(ImageTexture, ClampHoldsEdgeTexels) {
  ImageTexture t = make(TextureWrap::Clamp);
  expect_rgb(t.rgb({0.0f, 0.75f}), {1, 0, 0});
  expect_rgb(t.rgb({-3.0f, 5.0f}), {1, 0, 0});
  expect_rgb(t.rgb({7.0f, -2.0f}), {1, 1, 1});
}

TEST(ImageTexture, RepeatIsPeriodicAndBlendsAcrossTheSeam) {
  ImageTexture t = make(TextureWrap::Repeat);
  for (float du : {-2.0f, -1.0f, 1.0f, 3.0f}) {
    expect_rgb(t.rgb({0.25f + du, 0.75f - du}), {1, 0, 0});
    expect_rgb(t.rgb({0.6f + du, 0.3f + du}), t.rgb({0.6f, 0.3f}));
  }
  // u = 0 lies halfway between the last column and the first: red and green average.
  expect_rgb(t.rgb({0.0f, 0.75f}), {0.5f, 0.5f, 0});
}

// The lookup's wrapping (a compare for coordinates within one period, the remainder
// beyond) against the bilinear definition with Euclidean remainders, on a 5 × 3 texture
// of distinct texels, at (u, v) from within the image to three periods away, seams and
// texel edges included.
TEST(ImageTexture, RepeatMatchesTheRemainderDefinitionEverywhere) {
  const int w = 5, h = 3;
  std::vector<float> texels(size_t(w * h * 3));
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = float((i * 37) % 101) / 100;
  const ImageTexture t{texels.data(), w, h, TextureWrap::Repeat, &rgb_to_spectrum_table(ColorSpaceId::LinearSRGB)};
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  auto texel = [&](int x, int y) {
    const float* p = &texels[3 * size_t(wrap(y, h) * w + wrap(x, w))];
    return Vec3{p[0], p[1], p[2]};
  };
  std::mt19937 rng(1801);
  std::uniform_real_distribution<float> coord(-3.0f, 4.0f);
  std::vector<Vec2> uvs = {{0, 0}, {1, 1}, {0.1f, 0.5f}, {-1, 2}, {0.9f, 0.99f}, {-0.1f, -0.1f}, {3.5f, -2.5f}};
  for (int i = 0; i < 2000; ++i) uvs.push_back({coord(rng), coord(rng)});
  for (int i = 0; i < 200; ++i) uvs.push_back({float(int(coord(rng) * w)) / w, float(int(coord(rng) * h)) / h});
  for (Vec2 uv : uvs) {
    const float x = uv.x * float(w) - 0.5f, y = (1 - uv.y) * float(h) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y), dx = x - fx, dy = y - fy;
    const int x0 = int(fx), y0 = int(fy);
    const Vec3 want = texel(x0, y0) * ((1 - dx) * (1 - dy)) + texel(x0 + 1, y0) * (dx * (1 - dy)) +
                      texel(x0, y0 + 1) * ((1 - dx) * dy) + texel(x0 + 1, y0 + 1) * (dx * dy);
    const Vec3 got = t.rgb(uv);
    ASSERT_NEAR(got.x, want.x, 1e-6f) << uv.x << " " << uv.y;
    ASSERT_NEAR(got.y, want.y, 1e-6f) << uv.x << " " << uv.y;
    ASSERT_NEAR(got.z, want.z, 1e-6f) << uv.x << " " << uv.y;
  }
}

TEST(ImageTexture, AlbedoSpectrumReproducesTheFilteredColour) {
  // The texture's spectrum at a point is the RGB→spectrum fit of the filtered colour,
  // so a grey in between texels gives a constant spectrum of that grey.
  ImageTexture t = make(TextureWrap::Clamp);
  Spectrum s = t.albedo({0.5f, 0.5f});
  for (float lambda : {400.0f, 500.0f, 600.0f, 700.0f}) EXPECT_NEAR(s(lambda), 0.5f, 1e-4f);
  Spectrum white = t.albedo({0.75f, 0.25f});
  EXPECT_NEAR(white(550.0f), 1.0f, 1e-6f);
}


/// The texture with its per-texel fits, as the scene compiler makes it.
struct FittedTexture {
  std::vector<float> texels;
  std::vector<SigmoidPolynomial> coeffs;
  ImageTexture t;
  FittedTexture(std::vector<float> rgb, int w, int h, TextureWrap wrap, ColorSpaceId cs = ColorSpaceId::LinearSRGB)
      : texels(std::move(rgb)) {
    const RGBToSpectrumTable& table = rgb_to_spectrum_table(cs);
    coeffs = texel_coefficients(texels.data(), w, h, table);
    t = ImageTexture{texels.data(), w, h, wrap, &table, coeffs.data()};
  }
};

SampledWavelengths wavelengths_at(Float l0) {
  SampledWavelengths w;
  for (int i = 0; i < kSpectrumSamples; ++i) {
    w.lambda[i] = l0 + Float(i) * 110;
    w.pdf[i] = 1;
  }
  return w;
}

TEST(ImageTexture, FittedTexelCentresGiveThatTexelsSpectrum) {
  FittedTexture f(kTexels, 2, 2, TextureWrap::Clamp);
  const RGBToSpectrumTable& table = *f.t.table;
  const Vec2 centre[4] = {{0.25f, 0.75f}, {0.75f, 0.75f}, {0.25f, 0.25f}, {0.75f, 0.25f}};
  for (int k = 0; k < 4; ++k) {
    SigmoidPolynomial p = table(Vec3{kTexels[3 * k], kTexels[3 * k + 1], kTexels[3 * k + 2]});
    for (Float l0 : {360.0f, 401.5f, 497.0f}) {
      SampledWavelengths w = wavelengths_at(l0);
      SampledSpectrum got = f.t.albedo(centre[k], w);
      for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_FLOAT_EQ(got[i], p(w.lambda[i])) << "texel " << k;
    }
  }
}

TEST(ImageTexture, FittedBlendUsesTheBilinearFootprintInBothWrapModes) {
  // Grey texels have constant spectra, so the blend at any uv is the filtered grey: the
  // per-texel path's weights and wrapping must be those of rgb().
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> grey(0.02f, 0.98f), uv(-2.5f, 3.5f);
  std::vector<float> g;
  for (int i = 0; i < 5 * 3; ++i) {
    float v = grey(rng);
    g.insert(g.end(), {v, v, v});
  }
  for (TextureWrap wrap : {TextureWrap::Clamp, TextureWrap::Repeat}) {
    FittedTexture f(g, 5, 3, wrap);
    for (int n = 0; n < 200; ++n) {
      Vec2 p{uv(rng), uv(rng)};
      SampledSpectrum s = f.t.albedo(p, wavelengths_at(380));
      for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_NEAR(s[i], f.t.rgb(p).x, 2e-5f) << p.x << ", " << p.y;
    }
  }
}

TEST(ImageTexture, FittedBlendHasTheFilteredColour) {
  // RGB is linear in the spectrum: the blend's colour under the space's illuminant is the
  // bilinear colour, to the table's round-trip accuracy (and it stays a reflectance).
  const std::vector<float> colours = {0.8f, 0.2f, 0.1f, 0.1f, 0.6f, 0.3f,  //
                                      0.2f, 0.3f, 0.7f, 0.9f, 0.9f, 0.85f};
  for (ColorSpaceId id : {ColorSpaceId::LinearSRGB, ColorSpaceId::ACEScg}) {
    const RGBColorSpace& cs = color_space(id);
    FittedTexture f(colours, 2, 2, TextureWrap::Repeat, id);
    for (Vec2 p : {Vec2{0.5f, 0.5f}, Vec2{0.4f, 0.9f}, Vec2{0.1f, 0.3f}, Vec2{0.66f, 0.2f}}) {
      Vec3 xyz;
      double y_white = 0;
      for (int l = 360; l <= 830; l += kSpectrumSamples) {
        SampledWavelengths w;
        for (int i = 0; i < kSpectrumSamples; ++i) w.lambda[i] = Float(std::min(l + i, 830));
        SampledSpectrum s = f.t.albedo(p, w);
        for (int i = 0; i < kSpectrumSamples && l + i <= 830; ++i) {
          Float lit = (*cs.illuminant)(w.lambda[i]);
          EXPECT_GE(s[i], 0);
          EXPECT_LE(s[i], 1);
          xyz += cie_xyz_bar(w.lambda[i]) * (s[i] * lit);
          y_white += double(cie_xyz_bar(w.lambda[i]).y * lit);
        }
      }
      Vec3 got = cs.to_rgb(xyz / Float(y_white)), want = f.t.rgb(p);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 5e-3f) << "uv " << p.x << ", " << p.y << " channel " << c;
    }
  }
}

}  // namespace
}  // namespace kauri
