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
#include <vector>

#include "kauri/core/math.h"
#include "kauri/spectral/spectrum.h"

namespace kauri {

enum class TextureWrap : uint8_t { Repeat, Clamp };

struct ImageTexture {
  const float* texels = nullptr;  // width × height × 3, row 0 = top row of the image
  int width = 0, height = 0;
  TextureWrap wrap = TextureWrap::Repeat;
  const RGBToSpectrumTable* table = nullptr;  // working space's RGB → spectrum table
  // Each texel's reflectance as sigmoid coefficients, fitted once when the scene compiles
  // (texel_coefficients); null: fitted at lookup time from the filtered RGB.
  const SigmoidPolynomial* coeffs = nullptr;

  /// Linear RGB at texture coordinates `uv` (bilinear).
  KAURI_HOST_DEVICE Vec3 rgb(Vec2 uv) const {
    const Footprint f = footprint(uv);
    return texel(f.x[0], f.y[0]) * f.w[0] + texel(f.x[1], f.y[0]) * f.w[1] + texel(f.x[0], f.y[1]) * f.w[2] +
           texel(f.x[1], f.y[1]) * f.w[3];
  }

  /// Reflectance at the path's wavelengths: the bilinear blend of the four texels'
  /// spectra. RGB is linear in the spectrum, so the blend's colour is the blend of the
  /// texels' colours (each texel round-trips to its RGB within the table's fit), as
  /// upsampling the filtered RGB gives; but the fit happened once per texel at compile
  /// time instead of a table search and trilinear lookup at every hit (textured bench
  /// scene: 3% of the render time).
  KAURI_HOST_DEVICE SampledSpectrum albedo(Vec2 uv, const SampledWavelengths& lambda) const {
    if (!coeffs) return albedo(uv).sample(lambda);
    const Footprint f = footprint(uv);
    SampledSpectrum s = sample_sigmoid(coeff(f.x[0], f.y[0]), lambda) * f.w[0];
    s += sample_sigmoid(coeff(f.x[1], f.y[0]), lambda) * f.w[1];
    s += sample_sigmoid(coeff(f.x[0], f.y[1]), lambda) * f.w[2];
    s += sample_sigmoid(coeff(f.x[1], f.y[1]), lambda) * f.w[3];
    return s;
  }

  /// Reflectance spectrum of the (bilinearly filtered) RGB at `uv`: the filtered colour is
  /// upsampled, not the texels (textures without per-texel fits, tests).
  KAURI_HOST_DEVICE Spectrum albedo(Vec2 uv) const { return Spectrum::make_rgb_albedo((*table)(rgb(uv))); }

 private:
  /// The four texels around `uv` (columns x[0..1], rows y[0..1], wrapped) and their
  /// bilinear weights (x0y0, x1y0, x0y1, x1y1).
  struct Footprint {
    int x[2], y[2];
    Float w[4];
  };
  KAURI_HOST_DEVICE Footprint footprint(Vec2 uv) const {
    // Continuous texel coordinates with texel centres at integers.
    Float x = uv.x * Float(width) - Float(0.5);
    Float y = (1 - uv.y) * Float(height) - Float(0.5);
    Float fx = std::floor(x), fy = std::floor(y);
    Float dx = x - fx, dy = y - fy;
    int x0 = int(fx), y0 = int(fy);
    Footprint f;
    f.x[0] = wrap_index(x0, width, wrap);
    f.x[1] = next_index(f.x[0], x0 + 1, width, wrap);
    f.y[0] = wrap_index(y0, height, wrap);
    f.y[1] = next_index(f.y[0], y0 + 1, height, wrap);
    f.w[0] = (1 - dx) * (1 - dy);
    f.w[1] = dx * (1 - dy);
    f.w[2] = (1 - dx) * dy;
    f.w[3] = dx * dy;
    return f;
  }
  /// Texel index i (any integer) wrapped into [0, n) (repeat_index: no division within a
  /// period of the image).
  KAURI_HOST_DEVICE static int wrap_index(int i, int n, TextureWrap w) {
    if (w == TextureWrap::Clamp) return i < 0 ? 0 : (i >= n ? n - 1 : i);
    return repeat_index(i, n);
  }
  /// wrap_index(i + 1, n, w) from `wrapped` = wrap_index(i, n, w): a repeating neighbour's
  /// index without wrapping i + 1 again.
  KAURI_HOST_DEVICE static int next_index(int wrapped, int i_plus_1, int n, TextureWrap w) {
    if (w == TextureWrap::Clamp) return wrap_index(i_plus_1, n, w);
    return wrapped + 1 == n ? 0 : wrapped + 1;
  }
  /// Texel (x, y), already wrapped.
  KAURI_HOST_DEVICE Vec3 texel(int x, int y) const {
    const float* t = texels + 3 * (size_t(y) * size_t(width) + size_t(x));
    return {t[0], t[1], t[2]};
  }
  KAURI_HOST_DEVICE const SigmoidPolynomial& coeff(int x, int y) const {
    return coeffs[size_t(y) * size_t(width) + size_t(x)];
  }
};

// ---- host (image_texture.cpp) ----

/// The sigmoid coefficients of every texel of a width × height × 3 RGB image (clamped
/// to [0, 1], as reflectances are), for ImageTexture::coeffs. Parallel over rows.
std::vector<SigmoidPolynomial> texel_coefficients(const float* texels, int width, int height,
                                                  const RGBToSpectrumTable& table);

}  // namespace kauri
