// Film: per-pixel accumulation of beauty and data AOVs.
//
// Pixel reconstruction uses filter importance sampling (Ernst et al. 2006):
// each sample's film position is drawn from the filter around its own pixel
// centre and the sample counts for that pixel with weight 1, so a pixel is
// touched only by the thread rendering it (deterministic, lock-free).
#pragma once

#include "kauri/sampler/sampling.h"

namespace kauri {

enum class FilterType : uint8_t { Gaussian, Box };

struct PixelFilter {
  FilterType type = FilterType::Gaussian;
  Float sigma = 0.5f;   // Gaussian standard deviation (pixels)
  Float radius = 2.0f;  // support half-width (pixels): 4σ, as Mitsuba 3's default

  /// Offset from the pixel centre, distributed ∝ the filter.
  KAURI_HOST_DEVICE Vec2 sample(Vec2 u) const {
    if (type == FilterType::Box) return {(2 * u.x - 1) * radius, (2 * u.y - 1) * radius};
    return {sample_truncated_gaussian(u.x, sigma, radius), sample_truncated_gaussian(u.y, sigma, radius)};
  }
  KAURI_HOST_DEVICE Float pdf(Vec2 p) const {
    if (type == FilterType::Box)
      return (std::fabs(p.x) <= radius && std::fabs(p.y) <= radius) ? 1 / sqr(2 * radius) : 0;
    return truncated_gaussian_pdf(p.x, sigma, radius) * truncated_gaussian_pdf(p.y, sigma, radius);
  }
};

/// Running sums for one pixel (double sums keep long renders exact enough).
struct PixelAccum {
  double rgb[3] = {0, 0, 0};
  double alpha = 0;
  // Albedo as a ratio estimator: Σ XYZ(albedo·white) / Σ XYZ(white) over the same
  // wavelengths cancels most spectral noise (exact for flat reflectances).
  double albedo_xyz[3] = {0, 0, 0};
  double white_xyz[3] = {0, 0, 0};
  double normal[3] = {0, 0, 0};
  double depth = 0;
  uint32_t depth_count = 0;
  uint32_t samples = 0;
};

}  // namespace kauri
