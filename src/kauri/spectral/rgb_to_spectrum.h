// Jakob & Hanika 2019, "A Low-Dimensional Function Space for Efficient Spectral
// Upsampling" (CGF 38(2)): a reflectance is s(c0 l^2 + c1 l + c2) with the algebraic
// sigmoid s; a per-colour-space table maps rgb in [0,1]^3 to (c0, c1, c2).
#pragma once

#include <cmath>

#include "kauri/core/math.h"

namespace kauri {

/// s(x) = 1/2 + x / (2 sqrt(1 + x^2)) of the quadratic c0 l^2 + c1 l + c2 (l in nm).
struct SigmoidPolynomial {
  Float c0 = 0, c1 = 0, c2 = 0;

  /// The sigmoid maps R onto (0,1), so every coefficient triple is a valid
  /// reflectance (paper, eq. 3). The argument is clamped to ±2^60 instead of testing for
  /// infinity: s(±2^60) is exactly 1 or 0 in float, x² cannot overflow, and with no branch
  /// a loop over wavelengths runs as one 4-wide computation (sample_sigmoid).
  KAURI_HOST_DEVICE static Float sigmoid(Float x) {
    constexpr Float kBound = 0x1p60f;
    x = fmin_(fmax_(x, -kBound), kBound);
    return Float(0.5) + x / (2 * std::sqrt(1 + x * x));
  }
  KAURI_HOST_DEVICE Float operator()(Float lambda) const {
    return sigmoid((c0 * lambda + c1) * lambda + c2);  // Horner form
  }
  /// Largest value over [360, 830] nm: the sigmoid is monotone, so the extremum of
  /// the quadratic is at an end point or at its vertex -c1 / (2 c0).
  KAURI_HOST_DEVICE Float max_value() const {
    Float m = fmax_((*this)(360), (*this)(830));
    if (c0 != 0) {
      Float vertex = -c1 / (2 * c0);
      if (vertex >= 360 && vertex <= 830) m = fmax_(m, (*this)(vertex));
    }
    return m;
  }
};

/// Coefficient table for one RGB colour space (layout: docs/spectral.md).
/// data[m][zi][yi][xi][c]: m = index of the largest rgb component, zi indexes
/// `scale` (the value of that component), xi/yi the other two components divided
/// by it (uniform), c the three coefficients in nm.
struct RGBToSpectrumTable {
  int res = 0;
  const float* scale = nullptr;
  const float* data = nullptr;

  /// Sentinel for greys at 0 or 1: s(-/+8192) rounds to exactly 0/1 in float.
  static constexpr Float kSaturated = 8192;

  /// Coefficients for rgb (clamped to [0,1]).
  KAURI_HOST_DEVICE SigmoidPolynomial operator()(Vec3 rgb) const {
    for (int i = 0; i < 3; ++i) rgb[i] = clamp(rgb[i], 0, 1);
    if (rgb.x == rgb.y && rgb.y == rgb.z) return grey(rgb.x);
    int m = rgb.x >= rgb.y ? (rgb.x >= rgb.z ? 0 : 2) : (rgb.y >= rgb.z ? 1 : 2);
    Float z = rgb[m];
    // The other two components relative to the largest one lie in [0,1].
    Float x = rgb[(m + 1) % 3] * Float(res - 1) / z;
    Float y = rgb[(m + 2) % 3] * Float(res - 1) / z;
    int xi = x >= Float(res - 1) ? res - 2 : int(x);
    int yi = y >= Float(res - 1) ? res - 2 : int(y);
    int zi = find_interval(z);
    Float dx = x - Float(xi), dy = y - Float(yi);
    Float dz = (z - scale[zi]) / (scale[zi + 1] - scale[zi]);
    Float c[3];
    for (int i = 0; i < 3; ++i) c[i] = trilinear(m, xi, yi, zi, dx, dy, dz, i);
    return {c[0], c[1], c[2]};
  }

  /// r = g = b = v in closed form: a constant spectrum s(c2) = v needs
  /// c2 = (v - 1/2) / sqrt(v (1 - v)) (invert s).
  KAURI_HOST_DEVICE static SigmoidPolynomial grey(Float v) {
    if (v <= 0) return {0, 0, -kSaturated};
    if (v >= 1) return {0, 0, kSaturated};
    return {0, 0, (v - Float(0.5)) / std::sqrt(v * (1 - v))};
  }

 private:
  /// Largest zi in [0, res-2] with scale[zi] <= z (binary search on the monotone nodes).
  KAURI_HOST_DEVICE int find_interval(Float z) const {
    int lo = 0, hi = res - 2;
    while (lo < hi) {
      int mid = (lo + hi + 1) / 2;
      if (scale[mid] <= z) lo = mid; else hi = mid - 1;
    }
    return lo;
  }
  KAURI_HOST_DEVICE Float at(int m, int xi, int yi, int zi, int c) const {
    return data[((((m * res + zi) * res + yi) * res + xi) * 3) + c];
  }
  KAURI_HOST_DEVICE Float trilinear(int m, int xi, int yi, int zi, Float dx, Float dy, Float dz,
                                    int c) const {
    auto bilerp = [&](int z) {
      Float a = lerp(dx, at(m, xi, yi, z, c), at(m, xi + 1, yi, z, c));
      Float b = lerp(dx, at(m, xi, yi + 1, z, c), at(m, xi + 1, yi + 1, z, c));
      return lerp(dy, a, b);
    };
    return lerp(dz, bilerp(zi), bilerp(zi + 1));
  }
};

}  // namespace kauri
