// Russian roulette's survival probability (path_tracer.h): the cube root it takes without
// libm, and the probabilities it hands the path loop.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kauri/integrator/path_tracer.h"

namespace kauri {
namespace {

TEST(Roulette, CubeRootMatchesLibmOnTheUnitInterval) {
  // Every binade of (0, 1), 4096 points each, plus the ends: within 4e-6 of cbrt and
  // never above 1 (a probability above 1 with weight 1/p would bias the estimate).
  for (int e = -126; e < 0; ++e)
    for (int k = 0; k < 4096; ++k) {
      const float x = std::ldexp(1.0f + float(k) / 4096, e);
      const float y = path_detail::cbrt_unit(x);
      ASSERT_NEAR(double(y) / std::cbrt(double(x)), 1.0, 4e-6) << x;
      ASSERT_LE(y, 1.0f);
    }
  EXPECT_LE(path_detail::cbrt_unit(std::nextafter(1.0f, 0.0f)), 1.0f);
  // Below the normal range the input is raised to the smallest normal float.
  const float denormal = std::numeric_limits<float>::denorm_min();
  EXPECT_NEAR(path_detail::cbrt_unit(denormal), std::cbrt(double(std::numeric_limits<float>::min())), 1e-17);
}

TEST(Roulette, SurvivalIsAProbability) {
  EXPECT_EQ(path_detail::rr_survival(0), 0);
  EXPECT_EQ(path_detail::rr_survival(-1), 0);
  EXPECT_EQ(path_detail::rr_survival(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(path_detail::rr_survival(1), 1);
  EXPECT_EQ(path_detail::rr_survival(7.5f), 1);
  EXPECT_NEAR(path_detail::rr_survival(0.125f), 0.5f, 1e-6f);
  EXPECT_NEAR(path_detail::rr_survival(0.001f), 0.1f, 1e-6f);
  // Monotone over a fine grid: a brighter path never survives less often.
  float last = 0;
  for (int k = 1; k < 100000; ++k) {
    const float p = path_detail::rr_survival(float(k) / 100000);
    ASSERT_GE(p, last) << k;
    last = p;
  }
}

}  // namespace
}  // namespace kauri
