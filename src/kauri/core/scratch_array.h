// Fixed-size arrays of per-hit scratch values that are written before they are read.
#pragma once

#include "kauri/core/platform.h"

namespace kauri {

/// N values of T, left uninitialised on construction. The per-hit arrays of spectra in
/// BSDF and layer evaluation (8–16 SampledSpectrum each) were zeroed by SampledSpectrum's
/// default initialiser at every hit, although only the first n entries are ever written
/// and read; that zeroing measured 2–4% of render time on the benchmark scenes.
/// Trivially copyable when T is (the union has no constructor to run).
template <class T, int N>
struct ScratchArray {
  union {
    T v[N];
  };
  KAURI_HOST_DEVICE ScratchArray() {}
  KAURI_HOST_DEVICE T& operator[](int i) { return v[i]; }
  KAURI_HOST_DEVICE const T& operator[](int i) const { return v[i]; }
  KAURI_HOST_DEVICE T* data() { return v; }
  KAURI_HOST_DEVICE const T* data() const { return v; }
};

}  // namespace kauri
