// Light antialiasing's screen mask (kauri/render/light_aa.h): every pixel from which a
// camera ray can see a bright light must be marked for a probe (an unmarked one never
// gets the extra rays: no bias, but the gain is lost there), and the cases it cannot
// bound mark every pixel. The probe's flag test itself.
#include <gtest/gtest.h>

#include "kauri/render/light_aa.h"
#include "kauri/sampler/rng.h"

namespace kauri {
namespace {

Camera make_camera(CameraType type, int w, int h) {
  Camera cam;
  cam.type = type;
  cam.width = w;
  cam.height = h;
  cam.camera_to_world = look_at(Point3{0.3f, 1.0f, 6.0f}, Point3{0, 0.5f, 0}, Vec3{0, 1, 0});
  cam.tan_half_x = 0.6f;
  cam.tan_half_y = 0.6f * Float(h) / Float(w);
  cam.half_w = 3;
  cam.half_h = 3 * Float(h) / Float(w);
  return cam;
}

Light triangle_light(Point3 a, Point3 b, Point3 c, Float radiance) {
  Light l;
  l.type = LightType::Triangle;
  l.p0 = a, l.p1 = b, l.p2 = c;
  l.n = normalize(cross(b - a, c - a));
  l.two_sided = true;
  l.Le_rgb = Vec3{radiance, radiance, radiance};
  return l;
}

/// Ray–triangle distance (Möller–Trumbore), or a negative value on a miss.
Float hit_triangle(const Ray& r, const Light& l) {
  const Vec3 e1 = l.p1 - l.p0, e2 = l.p2 - l.p0, pv = cross(r.d, e2);
  const Float det = dot(e1, pv);
  if (std::fabs(det) < 1e-12f) return -1;
  const Vec3 tv = r.o - l.p0;
  const Float u = dot(tv, pv) / det;
  const Vec3 qv = cross(tv, e1);
  const Float v = dot(r.d, qv) / det;
  if (u < 0 || v < 0 || u + v > 1) return -1;
  return dot(e2, qv) / det;
}

/// Every film position (random, many per pixel) whose camera ray meets one of the
/// lights with radiance ≥ min_spread lies in a marked pixel; the dim light is ignored.
void expect_mask_covers_lights(const Camera& cam, const std::vector<Light>& lights, Float min_spread) {
  SceneView s;
  s.camera = cam;
  s.lights = lights.data();
  s.n_lights = int(lights.size());
  const std::vector<uint8_t> mask = light_aa_candidates(s, cam.width, cam.height, min_spread, 1);
  ASSERT_EQ(mask.size(), size_t(cam.width) * size_t(cam.height));
  PCG32 rng(7, 1);
  int seen = 0, marked = 0;
  for (uint8_t m : mask) marked += m;
  for (int i = 0; i < 400000; ++i) {
    const Vec2 film{rng.next_float() * Float(cam.width), rng.next_float() * Float(cam.height)};
    const Ray r = cam.generate_ray(film, Vec2{0.5f, 0.5f});
    for (const Light& l : lights) {
      if (max_component(l.Le_rgb) < min_spread || !(hit_triangle(r, l) > 0)) continue;
      ++seen;
      ASSERT_EQ(mask[size_t(int(film.y)) * size_t(cam.width) + size_t(int(film.x))], 1)
          << "film position " << film.x << ", " << film.y;
    }
  }
  EXPECT_GT(seen, 100);                                       // the lights are on screen
  EXPECT_LT(marked, cam.width * cam.height / 4) << "the mask should stay local";
}

std::vector<Light> lamps() {
  return {triangle_light({-1.0f, 2.0f, 0}, {-0.7f, 2.0f, 0}, {-1.0f, 2.0f, 0.3f}, 10),
          triangle_light({0.5f, 0.2f, 1}, {0.8f, 0.2f, 1}, {0.5f, 0.6f, 1}, 8),
          triangle_light({1.5f, 1.0f, -1}, {2.5f, 1.0f, -1}, {1.5f, 2.0f, -1}, 1)};  // below the spread
}

TEST(LightAA, MaskCoversEveryPixelSeeingABrightLightPerspective) {
  expect_mask_covers_lights(make_camera(CameraType::Perspective, 96, 64), lamps(), 5);
}

TEST(LightAA, MaskCoversEveryPixelSeeingABrightLightOrthographic) {
  expect_mask_covers_lights(make_camera(CameraType::Orthographic, 80, 60), lamps(), 5);
}

TEST(LightAA, MaskMarksEverythingWhereItCannotBound) {
  std::vector<Light> ls = lamps();
  SceneView s;
  s.lights = ls.data();
  s.n_lights = int(ls.size());
  auto all_marked = [&](const SceneView& v) {
    const std::vector<uint8_t> m = light_aa_candidates(v, v.camera.width, v.camera.height, 5, 1);
    for (uint8_t x : m)
      if (!x) return false;
    return true;
  };
  s.camera = make_camera(CameraType::Perspective, 32, 24);
  EXPECT_FALSE(all_marked(s));
  s.camera.lens_radius = 0.1f;  // defocus spreads a light over pixels its box does not cover
  EXPECT_TRUE(all_marked(s));
  s.camera.lens_radius = 0;
  ls.push_back(triangle_light({-1, -1, 7}, {1, -1, 7}, {0, 1, 7}, 9));  // behind the camera
  s.lights = ls.data();
  s.n_lights = int(ls.size());
  EXPECT_TRUE(all_marked(s));
  ls.pop_back();
  Light sun;
  sun.type = LightType::Distant;
  sun.n = Vec3{0, 1, 0};
  sun.cos_max = 0.999f;
  sun.Le_rgb = Vec3{6, 6, 6};
  ls.push_back(sun);
  s.lights = ls.data();
  s.n_lights = int(ls.size());
  EXPECT_TRUE(all_marked(s));
  ls.back().Le_rgb = Vec3{0, 0, 0};  // a sun too dim to make a spread of 5: boxes as before
  EXPECT_FALSE(all_marked(s));
  ls.back().Le_rgb = Vec3{6, 6, 6};
  ls.back().cos_max = 1;  // a delta sun is never met by a camera ray
  EXPECT_FALSE(all_marked(s));
}

TEST(LightAA, ProbeFlagsOnlyABrightEnoughSpread) {
  const Vec3 off{0, 0, 0}, lamp{8, 6, 4}, sky{0.5f, 0.5f, 0.5f};
  const Vec3 inside[3] = {lamp, lamp, lamp}, edge[3] = {off, lamp, off}, dim[3] = {sky, off, sky};
  EXPECT_FALSE(light_colours_differ(inside, 3, 4));
  EXPECT_TRUE(light_colours_differ(edge, 3, 4));
  EXPECT_FALSE(light_colours_differ(dim, 3, 4));
  EXPECT_TRUE(light_colours_differ(dim, 3, 0));  // any difference at all with no threshold
  const Vec3 none[2] = {off, off};
  EXPECT_FALSE(light_colours_differ(none, 2, 0));
}

TEST(LightAA, BrightestLampSeenInRgb) {
  std::vector<Light> ls = lamps();
  Light point;
  point.type = LightType::Point;
  point.Le_rgb = Vec3{50, 50, 50};  // never met by a camera ray
  ls.push_back(point);
  Light material_lamp = triangle_light({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 30);
  material_lamp.material = 0;  // an emissive material: estimated spectrally, not as Le_rgb
  ls.push_back(material_lamp);
  SceneView s;
  s.lights = ls.data();
  s.n_lights = int(ls.size());
  Light sky;
  sky.type = LightType::EnvConstant;
  sky.Le_rgb = Vec3{40, 40, 40};  // never flags: its silhouettes are lit by itself
  ls.push_back(sky);
  s.lights = ls.data();
  s.n_lights = int(ls.size());
  EXPECT_FLOAT_EQ(brightest_lamp(s), 10);
}

}  // namespace
}  // namespace kauri
