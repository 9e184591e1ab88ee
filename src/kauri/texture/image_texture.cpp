// Host side of image textures: the per-texel reflectance fit (image_texture.h).
#include "kauri/texture/image_texture.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace kauri {

std::vector<SigmoidPolynomial> texel_coefficients(const float* texels, int width, int height,
                                                  const RGBToSpectrumTable& table) {
  std::vector<SigmoidPolynomial> c(size_t(width) * size_t(height));
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < width; ++x) {
        const size_t i = size_t(y) * size_t(width) + size_t(x);
        c[i] = table(Vec3{texels[3 * i], texels[3 * i + 1], texels[3 * i + 2]});  // clamps to [0, 1]
      }
  });
  return c;
}

}  // namespace kauri
