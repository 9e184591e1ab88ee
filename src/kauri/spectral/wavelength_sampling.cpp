// Host construction of the wavelength densities (see wavelength_sampling.h).
#include "kauri/spectral/wavelength_sampling.h"

#include <cmath>
#include <stdexcept>

#include "kauri/spectral/spectral_tables.h"

namespace kauri {

std::vector<float> inverse_cdf_knots(const float* density, int n) {
  const int m = tables::kCieSamples - 1;  // 1 nm intervals
  if (n < 2) throw std::invalid_argument("inverse_cdf_knots: need at least 2 knots");
  std::vector<double> cdf(size_t(m) + 1, 0.0);
  for (int i = 0; i < m; ++i) {
    if (!(density[i] > 0) || !std::isfinite(density[i]))
      throw std::invalid_argument("inverse_cdf_knots: the density must be positive and finite");
    cdf[size_t(i) + 1] = cdf[size_t(i)] + 0.5 * (double(density[i]) + double(density[i + 1]));
  }
  const double total = cdf[size_t(m)];
  std::vector<float> knots(static_cast<size_t>(n));
  int i = 0;
  for (int k = 0; k < n; ++k) {
    double target = total * double(k) / double(n - 1);
    while (i < m - 1 && cdf[size_t(i) + 1] < target) ++i;
    double f = (target - cdf[size_t(i)]) / (cdf[size_t(i) + 1] - cdf[size_t(i)]);
    knots[size_t(k)] = float(double(tables::kCieLambdaMin) + double(i) + std::fmin(std::fmax(f, 0.0), 1.0));
  }
  knots.front() = tables::kCieLambdaMin;
  knots.back() = tables::kCieLambdaMin + float(m);
  for (int k = 1; k < n; ++k)
    if (!(knots[size_t(k)] > knots[size_t(k) - 1]))
      throw std::invalid_argument("inverse_cdf_knots: too many knots for float spacing");
  return knots;
}

std::vector<float> output_wavelength_knots(const Float xyz_to_rgb[3][3], const float* illuminant, int n) {
  // Σ_c |r̄_c(λ)| I(λ), normalised to mean 1, then flattened and floored (the header says
  // why). Exponent and illuminant were chosen on the bench scenes' relMSE at 64 spp:
  // against (Σ_c |r̄_c|)^0.6 without I, envmap −6%, hangar −3%, glossy −1.5%, cornell
  // and textured −0.7%; exponents 0.4-0.6 and I^0.5-1.25 are within 1% of this choice.
  const int s = tables::kCieSamples;
  std::vector<double> a(static_cast<size_t>(s));
  double mean = 0;
  for (int i = 0; i < s; ++i) {
    const double xyz[3] = {double(tables::kCieX[i]), double(tables::kCieY[i]), double(tables::kCieZ[i])};
    double sum = 0;
    for (int c = 0; c < 3; ++c)
      sum += std::fabs(double(xyz_to_rgb[c][0]) * xyz[0] + double(xyz_to_rgb[c][1]) * xyz[1] + double(xyz_to_rgb[c][2]) * xyz[2]);
    a[size_t(i)] = sum * double(illuminant[i]);
    mean += a[size_t(i)] / s;
  }
  std::vector<float> density(static_cast<size_t>(s));
  for (int i = 0; i < s; ++i) density[size_t(i)] = float(std::sqrt(a[size_t(i)] / mean) + 0.02);
  return inverse_cdf_knots(density.data(), n);
}

}  // namespace kauri
