// Light antialiasing's screen mask (kauri/render/light_aa.h): every pixel from which a
// camera ray can see a bright lamp must be marked for a probe (an unmarked one never
// gets the extra rays: no bias, but the gain is lost there), the cases it cannot bound
// mark every pixel, and lamps the camera cannot see neither mark nor set the threshold.
// The probe's flag test itself.
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

SceneView view_of(const Camera& cam, const std::vector<Light>& lights) {
  SceneView s;
  s.camera = cam;
  s.lights = lights.data();
  s.n_lights = int(lights.size());
  return s;
}

Light sphere_light(Point3 c, Float r, Float radiance) {
  Light l;
  l.type = LightType::Sphere;
  l.p0 = c;
  l.radius = r;
  l.Le_rgb = Vec3{radiance, radiance, radiance};
  return l;
}

/// Ray–sphere distance, or a negative value on a miss.
Float hit_sphere(const Ray& r, Point3 c, Float radius) {
  const Vec3 oc = r.o - c;
  const Float b = dot(oc, r.d), disc = b * b - (length_squared(oc) - radius * radius);
  return disc < 0 ? Float(-1) : -b - std::sqrt(disc);
}

/// Every film position (random, many per pixel) whose camera ray meets one of the
/// lights bright enough for the mask's threshold lies in a marked pixel. Spheres are hit
/// at their bounding radius (an instance's scaled sphere lies within it).
void expect_mask_covers_lights(const Camera& cam, const std::vector<Light>& lights, Float min_spread) {
  const SceneView s = view_of(cam, lights);
  const LightAAMask mask = light_aa_candidates(s, cam.width, cam.height, kLightAASpreadShare, 1);
  EXPECT_FLOAT_EQ(mask.min_spread, min_spread);
  ASSERT_EQ(mask.pixels.size(), size_t(cam.width) * size_t(cam.height));
  PCG32 rng(7, 1);
  int seen = 0, marked = 0;
  for (uint8_t m : mask.pixels) marked += m;
  for (int i = 0; i < 400000; ++i) {
    const Vec2 film{rng.next_float() * Float(cam.width), rng.next_float() * Float(cam.height)};
    const Ray r = cam.generate_ray(film, Vec2{0.5f, 0.5f});
    for (const Light& l : lights) {
      const bool hit = l.type == LightType::Triangle ? hit_triangle(r, l) > 0
                                                     : hit_sphere(r, l.p0, fmax_(l.radius, l.bound_radius)) > 0;
      if (max_component(l.Le_rgb) < min_spread || !hit) continue;
      ++seen;
      ASSERT_EQ(mask.pixels[size_t(int(film.y)) * size_t(cam.width) + size_t(int(film.x))], 1)
          << "film position " << film.x << ", " << film.y;
    }
  }
  EXPECT_GT(seen, 100);                                       // the lights are on screen
  EXPECT_LT(marked, cam.width * cam.height / 4) << "the mask should stay local";
}

std::vector<Light> lamps() {
  Light scaled = sphere_light({-0.3f, 0.1f, 2}, 0.05f, 9);
  scaled.bound_radius = 0.2f;  // an instance's stretched sphere: radius is its average
  return {triangle_light({-1.0f, 2.0f, 0}, {-0.7f, 2.0f, 0}, {-1.0f, 2.0f, 0.3f}, 10),
          triangle_light({0.5f, 0.2f, 1}, {0.8f, 0.2f, 1}, {0.5f, 0.6f, 1}, 8),
          triangle_light({1.5f, 1.0f, -1}, {2.5f, 1.0f, -1}, {1.5f, 2.0f, -1}, 1),  // below the spread
          sphere_light({1.0f, 1.6f, 0.5f}, 0.08f, 7), scaled};
}

TEST(LightAA, MaskCoversEveryPixelSeeingABrightLightPerspective) {
  expect_mask_covers_lights(make_camera(CameraType::Perspective, 96, 64), lamps(), 5);
}

TEST(LightAA, MaskCoversEveryPixelSeeingABrightLightOrthographic) {
  expect_mask_covers_lights(make_camera(CameraType::Orthographic, 80, 60), lamps(), 5);
}

TEST(LightAA, LampsOutOfViewSetNoThreshold) {
  std::vector<Light> ls = lamps();
  ls.push_back(triangle_light({-1, -1, 7}, {1, -1, 7}, {0, 1, 7}, 400));    // behind the camera
  ls.push_back(triangle_light({60, 0, 0}, {61, 0, 0}, {60, 1, 0}, 400));    // far off screen
  expect_mask_covers_lights(make_camera(CameraType::Perspective, 96, 64), ls, 5);
}

