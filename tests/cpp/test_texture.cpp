// Image texture lookups: bilinear reconstruction, wrap modes, orientation, and the
// reflectance spectrum of a filtered colour.
#include <gtest/gtest.h>

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

TEST(ImageTexture, AlbedoSpectrumReproducesTheFilteredColour) {
  // The texture's spectrum at a point is the RGB→spectrum fit of the filtered colour,
  // so a grey in between texels gives a constant spectrum of that grey.
  ImageTexture t = make(TextureWrap::Clamp);
  Spectrum s = t.albedo({0.5f, 0.5f});
  for (float lambda : {400.0f, 500.0f, 600.0f, 700.0f}) EXPECT_NEAR(s(lambda), 0.5f, 1e-4f);
  Spectrum white = t.albedo({0.75f, 0.25f});
  EXPECT_NEAR(white(550.0f), 1.0f, 1e-6f);
}

}  // namespace
}  // namespace kauri
