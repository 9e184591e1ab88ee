// The render loop's vector stages (kauri/sampler/sampler_lanes.h, kauri/render/sample_lanes.h)
// against the scalar code they replace, value for value: a pixel's samples started in
// lanes draw the dimensions start_pixel_sample gives them, the camera stage gives
// camera_sample's film positions, wavelengths and rays, and the film stage the scalar
// XYZ → RGB with the indirect clamp. The sampler's values bit for bit (integer
// operations); the floating-point stages to a few ulps: they are the same operations in
// the same order, but whether GCC contracts a multiply and an add into one FMA depends on
// the code around them (the scalar XYZ sum is contracted in one build and not in another).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "kauri/render/sample_lanes.h"
#include "kauri/sampler/rng.h"
#include "kauri/spectral/color_space.h"

namespace kauri {
namespace {

uint32_t bits(Float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}
#define EXPECT_SAME_FLOAT(a, b) EXPECT_EQ(bits(a), bits(b)) << (a) << " vs " << (b)
/// Equal to float rounding: within 4 ulps of `scale` (the magnitude of the terms summed).
#define EXPECT_ROUNDING_CLOSE(a, b, scale) EXPECT_NEAR(a, b, 4 * 0x1p-23f * (scale))

Sampler fresh_sampler(SamplerType type, uint32_t spp) {
  Sampler s;
  s.type = type;
  s.set_samples_per_pixel(spp);
  return s;
}

/// The scalar camera stage of renderer.cpp (camera_sample), written out.
Ray scalar_camera_sample(const Camera& cam, const WavelengthDistribution& wl, bool splat, const PixelFilter& filter,
                         int x, int y, uint32_t s, uint64_t seed, Sampler& sampler, Vec2* film_pos,
                         SampledWavelengths* lambda) {
  sampler.start_pixel_sample(x, y, s, seed);
  Vec2 u_film = sampler.get_2d();
  *film_pos = splat ? Vec2{Float(x) + u_film.x, Float(y) + u_film.y}
                    : Vec2{Float(x) + 0.5f, Float(y) + 0.5f} + filter.sample(u_film);
  Vec2 u_lens;
  if (cam.lens_radius > 0) u_lens = sampler.get_2d();
  else sampler.skip_2d();
  *lambda = sample_wavelengths(wl, sampler.get_1d());
  return cam.generate_ray(*film_pos, u_lens);
}

/// Samplers started L at a time by `start` (start_pixel_samples_lanes or _wide), full and
/// partial groups, against the scalar sampler: the same indices and the same values of the
/// lanes' batch (pairs 0 … kSobolBatch − 1) and of the pairs the samplers draw after it.
template <int L, class Start>
void check_started_like_scalar(Start start) {
  // Without and with a SobolSeedCache shared by the group (render_pixel_samples' samplers).
  SobolSeedCache cache;
  for (SobolSeedCache* seeds : {static_cast<SobolSeedCache*>(nullptr), &cache})
  for (SamplerType type : {SamplerType::Sobol, SamplerType::ZSobol}) {
    for (uint32_t spp : {1u, 5u, 8u, 16u, 24u, 100u}) {
      for (int px : {0, 3, 77}) {
        const int py = 2 * px + 1;
        // Past spp too: a ZSobol pixel's samples beyond its block use the pixel's own sequence.
        for (uint32_t g0 = 0; g0 < spp + 40; g0 += L) {
          const int n = int(std::min<uint32_t>(L, spp + 40 - g0));
          Sampler lanes[L];
          lanes[0] = fresh_sampler(type, spp);
          lanes[0].seeds = seeds;
          const uint32_t block = 1u << ceil_log2(spp);
          const bool straddles = type == SamplerType::ZSobol && g0 < block && g0 + uint32_t(n) > block;
          const bool started = start(lanes, n, px, py, g0, 0x1234567890abULL);
          ASSERT_EQ(started, !straddles) << "spp " << spp << " g0 " << g0;
          if (!started) continue;
          for (int k = 0; k < n; ++k) {
            Sampler ref = fresh_sampler(type, spp);
            ref.start_pixel_sample(px, py, g0 + uint32_t(k), 0x1234567890abULL);
            ASSERT_EQ(lanes[k].index, ref.index);
            ASSERT_EQ(lanes[k].reversed_index, ref.reversed_index);
            ASSERT_EQ(lanes[k].pixel_seed, ref.pixel_seed);
            ASSERT_EQ(lanes[k].dimension, ref.dimension);
            for (int d = 0; d < int(kSobolBatch) + 3; ++d) {
              const Vec2 a = lanes[k].get_2d(), b = ref.get_2d();
              EXPECT_SAME_FLOAT(a.x, b.x);
              EXPECT_SAME_FLOAT(a.y, b.y);
            }
          }
        }
      }
    }
  }
}

TEST(SampleLanes, StartedSamplersDrawTheScalarDimensions) {
  check_started_like_scalar<kSampleLanes>(start_pixel_samples_lanes);
}

TEST(SampleLanes, WideStartDrawsTheScalarDimensions) {
  // kStartLanes samples at once: 16 in the v4 core (this file is in kauri_tests_v4 too).
  check_started_like_scalar<kStartLanes>(start_pixel_samples_wide);
}

TEST(SampleLanes, IndependentSamplerIsStartedOneByOne) {
  Sampler s[8];
  s[0] = fresh_sampler(SamplerType::Independent, 16);
  EXPECT_FALSE(start_pixel_samples_lanes(s, 8, 1, 2, 0, 7));
}

/// A 64 × 48 perspective camera, rotated and moved off the origin (lens set by the tests).
Camera test_camera() {
  Camera cam;
  cam.width = 64;
  cam.height = 48;
  cam.tan_half_x = 0.4f;
  cam.tan_half_y = 0.3f;
  cam.half_w = 2;
  cam.half_h = 1.5f;
  cam.focus_distance = 3;
  const Float m[3][4] = {{0.8f, 0.0f, 0.6f, 1.5f}, {0.1f, 0.98f, -0.2f, 2.0f}, {-0.6f, 0.1f, 0.8f, -3.0f}};
  std::memcpy(cam.camera_to_world.m, m, sizeof m);
  return cam;
}

struct CameraCase {
  CameraType type;
  Float lens_radius;
  bool splat;
};

TEST(SampleLanes, CameraStageGivesCameraSamplesRays) {
  const WavelengthDistribution& wl = color_space(ColorSpaceId::LinearSRGB).wavelengths;
  Camera cam = test_camera();
  PixelFilter filter;
  for (CameraCase cc : {CameraCase{CameraType::Perspective, 0, true}, CameraCase{CameraType::Perspective, 0, false},
                        CameraCase{CameraType::Perspective, 0.1f, true}, CameraCase{CameraType::Orthographic, 0, true}}) {
    cam.type = cc.type;
    cam.lens_radius = cc.lens_radius;
    for (int px : {0, 17, 63}) {
      const int py = px % 48;
      for (uint32_t g0 = 0; g0 < 32; g0 += 8) {
        Sampler lanes[8];
        lanes[0] = fresh_sampler(SamplerType::ZSobol, 32);
        ASSERT_TRUE(start_pixel_samples_lanes(lanes, 8, px, py, g0, 99));
        Ray rays[8];
        Vec2 film[8];
        SampledWavelengths lambda[8];
        camera_rays_lanes(cam, wl, cc.splat, filter, px, py, lanes, 8, rays, film, lambda);
        for (int k = 0; k < 8; ++k) {
          Sampler ref = fresh_sampler(SamplerType::ZSobol, 32);
          Vec2 ref_film;
          SampledWavelengths ref_lambda;
          const Ray r = scalar_camera_sample(cam, wl, cc.splat, filter, px, py, g0 + uint32_t(k), 99, ref, &ref_film,
                                             &ref_lambda);
          SCOPED_TRACE(testing::Message() << "camera " << int(cc.type) << " lens " << cc.lens_radius << " pixel "
                                          << px << " sample " << g0 + uint32_t(k));
          EXPECT_SAME_FLOAT(film[k].x, ref_film.x);
          EXPECT_SAME_FLOAT(film[k].y, ref_film.y);
          for (int i = 0; i < kSpectrumSamples; ++i) {
            EXPECT_ROUNDING_CLOSE(lambda[k].lambda[i], ref_lambda.lambda[i], 830);
            EXPECT_ROUNDING_CLOSE(lambda[k].pdf[i], ref_lambda.pdf[i], ref_lambda.pdf[i]);
          }
          for (int a = 0; a < 3; ++a) {
            EXPECT_ROUNDING_CLOSE(rays[k].o[a], r.o[a], 4);
            EXPECT_ROUNDING_CLOSE(rays[k].d[a], r.d[a], 1);
          }
          EXPECT_EQ(rays[k].tmax, r.tmax);
          // The path goes on from the same dimension.
          const Vec2 a = lanes[k].get_2d(), b = ref.get_2d();
          EXPECT_SAME_FLOAT(a.x, b.x);
          EXPECT_SAME_FLOAT(a.y, b.y);
        }
      }
    }
  }
}

TEST(SampleLanes, CameraStageColumnsHoldTheRaysItWouldReturn) {
  // For the path lanes the camera stage writes its rays and wavelengths as columns of the
  // batch: the same values, bit for bit, at the entries of the group, for the vector
  // pinhole and the ray-by-ray cameras; the other entries untouched.
  const WavelengthDistribution& wl = color_space(ColorSpaceId::LinearSRGB).wavelengths;
  Camera cam = test_camera();
  for (Float lens : {Float(0), Float(0.1f)}) {
    cam.lens_radius = lens;
    for (int col0 : {0, 8}) {
      for (int n : {8, 5}) {
        Sampler a[8], b[8];
        a[0] = fresh_sampler(SamplerType::ZSobol, 32);
        b[0] = fresh_sampler(SamplerType::ZSobol, 32);
        ASSERT_TRUE(start_pixel_samples_lanes(a, n, 17, 9, 8, 3));
        ASSERT_TRUE(start_pixel_samples_lanes(b, n, 17, 9, 8, 3));
        Ray rays[8];
        Vec2 film_a[8], film_b[8];
        SampledWavelengths lambda_a[8], lambda_b[8];
        camera_rays_lanes(cam, wl, true, PixelFilter{}, 17, 9, a, n, rays, film_a, lambda_a);
        BatchColumns cols;
        for (int k = 0; k < kBatchColumns; ++k) cols.set_ray(k, Ray{Point3{-7, -7, -7}, Vec3{1, 0, 0}, 5});
        Ray untouched[8];
        camera_rays_lanes(cam, wl, true, PixelFilter{}, 17, 9, b, n, untouched, film_b, lambda_b, &cols, col0);
        for (int k = 0; k < n; ++k) {
          SCOPED_TRACE(testing::Message() << "lens " << lens << " col0 " << col0 << " n " << n << " sample " << k);
          const Ray r = cols.ray(col0 + k);
          for (int c = 0; c < 3; ++c) {
            EXPECT_SAME_FLOAT(r.o[c], rays[k].o[c]);
            EXPECT_SAME_FLOAT(r.d[c], rays[k].d[c]);
          }
          EXPECT_EQ(r.tmax, rays[k].tmax);
          EXPECT_EQ(untouched[k].o.x, 0);  // `rays` is left alone
          for (int i = 0; i < kSpectrumSamples; ++i) {
            EXPECT_SAME_FLOAT(cols.lambda[i][col0 + k], lambda_a[k].lambda[i]);
            EXPECT_SAME_FLOAT(lambda_b[k].lambda[i], lambda_a[k].lambda[i]);
            EXPECT_SAME_FLOAT(lambda_b[k].pdf[i], lambda_a[k].pdf[i]);
          }
        }
        for (int k = 0; k < kBatchColumns; ++k)
          if (k < col0 || k >= col0 + 8) EXPECT_EQ(cols.ray(k).o.x, -7) << "entry " << k << " outside the group";
      }
    }
  }
}

TEST(SampleLanes, WavelengthsAtTheEdgesOfTheUnitInterval) {
  // The camera stage reads u from the samplers' batch: set it to values where the
  // rotation by i/4 lands exactly on 1 (wrapped to 0) or on the last knot.
  const WavelengthDistribution& wl = color_space(ColorSpaceId::LinearSRGB).wavelengths;
  const Float us[8] = {0, 0.25f, 0.5f, 0.75f, kOneMinusEpsilon, 0.1f, 0.2499999f, 0.3f};
  Camera cam;
  Sampler lanes[8];
  lanes[0] = fresh_sampler(SamplerType::Sobol, 8);
  ASSERT_TRUE(start_pixel_samples_lanes(lanes, 8, 0, 0, 0, 1));
  for (int k = 0; k < 8; ++k) lanes[k].batch[2] = us[k];
  Ray rays[8];
  Vec2 film[8];
  SampledWavelengths lambda[8];
  camera_rays_lanes(cam, wl, true, PixelFilter{}, 0, 0, lanes, 8, rays, film, lambda);
  for (int k = 0; k < 8; ++k) {
    const SampledWavelengths ref = sample_wavelengths(wl, us[k]);
    for (int i = 0; i < kSpectrumSamples; ++i) {
      EXPECT_ROUNDING_CLOSE(lambda[k].lambda[i], ref.lambda[i], 830) << "u " << us[k] << " i " << i;
      EXPECT_ROUNDING_CLOSE(lambda[k].pdf[i], ref.pdf[i], ref.pdf[i]) << "u " << us[k] << " i " << i;
    }
  }
}

TEST(SampleLanes, FilmStageGivesTheScalarColour) {
  SceneView sv{};
  const RGBColorSpace& cs = color_space(ColorSpaceId::LinearSRGB);
  std::memcpy(sv.xyz_to_rgb, cs.xyz_to_rgb, sizeof sv.xyz_to_rgb);
  PCG32 rng;
  rng.set_sequence(5, 11);
  for (Float clamp : {Float(0), Float(0.7f), Float(3)}) {
    for (int round = 0; round < 200; ++round) {
      const int n = 1 + int(rng.next_u32() % 8);
      PathOutput out[8];
      SampledWavelengths lambda[8];
      for (int k = 0; k < n; ++k) {
        lambda[k] = sample_wavelengths(cs.wavelengths, rng.next_float());
        for (int i = 0; i < kSpectrumSamples; ++i) {
          out[k].L[i] = 4 * rng.next_float();
          out[k].L_direct_first[i] = rng.next_float() < 0.3f ? 0 : 2 * rng.next_float();
        }
        if (rng.next_float() < 0.3f) out[k].rgb_exact = {rng.next_float(), 2 * rng.next_float(), rng.next_float()};
        // A dispersive path keeps only its hero wavelength: the others' densities are 0.
        if (rng.next_float() < 0.2f)
          for (int i = 1; i < kSpectrumSamples; ++i) lambda[k].pdf[i] = 0;
        if (rng.next_float() < 0.05f) out[k].L[2] = std::nanf("");
        if (round % 8 == 0)  // paths that gathered nothing (camera rays into the sky): the shortcut
          out[k].L = out[k].L_direct_first = SampledSpectrum(0);
      }
      // The radiance sums as the path lanes leave them: columns of the batch (here its
      // second half, so the offset is exercised too).
      BatchColumns cols;
      for (int k = 0; k < n; ++k) cols.set_radiance(8 + k, out[k]);
      Vec3 rgb[8];
      sample_rgb_lanes(sv, clamp, cols, 8, out, lambda, n, rgb);
      for (int k = 0; k < n; ++k) {
        const SampledXYZWeights to_xyz(lambda[k]);
        const Vec3 indirect_xyz = to_xyz(out[k].L);
        const Vec3 ref = sv.to_rgb(to_xyz(out[k].L_direct_first)) + out[k].rgb_exact +
                         clamp_luminance(sv.to_rgb(indirect_xyz), indirect_xyz.y, clamp);
        if (!is_finite(ref)) {
          EXPECT_FALSE(is_finite(rgb[k]));
          continue;
        }
        // The terms of the sums are up to ~3·4·4 (matrix, L, CMF / pdf).
        for (int a = 0; a < 3; ++a) EXPECT_ROUNDING_CLOSE(rgb[k][a], ref[a], 48 * (1 + std::fabs(ref[a])));
      }
    }
  }
}

TEST(SampleLanes, ClampLimitsTheIndirectLuminance) {
  // Luminance 2 clamped to 0.5: a quarter of the colour, hue kept; below the clamp, as is.
  const Vec3 c = clamp_luminance(Vec3{4, 2, 1}, 2, 0.5f);
  EXPECT_FLOAT_EQ(c.x, 1);
  EXPECT_FLOAT_EQ(c.y, 0.5f);
  EXPECT_FLOAT_EQ(c.z, 0.25f);
  EXPECT_FLOAT_EQ(clamp_luminance(Vec3{4, 2, 1}, 2, 3).x, 4);
  EXPECT_FLOAT_EQ(clamp_luminance(Vec3{4, 2, 1}, 2, 0).x, 4);
}

}  // namespace
}  // namespace kauri
