// Working colour spaces, built once on the host from primaries and white points.
#include "kauri/spectral/color_space.h"

namespace kauri {
namespace {

constexpr int kSpaces = 2;

/// The space's illuminant scaled so that its Y is 1 (sum(I ybar) = CIE_Y_integral),
/// which makes rgb_illuminant(1,1,1) exactly the white of luminance 1.
struct NormalisedIlluminant {
  float values[tables::kCieSamples];
  DenselySampled view;
};

void normalise_illuminant(ColorSpaceId id, NormalisedIlluminant* out) {
  const float* src = color_space_illuminant_table(id);
  double y = 0;
  for (int i = 0; i < tables::kCieSamples; ++i) y += double(src[i]) * double(tables::kCieY[i]);
  double k = double(tables::kCieYIntegral) / y;
  for (int i = 0; i < tables::kCieSamples; ++i) out->values[i] = float(double(src[i]) * k);
  out->view = {out->values, tables::kCieLambdaMin, 1, tables::kCieSamples};
}

void to_float(const double in[3][3], Float out[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = Float(in[i][j]);
}

void build(ColorSpaceId id, NormalisedIlluminant* illum, std::vector<float>* knots, RGBColorSpace* cs) {
  double to_xyz[3][3], to_rgb[3][3] = {};
  rgb_to_xyz_matrix(color_space_definition(id), to_xyz);
  invert3x3(to_xyz, to_rgb);
  normalise_illuminant(id, illum);
  cs->id = id;
  to_float(to_xyz, cs->rgb_to_xyz);
  to_float(to_rgb, cs->xyz_to_rgb);
  cs->illuminant = &illum->view;
  cs->table = &rgb_to_spectrum_table(id);
  *knots = output_wavelength_knots(cs->xyz_to_rgb, illum->values);
  cs->wavelengths = {knots->data(), int(knots->size())};
}

struct Registry {
  NormalisedIlluminant illuminants[kSpaces];
  std::vector<float> wavelength_knots[kSpaces];
  RGBColorSpace spaces[kSpaces];
  Registry() {
    for (int i = 0; i < kSpaces; ++i) build(ColorSpaceId(i), &illuminants[i], &wavelength_knots[i], &spaces[i]);
  }
};

void mat_mul(const double a[3][3], const double b[3][3], double out[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

/// Bradford von Kries adaptation XYZ(src white) -> XYZ(dst white) (Lam 1985; CIE 159 sec. 3).
void bradford(const double src_xy[2], const double dst_xy[2], double out[3][3]) {
  const double B[3][3] = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};
  double Binv[3][3], ws[3], wd[3], D[3][3] = {}, tmp[3][3];
  invert3x3(B, Binv);
  xy_to_xyz(src_xy, ws);
  xy_to_xyz(dst_xy, wd);
  for (int i = 0; i < 3; ++i) {
    double cs = B[i][0] * ws[0] + B[i][1] * ws[1] + B[i][2] * ws[2];
    double cd = B[i][0] * wd[0] + B[i][1] * wd[1] + B[i][2] * wd[2];
    D[i][i] = cd / cs;
  }
  mat_mul(D, B, tmp);
  mat_mul(Binv, tmp, out);
}

/// ACEScg -> linear sRGB for display: AP1 -> XYZ (D60) -> Bradford -> XYZ (D65) -> sRGB.
struct AcesToSrgb {
  double m[3][3];
  AcesToSrgb() {
    double ap1_to_xyz[3][3], srgb_to_xyz[3][3], xyz_to_srgb[3][3], cat[3][3], tmp[3][3];
    rgb_to_xyz_matrix(kACEScgDefinition, ap1_to_xyz);
    rgb_to_xyz_matrix(kLinearSRGBDefinition, srgb_to_xyz);
    invert3x3(srgb_to_xyz, xyz_to_srgb);
    bradford(kACEScgDefinition.white, kLinearSRGBDefinition.white, cat);
    mat_mul(cat, ap1_to_xyz, tmp);
    mat_mul(xyz_to_srgb, tmp, m);
  }
};

}  // namespace

const RGBColorSpace& color_space(ColorSpaceId id) {
  static const Registry registry;  // thread-safe one-time initialisation
  return registry.spaces[int(id)];
}

Spectrum rgb_albedo(const RGBColorSpace& cs, Vec3 rgb) {
  SigmoidPolynomial p = (*cs.table)(rgb);  // the table clamps to [0,1]
  // A grey's polynomial is the constant c2 (RGBToSpectrumTable::grey), so its spectrum
  // is the constant s(c2): stored as such, a hit skips four sigmoid evaluations, with
  // bit-identical values (greys are the common case: white walls, grey floors).
  if (p.c0 == 0 && p.c1 == 0) return Spectrum::make_constant(SigmoidPolynomial::sigmoid(p.c2));
  return Spectrum::make_rgb_albedo(p);
}

Spectrum rgb_unbounded(const RGBColorSpace& cs, Vec3 rgb) {
  rgb = vmax(rgb, Vec3{0, 0, 0});
  Float m = max_component(rgb);
  Float scale = 2 * m;
  SigmoidPolynomial p = scale > 0 ? (*cs.table)(rgb / scale) : RGBToSpectrumTable::grey(0);
  return Spectrum::make_rgb_unbounded(p, scale);
}

Spectrum rgb_illuminant(const RGBColorSpace& cs, Vec3 rgb) {
  Spectrum s = rgb_unbounded(cs, rgb);
  return Spectrum::make_rgb_illuminant(s.rgb.poly, s.rgb.scale, *cs.illuminant);
}

Vec3 working_to_linear_srgb(ColorSpaceId id, Vec3 rgb) {
  if (id == ColorSpaceId::LinearSRGB) return rgb;
  static const AcesToSrgb conv;
  Vec3 out;
  for (int i = 0; i < 3; ++i)
    out[i] = Float(conv.m[i][0] * double(rgb.x) + conv.m[i][1] * double(rgb.y) + conv.m[i][2] * double(rgb.z));
  return out;
}

}  // namespace kauri
