// Image textures at render time: plain data (a pointer to linear RGB texels owned by
// the compiled scene) plus lookups usable on CPU and GPU.
//
// Convention (OpenGL / USD UsdUVTexture / pbrt): (u, v) = (0, 0) is the bottom-left
// corner of the image, v grows upwards; texel centres sit at half-integers. Lookups are
// bilinear with repeat or clamp-to-edge wrapping, and no mip-mapping yet: a texture
// seen minified aliases, which the pixel filter averages out with enough samples.
#pragma once

#include <cmath>
#include <cstdint>

#include "kauri/core/math.h"
#include "kauri/spectral/spectrum.h"

namespace kauri {

enum class TextureWrap : uint8_t { Repeat, Clamp };

struct ImageTexture {
  const float* texels = nullptr;  // width × height × 3, row 0 = top row of the image
  int width = 0, height = 0;
  TextureWrap wrap = TextureWrap::Repeat;
  const RGBToSpectrumTable* table = nullptr;  // working space's RGB → spectrum table

  /// Linear RGB at texture coordinates `uv` (bilinear).
  KAURI_HOST_DEVICE Vec3 rgb(Vec2 uv) const {
    // Continuous texel coordinates with texel centres at integers.
    Float x = uv.x * Float(width) - Float(0.5);
    Float y = (1 - uv.y) * Float(height) - Float(0.5);
    Float fx = std::floor(x), fy = std::floor(y);
    Float dx = x - fx, dy = y - fy;
    int x0 = int(fx), y0 = int(fy);
    return texel(x0, y0) * ((1 - dx) * (1 - dy)) + texel(x0 + 1, y0) * (dx * (1 - dy)) +
           texel(x0, y0 + 1) * ((1 - dx) * dy) + texel(x0 + 1, y0 + 1) * (dx * dy);
  }

  /// Reflectance spectrum of the (bilinearly filtered) RGB at `uv`: the filtered colour is
  /// upsampled, not the texels, so the spectrum's RGB is the filtered RGB.
  KAURI_HOST_DEVICE Spectrum albedo(Vec2 uv) const { return Spectrum::make_rgb_albedo((*table)(rgb(uv))); }

 private:
  KAURI_HOST_DEVICE static int wrap_index(int i, int n, TextureWrap w) {
    if (w == TextureWrap::Clamp) return i < 0 ? 0 : (i >= n ? n - 1 : i);
    int r = i % n;
    return r < 0 ? r + n : r;
  }
  KAURI_HOST_DEVICE Vec3 texel(int x, int y) const {
    const float* t = texels + 3 * (size_t(wrap_index(y, height, wrap)) * size_t(width) + size_t(wrap_index(x, width, wrap)));
    return {t[0], t[1], t[2]};
  }
};

}  // namespace kauri
