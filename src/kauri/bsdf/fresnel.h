// Fresnel reflectance for dielectric and conducting interfaces.
#pragma once

#include "kauri/spectral/sampled.h"

namespace kauri {

/// Unpolarised Fresnel reflectance at a dielectric interface of relative IOR
/// `eta` = η_t/η_i; `cos_i` < 0 means the ray arrives from the inside.
KAURI_HOST_DEVICE inline Float fresnel_dielectric(Float cos_i, Float eta) {
  cos_i = clamp(cos_i, -1, 1);
  if (cos_i < 0) {
    eta = 1 / eta;
    cos_i = -cos_i;
  }
  Float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;  // total internal reflection
  Float cos_t = safe_sqrt(1 - sin2_t);
  Float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  Float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return (r_par * r_par + r_perp * r_perp) / 2;
}

/// Fresnel reflectance of a conductor with complex IOR η + iκ (relative to the
/// outside medium), written with real arithmetic so it runs on any device
/// (the a² + b² form of the complex Snell/Fresnel relations, e.g. Born & Wolf §14.2).
KAURI_HOST_DEVICE inline Float fresnel_conductor(Float cos_i, Float eta, Float k) {
  cos_i = clamp(std::fabs(cos_i), 0, 1);
  Float cos2 = cos_i * cos_i, sin2 = 1 - cos2;
  Float eta2 = eta * eta, k2 = k * k;
  Float t0 = eta2 - k2 - sin2;
  Float a2b2 = safe_sqrt(t0 * t0 + 4 * eta2 * k2);
  Float a = safe_sqrt((a2b2 + t0) / 2);
  Float t1 = a2b2 + cos2, t2 = 2 * a * cos_i;
  Float rs = (t1 - t2) / (t1 + t2);
  Float t3 = cos2 * a2b2 + sin2 * sin2, t4 = t2 * sin2;
  Float rp = rs * (t3 - t4) / (t3 + t4);
  Float r = (rs + rp) / 2;
  return std::isfinite(r) ? clamp(r, 0, 1) : Float(1);
}

KAURI_HOST_DEVICE inline SampledSpectrum fresnel_conductor(Float cos_i, const SampledSpectrum& eta,
                                                           const SampledSpectrum& k) {
  SampledSpectrum r;
  for (int i = 0; i < kSpectrumSamples; ++i) r[i] = fresnel_conductor(cos_i, eta[i], k[i]);
  return r;
}

/// Refracts `wi` about `n` (same side as wi) with relative IOR `eta`; false on TIR.
KAURI_HOST_DEVICE inline bool refract(Vec3 wi, Vec3 n, Float eta, Vec3* wt, Float* eta_p = nullptr) {
  Float cos_i = dot(n, wi);
  if (cos_i < 0) {
    eta = 1 / eta;
    cos_i = -cos_i;
    n = -n;
  }
  Float sin2_t = fmax_(0, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return false;
  Float cos_t = safe_sqrt(1 - sin2_t);
  *wt = -wi / eta + (cos_i / eta - cos_t) * n;
  if (eta_p) *eta_p = eta;
  return true;
}

}  // namespace kauri
