// RGB working spaces. Convention (see docs/spectral.md): an RGB value is interpreted in
// the working space and lifted to a spectrum against that space's own illuminant (D65
// for linear sRGB, ACES D60 for ACEScg); the film converts XYZ straight to the working
// space with no chromatic adaptation. So RGB (1,1,1) light on RGB (1,1,1) albedo
// renders (1,1,1) in either space.
#pragma once

#include <string_view>

#include "kauri/core/math.h"
#include "kauri/spectral/rgb_to_spectrum.h"
#include "kauri/spectral/spectral_tables.h"
#include "kauri/spectral/spectrum.h"
#include "kauri/spectral/wavelength_sampling.h"

namespace kauri {

enum class ColorSpaceId { LinearSRGB, ACEScg };

/// Device-portable description of a working space (built once on the host).
struct RGBColorSpace {
  ColorSpaceId id;
  Float xyz_to_rgb[3][3];
  Float rgb_to_xyz[3][3];
  const DenselySampled* illuminant;   ///< the space's white, scaled to Y = 1
  const RGBToSpectrumTable* table;    ///< Jakob-Hanika coefficients for this space
  WavelengthDistribution wavelengths; ///< path wavelengths for an image in this space

  KAURI_HOST_DEVICE Vec3 to_rgb(Vec3 xyz) const { return apply(xyz_to_rgb, xyz); }
  KAURI_HOST_DEVICE Vec3 to_xyz(Vec3 rgb) const { return apply(rgb_to_xyz, rgb); }

  KAURI_HOST_DEVICE static Vec3 apply(const Float m[3][3], Vec3 v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
};

/// Primaries and white as CIE xy chromaticities.
struct ColorSpaceDefinition {
  double r[2], g[2], b[2], white[2];
};
/// IEC 61966-2-1 (Rec. 709 primaries, D65 white).
inline constexpr ColorSpaceDefinition kLinearSRGBDefinition{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06},
                                                            {0.3127, 0.3290}};
/// ACEScg = AP1 primaries, ACES white (S-2014-004).
inline constexpr ColorSpaceDefinition kACEScgDefinition{{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044},
                                                        {0.32168, 0.33767}};

/// "srgb" / "linear_srgb" / "acescg" (case-sensitive); false if unknown.
inline bool parse_color_space(std::string_view name, ColorSpaceId* out) {
  if (name == "srgb" || name == "linear_srgb") { *out = ColorSpaceId::LinearSRGB; return true; }
  if (name == "acescg") { *out = ColorSpaceId::ACEScg; return true; }
  return false;
}
inline const char* color_space_name(ColorSpaceId id) {
  return id == ColorSpaceId::ACEScg ? "acescg" : "linear_srgb";
}

inline const ColorSpaceDefinition& color_space_definition(ColorSpaceId id) {
  return id == ColorSpaceId::ACEScg ? kACEScgDefinition : kLinearSRGBDefinition;
}
/// The space's illuminant, un-normalised, on the 1 nm CIE grid.
inline const float* color_space_illuminant_table(ColorSpaceId id) {
  return id == ColorSpaceId::ACEScg ? tables::kAcesD60 : tables::kCieD65;
}

/// XYZ (Y = 1) of chromaticity xy.
inline void xy_to_xyz(const double xy[2], double out[3]) {
  out[0] = xy[0] / xy[1];
  out[1] = 1;
  out[2] = (1 - xy[0] - xy[1]) / xy[1];
}

/// Inverse of a 3x3 matrix by the adjugate (Cramer's rule); returns false if singular.
inline bool invert3x3(const double m[3][3], double out[3][3]) {
  double cof[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      cof[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
    }
  double det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
  if (det == 0) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = cof[j][i] / det;
  return true;
}

/// RGB->XYZ: columns are the primaries' XYZ, each scaled so that RGB (1,1,1) maps to
/// the white with Y = 1 (solve P s = W for the scales s; SMPTE RP 177 derivation).
inline void rgb_to_xyz_matrix(const ColorSpaceDefinition& d, double out[3][3]) {
  double p[3][3], w[3], inv[3][3];
  const double* prim[3] = {d.r, d.g, d.b};
  for (int c = 0; c < 3; ++c) {
    double xyz[3];
    xy_to_xyz(prim[c], xyz);
    for (int row = 0; row < 3; ++row) p[row][c] = xyz[row];
  }
  xy_to_xyz(d.white, w);
  invert3x3(p, inv);
  for (int c = 0; c < 3; ++c) {
    double s = inv[c][0] * w[0] + inv[c][1] * w[1] + inv[c][2] * w[2];
    for (int row = 0; row < 3; ++row) out[row][c] = p[row][c] * s;
  }
}

// ---- host API (color_space.cpp, rgb2spec_tables.cpp) ----

const RGBColorSpace& color_space(ColorSpaceId id);

/// Embedded Jakob-Hanika table for the space (validated on first use; aborts if corrupt).
const RGBToSpectrumTable& rgb_to_spectrum_table(ColorSpaceId id);

/// Reflectance: rgb clamped to [0,1], coefficients straight from the table.
Spectrum rgb_albedo(const RGBColorSpace& cs, Vec3 rgb);
/// Unbounded (>= 0) quantity: m = max component, scale = 2m, table(rgb / 2m) so the
/// largest component sits at the middle of the sigmoid (pbrt-v4 convention).
Spectrum rgb_unbounded(const RGBColorSpace& cs, Vec3 rgb);
/// Emission: rgb_unbounded times the space's Y = 1 illuminant, so (1,1,1) is its white.
Spectrum rgb_illuminant(const RGBColorSpace& cs, Vec3 rgb);

/// Working-space RGB -> linear sRGB for preview: identity for sRGB; for ACEScg,
/// AP1 -> XYZ, Bradford D60 -> D65, XYZ -> sRGB.
Vec3 working_to_linear_srgb(ColorSpaceId id, Vec3 rgb);

}  // namespace kauri
