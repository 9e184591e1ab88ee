#include "kauri/light/env_importance.h"

#include <algorithm>
#include <cmath>

namespace kauri {

std::vector<Float> env_importance(const std::vector<Float>& lum, int w, int h) {
  std::vector<Float> weight(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y) {
    Float sin_theta = std::sin(kPi * (Float(y) + 0.5f) / Float(h));
    for (int x = 0; x < w; ++x) {
      Float m = 0;
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          int yy = std::min(std::max(y + oy, 0), h - 1), xx = ((x + ox) % w + w) % w;
          m = std::max(m, lum[size_t(yy) * size_t(w) + size_t(xx)]);
        }
      weight[size_t(y) * size_t(w) + size_t(x)] = m * sin_theta;
    }
  }
  return weight;
}

}  // namespace kauri
