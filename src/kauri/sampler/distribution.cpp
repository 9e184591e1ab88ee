#include "kauri/sampler/distribution.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kauri {

namespace {
/// The CDF of the n values at `func` into cdf[0 … n] (cdf[0] = 0, cdf[n] = 1; a uniform
/// one where they sum to 0), and their integral over [0, 1). Accumulated in double so
/// large tables keep a monotone, accurate CDF.
Float build_cdf(const Float* func, size_t n, Float* cdf) {
  double sum = 0;
  std::vector<double> acc(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!(func[i] >= 0) || !std::isfinite(func[i]))
      throw std::invalid_argument("Distribution1D: negative or non-finite value");
    sum += double(func[i]) / double(n);
    acc[i + 1] = sum;
  }
  cdf[0] = 0;
  for (size_t i = 1; i <= n; ++i) cdf[i] = sum > 0 ? Float(acc[i] / sum) : Float(double(i) / double(n));
  cdf[n] = 1;
  return Float(sum);
}
}  // namespace

Distribution1DStorage::Distribution1DStorage(std::vector<Float> func) : func_(std::move(func)) {
  if (func_.empty()) throw std::invalid_argument("Distribution1D: empty function");
  cdf_.assign(func_.size() + 1, 0);
  integral_ = build_cdf(func_.data(), func_.size(), cdf_.data());
  // The stored probabilities are what the view without them computes, bit for bit.
  const Distribution1D computed{func_.data(), cdf_.data(), int(func_.size()), integral_};
  pmf_.resize(func_.size());
  for (size_t i = 0; i < func_.size(); ++i) pmf_[i] = computed.discrete_pmf(int(i));
}

Distribution2DStorage::Distribution2DStorage(const std::vector<Float>& func, int nu, int nv)
    : func_(func), cdf_(size_t(nu + 1) * size_t(std::max(nv, 0))), nu_(nu), nv_(nv) {
  if (nu <= 0 || nv <= 0 || func.size() != size_t(nu) * size_t(nv))
    throw std::invalid_argument("Distribution2D: size mismatch");
  // The rows one after another (Distribution2D's layout), each a Distribution1D view.
  std::vector<Float> row_integrals(nv);
  conditional_views_.reserve(nv);
  for (int v = 0; v < nv; ++v) {
    const Float* f = func_.data() + size_t(v) * size_t(nu);
    Float* c = cdf_.data() + size_t(v) * size_t(nu + 1);
    row_integrals[v] = build_cdf(f, size_t(nu), c);
    conditional_views_.push_back({f, c, nu, row_integrals[v]});
  }
  marginal_ = Distribution1DStorage(std::move(row_integrals));
}

size_t Distribution2DStorage::bytes() const {
  return marginal_.bytes() + conditional_views_.size() * sizeof(Distribution1D) +
         (func_.size() + cdf_.size()) * sizeof(Float);
}

}  // namespace kauri
