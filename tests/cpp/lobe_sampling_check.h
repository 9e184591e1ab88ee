// Chi-square test of a lobe's (or a whole BSDF's) sample() against its pdf(), shared by
// the lobe and BSDF tests (test_bsdf.cpp, test_lobes_extra.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "chi2.h"
#include "kauri/bsdf/bsdf.h"
#include "lobe_test_util.h"

namespace kauri::test {

struct LobeSamplingOptions {
  int samples = 1000000;
  int pilot = 40000;  // samples that place the chi-square cells (SphereChi2Config::pilot)
  TransportMode mode = TransportMode::Radiance;
};

/// Chi-square test of lobe.sample(wo) against lobe.pdf(wo, ·), plus per-sample checks
/// that sample().f == eval() (wavelengths the sample terminated excepted) and
/// sample().pdf == pdf() (relative 1e-3), that Lobe::eval_pdf() equals eval() and pdf()
/// (relative 1e-5), and that a non-delta lobe never returns a specular sample.
template <class L>
void check_lobe_sampling(const L& lobe, Vec3 wo, const std::string& name, uint64_t seed,
                         const LobeSamplingOptions& o = {}) {
  const SampledWavelengths lambda0 = test_wavelengths();
  int f_mismatch = 0, pdf_mismatch = 0, specular = 0, fused_mismatch = 0;
  double max_f_err = 0, max_pdf_err = 0;
  auto sample = [&](PCG32& r, Vec3* w) {
    SampledWavelengths lambda = lambda0;
    Float uc = r.next_float();
    BSDFSample s = lobe.sample(wo, uc, next_2d(r), lambda, o.mode);
    if (!s.valid()) return false;
    if (s.is_specular()) ++specular;
    *w = s.wi;
    Float p = lobe.pdf(wo, s.wi);
    double pe = std::fabs(double(s.pdf) - double(p)) / std::max(double(p), 1e-30);
    max_pdf_err = std::max(max_pdf_err, pe);
    if (pe > 1e-3) ++pdf_mismatch;
    SampledSpectrum f = lobe.eval(wo, s.wi, o.mode);
    // eval_pdf (Lobe's: the lobe's fused form, or eval() and pdf() apart; or BSDF's) gives
    // the same pair.
    Float p_fused;
    SampledSpectrum f_fused;
    if constexpr (std::is_same_v<L, BSDF>) f_fused = lobe.eval_pdf(wo, s.wi, o.mode, &p_fused);
    else f_fused = Lobe(lobe).eval_pdf(wo, s.wi, o.mode, &p_fused);
    bool fused_ok = std::fabs(double(p_fused) - double(p)) <= 1e-5 * std::max(double(p), 1e-30);
    for (int i = 0; i < kSpectrumSamples; ++i)
      fused_ok = fused_ok && std::fabs(double(f_fused[i]) - double(f[i])) <= 1e-5 * std::max(double(f[i]), 1e-30);
    if (!fused_ok) ++fused_mismatch;
    for (int i = 0; i < kSpectrumSamples; ++i) {
      if (lambda.pdf[i] == 0) continue;  // terminated secondary wavelength
      double fe = std::fabs(double(s.f[i]) - double(f[i])) / std::max(double(f[i]), 1e-30);
      max_f_err = std::max(max_f_err, fe);
      if (fe > 1e-3) {
        ++f_mismatch;
        break;
      }
    }
    return true;
  };
  SphereChi2Config cfg;
  cfg.name = name;
  cfg.forced_cos = {0};
  cfg.seed = seed;
  cfg.samples = o.samples;
  cfg.pilot = o.pilot;
  EXPECT_TRUE(sphere_chi2(sample, [&](Vec3 w) { return double(lobe.pdf(wo, w)); }, cfg));
  EXPECT_EQ(specular, 0) << name << ": a non-delta lobe returned specular samples";
  EXPECT_EQ(f_mismatch, 0) << name << ": sample().f != eval(), max rel. error " << max_f_err;
  EXPECT_EQ(pdf_mismatch, 0) << name << ": sample().pdf != pdf(), max rel. error " << max_pdf_err;
  EXPECT_EQ(fused_mismatch, 0) << name << ": eval_pdf() != (eval(), pdf())";
}

}  // namespace kauri::test
