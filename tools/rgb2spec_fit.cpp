// rgb2spec_fit: fits the Jakob & Hanika 2019 RGB -> spectrum coefficient table for one
// working space ("A Low-Dimensional Function Space for Efficient Spectral Upsampling",
// CGF 38(2)). Written for kauri from the paper's equations; see docs/spectral.md.
//
//   usage: rgb2spec_fit <res> <srgb|acescg> <out.bin>
//   output: "KSPC", uint32 res, float scale[res], float data[3][res][res][res][3]
//
// For every table node we solve for (A, B, C) such that the reflectance
// S(t) = s(A t^2 + B t + C), t = (lambda - 360) / 470, lit by the space's illuminant and
// seen through the CIE 1931 observer, has the node's RGB. The residual is measured in
// CIELAB relative to the space's white (perceptually uniform, so the solver spends its
// effort where errors are visible), and solved with Gauss-Newton (square 3x3 system,
// analytic Jacobian, Cramer solve).
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "kauri/spectral/color_space.h"
#include "kauri/spectral/spectral_tables.h"

namespace {

using kauri::ColorSpaceId;
namespace tables = kauri::tables;

constexpr int kNodes = tables::kCieSamples;  // 1 nm quadrature, same as the runtime
constexpr double kLambda0 = 360, kLambdaScale = 1.0 / 470;
constexpr int kMaxIterations = 20;
constexpr double kTolerance = 1e-6;   // squared CIELAB residual
constexpr double kMaxCoeff = 200;     // keeps the sigmoid argument bounded near black/white

/// Everything the forward model needs, precomputed once per colour space.
struct ForwardModel {
  double t[kNodes];            // normalised wavelength
  double weight[kNodes][3];    // illuminant * cmf / int(illuminant * ybar)
  double rgb_to_xyz[3][3];
  double white[3];             // XYZ of RGB (1,1,1), Y = 1
};

ForwardModel make_model(ColorSpaceId id) {
  ForwardModel fm{};
  const float* illum = kauri::color_space_illuminant_table(id);
  double y_norm = 0;
  for (int l = 0; l < kNodes; ++l) y_norm += double(illum[l]) * double(tables::kCieY[l]);
  for (int l = 0; l < kNodes; ++l) {
    fm.t[l] = l * kLambdaScale;  // the grid is 1 nm from 360
    double w = double(illum[l]) / y_norm;
    fm.weight[l][0] = w * double(tables::kCieX[l]);
    fm.weight[l][1] = w * double(tables::kCieY[l]);
    fm.weight[l][2] = w * double(tables::kCieZ[l]);
  }
  kauri::rgb_to_xyz_matrix(kauri::color_space_definition(id), fm.rgb_to_xyz);
  for (int r = 0; r < 3; ++r) fm.white[r] = fm.rgb_to_xyz[r][0] + fm.rgb_to_xyz[r][1] + fm.rgb_to_xyz[r][2];
  return fm;
}

/// CIELAB companding f(t) and its derivative (CIE 15, delta = 6/29 linear segment).
constexpr double kDelta = 6.0 / 29.0;
double lab_f(double t) { return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0 / 29.0; }
double lab_df(double t) {
  if (t > kDelta * kDelta * kDelta) { double c = std::cbrt(t); return 1 / (3 * c * c); }
  return 1 / (3 * kDelta * kDelta);
}

void xyz_to_lab(const double xyz[3], const double white[3], double lab[3]) {
  double fx = lab_f(xyz[0] / white[0]), fy = lab_f(xyz[1] / white[1]), fz = lab_f(xyz[2] / white[2]);
  lab[0] = 116 * fy - 16;
  lab[1] = 500 * (fx - fy);
  lab[2] = 200 * (fy - fz);
}

/// Model XYZ and d(XYZ)/d(A,B,C) in one pass over the wavelength grid.
/// s(x) = 1/2 + x q / 2 with q = 1/sqrt(1+x^2), s'(x) = q^3 / 2.
void eval_xyz(const ForwardModel& fm, const double c[3], double xyz[3], double dxyz[3][3]) {
  double acc[12] = {};
  for (int l = 0; l < kNodes; ++l) {
    double t = fm.t[l];
    double x = (c[0] * t + c[1]) * t + c[2];
    double q = 1 / std::sqrt(1 + x * x);
    double s = 0.5 + 0.5 * x * q, ds = 0.5 * q * q * q;
    double dt[3] = {ds * t * t, ds * t, ds};
    for (int k = 0; k < 3; ++k) {
      double w = fm.weight[l][k];
      acc[k] += s * w;
      for (int j = 0; j < 3; ++j) acc[3 + 3 * k + j] += dt[j] * w;
    }
  }
  for (int k = 0; k < 3; ++k) {
    xyz[k] = acc[k];
    for (int j = 0; j < 3; ++j) dxyz[k][j] = acc[3 + 3 * k + j];
  }
}

/// CIELAB residual (target - model) and its Jacobian with respect to (A,B,C).
double residual(const ForwardModel& fm, const double target_lab[3], const double c[3], double r[3],
                double jac[3][3]) {
  double xyz[3], dxyz[3][3], lab[3];
  eval_xyz(fm, c, xyz, dxyz);
  xyz_to_lab(xyz, fm.white, lab);
  double dfx = lab_df(xyz[0] / fm.white[0]) / fm.white[0];
  double dfy = lab_df(xyz[1] / fm.white[1]) / fm.white[1];
  double dfz = lab_df(xyz[2] / fm.white[2]) / fm.white[2];
  for (int j = 0; j < 3; ++j) {
    jac[0][j] = 116 * dfy * dxyz[1][j];
    jac[1][j] = 500 * (dfx * dxyz[0][j] - dfy * dxyz[1][j]);
    jac[2][j] = 200 * (dfy * dxyz[1][j] - dfz * dxyz[2][j]);
  }
  double err = 0;
  for (int k = 0; k < 3; ++k) {
    r[k] = target_lab[k] - lab[k];
    err += r[k] * r[k];
  }
  return err;
}

/// Solves J d = r by Cramer's rule; false if J is (numerically) singular.
bool solve3x3(const double jac[3][3], const double r[3], double d[3]) {
  double inv[3][3];
  if (!kauri::invert3x3(jac, inv)) return false;
  for (int i = 0; i < 3; ++i) d[i] = inv[i][0] * r[0] + inv[i][1] * r[1] + inv[i][2] * r[2];
  return std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2]);
}