TEST(LightAA, FilterImportanceMarginReachesFurther) {
  const Camera cam = make_camera(CameraType::Perspective, 96, 64);
  const std::vector<Light> ls = lamps();
  const SceneView s = view_of(cam, ls);
  const LightAAMask m1 = light_aa_candidates(s, cam.width, cam.height, kLightAASpreadShare, 1);
  const LightAAMask m3 = light_aa_candidates(s, cam.width, cam.height, kLightAASpreadShare, 3);
  int grown = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      bool near = false;  // within 2 pixels of a margin-1 mark
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int u = x + dx, v = y + dy;
          near = near || (u >= 0 && v >= 0 && u < cam.width && v < cam.height && m1.pixels[size_t(v * cam.width + u)]);
        }
      EXPECT_EQ(m3.pixels[size_t(y * cam.width + x)], near ? 1 : 0) << x << ", " << y;
      grown += m3.pixels[size_t(y * cam.width + x)] - m1.pixels[size_t(y * cam.width + x)];
    }
  EXPECT_GT(grown, 0);
}

TEST(LightAA, MaskMarksEverythingWhereItCannotBound) {
  std::vector<Light> ls = lamps();
  SceneView s = view_of(make_camera(CameraType::Perspective, 32, 24), ls);
  auto all_marked = [&](const SceneView& v) {
    const LightAAMask m = light_aa_candidates(v, v.camera.width, v.camera.height, kLightAASpreadShare, 1);
    for (uint8_t x : m.pixels)
      if (!x) return false;
    return !m.pixels.empty();
  };
  EXPECT_FALSE(all_marked(s));
  s.camera.lens_radius = 0.1f;  // defocus spreads a light over pixels its box does not cover
  EXPECT_TRUE(all_marked(s));
  s.camera.lens_radius = 0;
  // A lamp across the camera's plane: its projection is unbounded.
  ls.push_back(triangle_light({-1, 1, 5.5f}, {1, 1, 5.5f}, {0, 1, 6.5f}, 9));
  s = view_of(s.camera, ls);
  EXPECT_TRUE(all_marked(s));
  ls.pop_back();
  Light sun;
  sun.type = LightType::Distant;
  sun.n = normalize(Vec3{0.0f, -0.1f, 1.0f});  // light travels towards +z: seen by rays towards −z, in view
  sun.cos_max = 0.999f;
  sun.Le_rgb = Vec3{6, 6, 6} * distant_cone_projected_solid_angle(sun);  // radiance 6 in its cone
  ls.push_back(sun);
  s = view_of(s.camera, ls);
  EXPECT_TRUE(all_marked(s));
  ls.back().n = Vec3{0, 0, -1};  // the same sun behind the camera: no ray of it meets it
  s = view_of(s.camera, ls);
  EXPECT_FALSE(all_marked(s));
  ls.back().n = normalize(Vec3{0.0f, -0.1f, 1.0f});
  ls.back().Le_rgb = Vec3{4, 4, 4} * distant_cone_projected_solid_angle(sun);  // radiance 4 < the spread 5
  s = view_of(s.camera, ls);
  EXPECT_FALSE(all_marked(s));
  ls.back().Le_rgb = Vec3{6, 6, 6};
  ls.back().cos_max = 1;  // a delta sun is never met by a camera ray
  s = view_of(s.camera, ls);
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

TEST(LightAA, ThresholdFromTheBrightestLampSeenInRgb) {
  std::vector<Light> ls = lamps();
  Light point;
  point.type = LightType::Point;
  point.Le_rgb = Vec3{50, 50, 50};  // never met by a camera ray
  ls.push_back(point);
  Light material_lamp = triangle_light({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 30);
  material_lamp.material = 0;  // an emissive material: estimated spectrally, not as Le_rgb
  ls.push_back(material_lamp);
  Light sky;
  sky.type = LightType::EnvConstant;
  sky.Le_rgb = Vec3{40, 40, 40};  // never flags: its silhouettes are lit by itself
  ls.push_back(sky);
  const Camera cam = make_camera(CameraType::Perspective, 32, 24);
  const SceneView s = view_of(cam, ls);
  EXPECT_FLOAT_EQ(light_aa_candidates(s, cam.width, cam.height, 0.5f, 1).min_spread, 5);
  const std::vector<Light> none = {point, material_lamp, sky};
  const LightAAMask m = light_aa_candidates(view_of(cam, none), cam.width, cam.height, 0.5f, 1);
  EXPECT_TRUE(m.pixels.empty());
  EXPECT_EQ(m.min_spread, 0);
}

}  // namespace
}  // namespace kauri
