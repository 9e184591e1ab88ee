#include "kauri/light/env_importance.h"

#include <algorithm>
#include <cmath>

namespace kauri {

namespace {

Float row_sin_theta(int y, int h) { return std::sin(kPi * (Float(y) + 0.5f) / Float(h)); }

/// Each texel's maximum luminance over its 3 × 3 neighbourhood (u wraps, v clamps).
std::vector<Float> dilated_luminance(const std::vector<Float>& lum, int w, int h) {
  std::vector<Float> m(size_t(w) * size_t(h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Float v = 0;
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          int yy = std::min(std::max(y + oy, 0), h - 1), xx = ((x + ox) % w + w) % w;
          v = std::max(v, lum[size_t(yy) * size_t(w) + size_t(xx)]);
        }
      m[size_t(y) * size_t(w) + size_t(x)] = v;
    }
  return m;
}

}  // namespace

std::vector<Float> env_importance(const std::vector<Float>& lum, int w, int h) {
  std::vector<Float> weight = dilated_luminance(lum, w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) weight[size_t(y) * size_t(w) + size_t(x)] *= row_sin_theta(y, h);
  return weight;
}

std::vector<Float> env_importance_compensated(const std::vector<Float>& lum, int w, int h) {
  std::vector<Float> weight = dilated_luminance(lum, w, h);
  double sum = 0, area = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      sum += double(weight[size_t(y) * size_t(w) + size_t(x)]) * double(row_sin_theta(y, h));
      area += double(row_sin_theta(y, h));
    }
  const double mean = area > 0 ? sum / area : 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Rounding in the mean must not leave a constant image with a few texels of
      // spurious weight: differences below 1e-5 of the mean count as none.
      Float& v = weight[size_t(y) * size_t(w) + size_t(x)];
      const double d = double(v) - mean;
      v = d > 1e-5 * mean ? Float(d) * row_sin_theta(y, h) : 0;
    }
  return weight;
}

}  // namespace kauri
