#include "kauri/sampler/distribution.h"

#include <cmath>
#include <stdexcept>

namespace kauri {

Distribution1DStorage::Distribution1DStorage(std::vector<Float> func) : func_(std::move(func)) {
  if (func_.empty()) throw std::invalid_argument("Distribution1D: empty function");
  const size_t n = func_.size();
  cdf_.assign(n + 1, 0);
  // Accumulate in double so large tables keep a monotone, accurate CDF.
  double sum = 0;
  std::vector<double> acc(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!(func_[i] >= 0) || !std::isfinite(func_[i]))
      throw std::invalid_argument("Distribution1D: negative or non-finite value");
    sum += double(func_[i]) / double(n);
    acc[i + 1] = sum;
  }
  integral_ = Float(sum);
  for (size_t i = 1; i <= n; ++i) cdf_[i] = sum > 0 ? Float(acc[i] / sum) : Float(double(i) / double(n));
  cdf_[n] = 1;
}

Distribution2DStorage::Distribution2DStorage(const std::vector<Float>& func, int nu, int nv) : nu_(nu), nv_(nv) {
  if (nu <= 0 || nv <= 0 || func.size() != size_t(nu) * size_t(nv))
    throw std::invalid_argument("Distribution2D: size mismatch");
  std::vector<Float> row_integrals(nv);
  conditional_.reserve(nv);
  for (int v = 0; v < nv; ++v) {
    conditional_.emplace_back(std::vector<Float>(func.begin() + size_t(v) * nu, func.begin() + size_t(v + 1) * nu));
    row_integrals[v] = conditional_.back().integral();
  }
  marginal_ = Distribution1DStorage(std::move(row_integrals));
  conditional_views_.reserve(nv);
  for (const auto& c : conditional_) conditional_views_.push_back(c.view());
}

size_t Distribution2DStorage::bytes() const {
  size_t b = marginal_.bytes() + conditional_views_.size() * sizeof(Distribution1D);
  for (const auto& c : conditional_) b += c.bytes();
  return b;
}

}  // namespace kauri