/// Near black/white the optimum runs off to infinity; bounding the coefficients keeps
/// the table smooth and finite (the sigmoid is saturated long before this).
void bound_coefficients(double c[3]) {
  double big = std::fmax(std::fabs(c[0]), std::fmax(std::fabs(c[1]), std::fabs(c[2])));
  if (big > kMaxCoeff)
    for (int k = 0; k < 3; ++k) c[k] *= kMaxCoeff / big;
}

/// Gauss-Newton from the warm start in `c`; returns the final squared residual.
/// A full step can overshoot far from the optimum (the sigmoid saturates), so steps are
/// halved until the residual decreases (backtracking; Nocedal & Wright, ch. 3).
double fit(const ForwardModel& fm, const double rgb[3], double c[3]) {
  double xyz[3], target_lab[3];
  for (int k = 0; k < 3; ++k)
    xyz[k] = fm.rgb_to_xyz[k][0] * rgb[0] + fm.rgb_to_xyz[k][1] * rgb[1] + fm.rgb_to_xyz[k][2] * rgb[2];
  xyz_to_lab(xyz, fm.white, target_lab);
  double r[3], jac[3][3], d[3];
  double err = residual(fm, target_lab, c, r, jac);
  for (int it = 0; it < kMaxIterations && err >= kTolerance; ++it) {
    if (!solve3x3(jac, r, d)) break;
    bool improved = false;
    for (double step = 1; step > 0.02 && !improved; step *= 0.5) {
      double trial[3] = {c[0] + step * d[0], c[1] + step * d[1], c[2] + step * d[2]};
      bound_coefficients(trial);
      double rt[3], jt[3][3];
      double et = residual(fm, target_lab, trial, rt, jt);
      if (et < err) {
        improved = true;
        err = et;
        std::memcpy(c, trial, sizeof trial);
        std::memcpy(r, rt, sizeof rt);
        std::memcpy(jac, jt, sizeof jt);
      }
    }
    if (!improved) break;
  }
  return err;
}

/// Normalised (A t^2 + B t + C), t = (lambda - l0) s  ->  nm coefficients (c0, c1, c2).
void to_nm(const double c[3], float out[3]) {
  const double s = kLambdaScale, l0 = kLambda0;
  out[0] = float(c[0] * s * s);
  out[1] = float(c[1] * s - 2 * c[0] * l0 * s * s);
  out[2] = float(c[2] - c[1] * l0 * s + c[0] * (l0 * s) * (l0 * s));
}

