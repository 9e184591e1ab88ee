// Host-side owners of the Distribution1D/2D device views.
#pragma once

#include <vector>

#include "kauri/sampler/sampling.h"

namespace kauri {

class Distribution1DStorage {
 public:
  Distribution1DStorage() = default;
  explicit Distribution1DStorage(std::vector<Float> func);
  Distribution1D view() const {
    return {func_.data(), cdf_.data(), int(func_.size()), integral_, pmf_.data()};
  }
  Float integral() const { return integral_; }
  size_t bytes() const { return (func_.size() + cdf_.size() + pmf_.size()) * sizeof(Float); }

 private:
  std::vector<Float> func_, cdf_, pmf_;
  Float integral_ = 0;
};

class Distribution2DStorage {
 public:
  Distribution2DStorage() = default;
  /// `func` is row-major, nv rows of nu values; the conditional rows' values and CDFs are
  /// kept one row after another (the layout Distribution2D documents).
  Distribution2DStorage(const std::vector<Float>& func, int nu, int nv);
  // Views point into the rows' heap buffers: moving keeps them valid, copying would not.
  Distribution2DStorage(Distribution2DStorage&&) = default;
  Distribution2DStorage& operator=(Distribution2DStorage&&) = default;
  Distribution2DStorage(const Distribution2DStorage&) = delete;
  Distribution2DStorage& operator=(const Distribution2DStorage&) = delete;
  Distribution2D view() const {
    return {conditional_views_.data(), marginal_.view(), nu_, nv_};
  }
  size_t bytes() const;

 private:
  std::vector<Float> func_, cdf_;  // the conditional rows: nv × nu values, nv × (nu + 1) CDF entries
  std::vector<Distribution1D> conditional_views_;
  Distribution1DStorage marginal_;
  int nu_ = 0, nv_ = 0;
};

}  // namespace kauri
