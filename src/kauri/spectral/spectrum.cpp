// Host helpers for Spectrum: CIE integration and table lookups.
#include "kauri/spectral/spectrum.h"

#include <cmath>
#include <string>

namespace kauri {

Vec3 spectrum_to_xyz(const Spectrum& s) {
  // Sum over the 1 nm table (the CMFs are tabulated at 1 nm, so this is the
  // rectangle rule the CIE itself uses for tristimulus sums; CIE 15:2004 sec. 7.1).
  double x = 0, y = 0, z = 0;
  for (int i = 0; i < tables::kCieSamples; ++i) {
    double v = s(tables::kCieLambdaMin + Float(i));
    x += v * double(tables::kCieX[i]);
    y += v * double(tables::kCieY[i]);
    z += v * double(tables::kCieZ[i]);
  }
  double inv = 1.0 / double(tables::kCieYIntegral);
  return {Float(x * inv), Float(y * inv), Float(z * inv)};
}

Float spectrum_to_y(const Spectrum& s) { return spectrum_to_xyz(s).y; }

Vec3 spectrum_to_xyz_expected(const Spectrum& s) {
  // Gauss–Legendre nodes and weights on [0, 1].
  const double node[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  const double weight[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  double x = 0, y = 0, z = 0;
  for (int i = 0; i + 1 < tables::kCieSamples; ++i)
    for (int q = 0; q < 3; ++q) {
      const double t = node[q];
      const double v = double(s(Float(double(tables::kCieLambdaMin) + double(i) + t))) * weight[q];
      x += v * ((1 - t) * double(tables::kCieX[i]) + t * double(tables::kCieX[i + 1]));
      y += v * ((1 - t) * double(tables::kCieY[i]) + t * double(tables::kCieY[i + 1]));
      z += v * ((1 - t) * double(tables::kCieZ[i]) + t * double(tables::kCieZ[i + 1]));
    }
  const double inv = 1.0 / double(tables::kCieYIntegral);
  return {Float(x * inv), Float(y * inv), Float(z * inv)};
}

Float spectrum_max_value(const Spectrum& s) {
  switch (s.type) {
    case SpectrumType::Constant: return s.constant;
    case SpectrumType::RGBAlbedo: return s.rgb.poly.max_value();
    case SpectrumType::RGBUnbounded: return s.rgb.scale * s.rgb.poly.max_value();
    case SpectrumType::Blackbody: return s.blackbody.scale;  // peak-normalised (peak may lie outside 360..830)
    default: break;
  }
  Float m = 0;
  for (int i = 0; i < tables::kCieSamples; ++i) m = fmax_(m, s(tables::kCieLambdaMin + Float(i)));
  return m;
}

DenselySampled metal_eta(const tables::MetalIOR& m) {
  return {m.eta, tables::kMetalLambdaMin, tables::kMetalLambdaStep, tables::kMetalSamples};
}
DenselySampled metal_k(const tables::MetalIOR& m) {
  return {m.k, tables::kMetalLambdaMin, tables::kMetalLambdaStep, tables::kMetalSamples};
}

namespace tables {

const MetalIOR* find_metal(std::string_view name) {
  for (int i = 0; i < kMetalCount; ++i)
    if (name == kMetals[i].name) return &kMetals[i];
  return nullptr;
}

std::string known_metal_names() {
  std::string out;
  for (int i = 0; i < kMetalCount; ++i) {
    if (i) out += ", ";
    out += kMetals[i].name;
  }
  return out;
}

}  // namespace tables
}  // namespace kauri