double smoothstep(double x) { return x * x * (3 - 2 * x); }

struct Table {
  int res;
  std::vector<float> scale, data;
  size_t index(int m, int k, int j, int i) const { return ((size_t(m * res + k) * res + j) * res + i) * 3; }
};

/// One (m, x, y) column: walk z upward from res/5 and then downward, warm-starting each
/// solve from its neighbour (the optimum varies smoothly along z).
double fit_column(const ForwardModel& fm, Table& tab, int m, int j, int i) {
  const int res = tab.res, start = res / 5;
  const double x = double(i) / (res - 1), y = double(j) / (res - 1);
  double worst = 0;
  auto solve_at = [&](int k, double c[3]) {
    double z = tab.scale[k], rgb[3];
    rgb[m] = z;
    rgb[(m + 1) % 3] = x * z;
    rgb[(m + 2) % 3] = y * z;
    double e = fit(fm, rgb, c);
    static const bool debug = std::getenv("RGB2SPEC_DEBUG") != nullptr;  // log poor fits
    if (debug && e > 1e-3)
      std::fprintf(stderr, "m%d k%d j%d i%d rgb %.4f %.4f %.4f err %.3g c %.3g %.3g %.3g\n", m, k, j, i, rgb[0], rgb[1], rgb[2], e, c[0], c[1], c[2]);
    worst = std::fmax(worst, e);
    to_nm(c, &tab.data[tab.index(m, k, j, i)]);
  };
  double c[3] = {0, 0, 0};
  for (int k = start; k < res; ++k) solve_at(k, c);
  c[0] = c[1] = c[2] = 0;
  for (int k = start; k >= 0; --k) solve_at(k, c);
  return worst;
}

bool write_table(const Table& tab, const std::string& path) {
  std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return false;
  uint32_t res = uint32_t(tab.res);
  bool ok = std::fwrite("KSPC", 1, 4, f) == 4 && std::fwrite(&res, 4, 1, f) == 1 &&
            std::fwrite(tab.scale.data(), 4, tab.scale.size(), f) == tab.scale.size() &&
            std::fwrite(tab.data.data(), 4, tab.data.size(), f) == tab.data.size();
  ok = (std::fclose(f) == 0) && ok;
  return ok && std::rename(tmp.c_str(), path.c_str()) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <res> <srgb|acescg> <out.bin>\n", argv[0]);
    return 1;
  }
  Table tab;
  tab.res = std::atoi(argv[1]);
  ColorSpaceId id;
  if (tab.res < 3 || tab.res > 256 || !kauri::parse_color_space(argv[2], &id)) {
    std::fprintf(stderr, "rgb2spec_fit: bad resolution or colour space (srgb|acescg)\n");
    return 1;
  }
  auto t0 = std::chrono::steady_clock::now();
  const ForwardModel fm = make_model(id);
  const int res = tab.res;
  tab.scale.resize(res);
  // Double smoothstep packs z nodes densely near 0 and 1, where the coefficients change fastest.
  for (int k = 0; k < res; ++k) tab.scale[k] = float(smoothstep(smoothstep(double(k) / (res - 1))));
  tab.data.assign(size_t(3) * res * res * res * 3, 0.f);

  std::atomic<int> next{0};
  std::vector<double> worst(std::max(1u, std::thread::hardware_concurrency()), 0.0);
  std::vector<std::thread> pool;
  for (size_t w = 0; w < worst.size(); ++w)
    pool.emplace_back([&, w] {
      for (int task; (task = next.fetch_add(1)) < 3 * res * res;)
        worst[w] = std::fmax(worst[w], fit_column(fm, tab, task / (res * res), (task / res) % res, task % res));
    });
  for (auto& th : pool) th.join();
  double max_err = 0;
  for (double e : worst) max_err = std::fmax(max_err, e);

  if (!write_table(tab, argv[3])) {
    std::fprintf(stderr, "rgb2spec_fit: cannot write %s\n", argv[3]);
    return 1;
  }
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("rgb2spec_fit: %s res %d in %.2f s (%zu threads), max squared CIELAB residual %.3g\n",
              argv[2], res, secs, worst.size(), max_err);
  return 0;
}
