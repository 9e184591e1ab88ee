// trace_paths_lanes (integrator/path_lanes.h): which scenes it runs, and that its images
// are trace_path's, pixel for pixel up to float rounding, with the same ray counts:
// a box of Lambert walls lit by a one-sided quad light (seen by the camera and through
// the BSDF samples), walls with per-vertex normals and uvs (the shading frame from ∂p/∂u),
// a two-sided light, a dark wall (w_b = 0), an analytic sphere (EmbreeAccel's direct
// shapes), the bounce budgets and roulette.
#include <gtest/gtest.h>

#include <cmath>

#include "kauri/integrator/path_lanes.h"
#include "kauri/render/renderer.h"
#include "kauri/scene/scene.h"

namespace kauri {
namespace {

MaterialDesc lambert(const std::string& name, Vec3 albedo, Float weight = 1) {
  MaterialDesc m;
  m.name = name;
  LobeDesc l;
  l.name = "base";
  l.type = LobeType::Lambert;
  l.albedo = albedo;
  l.weight.value = weight;
  m.lobes.push_back(l);
  return m;
}

MeshDesc quad(const std::string& name, std::initializer_list<float> p, int material) {
  MeshDesc m;
  m.name = name;
  m.positions = p;
  m.indices = {0, 1, 2, 3};
  m.face_size = 4;
  m.material = material;
  return m;
}

/// A Cornell-like box open towards the camera. `normals_and_uvs`: the back wall gets
/// bent per-vertex normals and a rotated uv layout; `two_sided`: the light emits both ways.
void add_box(Scene& s, bool normals_and_uvs, bool two_sided, bool sphere = false, bool sky = false) {
  const int white = s.add_material(lambert("white", {0.73f, 0.73f, 0.73f}));
  const int red = s.add_material(lambert("red", {0.63f, 0.065f, 0.05f}));
  const int green = s.add_material(lambert("green", {0.14f, 0.45f, 0.091f}));
  const int dark = s.add_material(lambert("dark", {0.5f, 0.5f, 0.5f}, 0));
  s.add_mesh(0, quad("floor", {-1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1}, white));
  s.add_mesh(0, quad("ceiling", {-1, 2, -1, 1, 2, -1, 1, 2, 1, -1, 2, 1}, white));
  MeshDesc back = quad("back", {-1, 0, -1, 1, 0, -1, 1, 2, -1, -1, 2, -1}, white);
  if (normals_and_uvs) {
    back.normals = {-0.3f, 0, 1, 0.3f, 0, 1, 0.3f, 0.2f, 1, -0.3f, 0.2f, 1};
    back.uvs = {0, 1, 0, 0, 1, 0, 1, 1};
  }
  s.add_mesh(0, back);
  s.add_mesh(0, quad("left", {-1, 0, 1, -1, 0, -1, -1, 2, -1, -1, 2, 1}, red));
  s.add_mesh(0, quad("right", {1, 0, -1, 1, 0, 1, 1, 2, 1, 1, 2, -1}, green));
  s.add_mesh(0, quad("patch", {0.2f, 0.01f, 0.2f, 0.7f, 0.01f, 0.2f, 0.7f, 0.01f, -0.3f, 0.2f, 0.01f, -0.3f}, dark));
  if (sphere) {  // analytic shapes: EmbreeAccel tests them itself (direct shapes)
    SphereDesc sp;
    sp.name = "ball";
    sp.center = {0.3f, 0.45f, 0.1f};
    sp.radius = 0.45f;
    sp.material = white;
    s.add_sphere(0, sp);
    DiskDesc dk;  // a tilted disk that shadows part of the box: a direct shape too
    dk.name = "plate";
    dk.center = {-0.45f, 1.3f, -0.2f};
    dk.normal = normalize(Vec3{0.3f, 1, 0.4f});
    dk.radius = 0.3f;
    dk.material = red;
    s.add_disk(0, dk);
  }
  if (sky) {  // infinite lights, seen and sampled through the open front
    LightDesc env;
    env.name = "sky";
    env.type = LightType::EnvMap;
    env.width = 16, env.height = 8;
    for (int y = 0; y < env.height; ++y)
      for (int x = 0; x < env.width; ++x) {
        const float hot = (x == 5 && y == 3) ? 40.0f : 0.0f;  // a small bright patch to sample
        env.image.insert(env.image.end(), {0.2f + hot + 0.05f * float(x), 0.3f + 0.5f * hot, 0.5f - 0.04f * float(y)});
      }
    s.add_light(env);
    LightDesc ambient;
    ambient.name = "ambient";
    ambient.type = LightType::EnvConstant;
    ambient.emission.rgb = {0.1f, 0.12f, 0.15f};
    s.add_light(ambient);
    LightDesc sun;
    sun.name = "sun";
    sun.type = LightType::Distant;
    sun.direction = normalize(Vec3{0.3f, -0.4f, -1});
    sun.emission.rgb = {1, 0.9f, 0.8f};
    sun.emission.intensity = 3;
    s.add_light(sun);
  }
  MeshDesc light = quad("light", {-0.25f, 1.99f, -0.25f, 0.25f, 1.99f, -0.25f, 0.25f, 1.99f, 0.25f, -0.25f, 1.99f, 0.25f}, -1);
  light.emissive = true;
  light.emission.rgb = {1, 0.85f, 0.6f};
  light.emission.intensity = 17;
  light.emission.two_sided = two_sided;
  s.add_mesh(0, light);
  CameraDesc cam;
  cam.eye = {0, 1, 3.85f};
  cam.target = {0, 1, 0};
  cam.fov = 38;
  s.set_camera(cam);
}

RenderResult render_box(const CompiledScene& c, bool lanes, int max_diffuse, int rr_depth) {
  RenderSettings cfg;
  cfg.width = cfg.height = 24;
  cfg.spp = 16;
  cfg.seed = 7;
  cfg.threads = 1;
  cfg.progress = false;
  cfg.integrator.path_lanes = lanes;
  cfg.integrator.max_diffuse = max_diffuse;
  cfg.integrator.rr_min_depth = rr_depth;
  return render(c, cfg);
}

void expect_same_images(bool normals_and_uvs, bool two_sided, int max_diffuse, int rr_depth, bool sphere = false,
                        bool sky = false) {
  Scene s;
  add_box(s, normals_and_uvs, two_sided, sphere, sky);
  auto c = s.compile(24, 24);
  ASSERT_TRUE(path_lanes_supported(c->view()));
  const RenderResult a = render_box(*c, false, max_diffuse, rr_depth);
  const RenderResult b = render_box(*c, true, max_diffuse, rr_depth);
  EXPECT_FALSE(a.stats.path_lanes);
  EXPECT_TRUE(b.stats.path_lanes);
  // A path whose last-bit difference flips a comparison (a roulette test, a hemisphere
  // sign) parts ways: allow a handful of rays in a million.
  const double rays_a = double(a.stats.rays), rays_b = double(b.stats.rays);
  EXPECT_NEAR(rays_b / rays_a, 1.0, 1e-5);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  double sum = 0, diff = 0;
  size_t differing = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    sum += std::fabs(double(a.rgba[i]));
    diff += std::fabs(double(a.rgba[i]) - double(b.rgba[i]));
    if (std::fabs(a.rgba[i] - b.rgba[i]) > 1e-4f * (1 + std::fabs(a.rgba[i]))) ++differing;
  }
  EXPECT_GT(sum, 0);
  EXPECT_LT(diff / sum, 1e-5) << "mean relative difference";
  EXPECT_LE(differing, a.rgba.size() / 500) << "values differing beyond rounding";
  // The data AOVs come from the first vertex, the same in both.
  ASSERT_EQ(a.albedo.size(), b.albedo.size());
  for (size_t i = 0; i < a.albedo.size(); ++i) EXPECT_NEAR(a.albedo[i], b.albedo[i], 1e-5f);
  for (size_t i = 0; i < a.normal.size(); ++i) EXPECT_NEAR(a.normal[i], b.normal[i], 1e-5f);
}

TEST(PathLanes, SameImageAsOnePathAtATime) { expect_same_images(false, false, 6, 4); }
TEST(PathLanes, ShadingNormalsUvFramesAndTwoSidedLight) { expect_same_images(true, true, 6, 4); }
TEST(PathLanes, RouletteFromTheFirstBounce) { expect_same_images(false, false, 6, 0); }
TEST(PathLanes, DiffuseBudgetOfOneAndNoRoulette) { expect_same_images(true, false, 1, 9); }
TEST(PathLanes, AnalyticSphereAndDisk) { expect_same_images(false, false, 6, 4, true); }
TEST(PathLanes, EnvironmentConstantAndDistantLights) { expect_same_images(false, false, 6, 4, true, true); }

TEST(PathLanes, OnlyLambertSurfacesTriangleAndInfiniteLightsRunInLanes) {
  auto supported = [](auto&& build) {
    Scene s;
    add_box(s, false, false);
    build(s);
    return path_lanes_supported(s.compile(8, 8)->view());
  };
  EXPECT_TRUE(supported([](Scene&) {}));
  EXPECT_TRUE(supported([](Scene& s) {  // an analytic sphere
    SphereDesc sp;
    sp.name = "ball";
    sp.radius = 0.3f;
    sp.material = 0;
    s.add_sphere(0, sp);
  }));
  EXPECT_FALSE(supported([](Scene& s) {  // an emissive sphere: a sphere light
    SphereDesc sp;
    sp.name = "lamp";
    sp.radius = 0.1f;
    sp.emissive = true;
    s.add_sphere(0, sp);
  }));
  EXPECT_FALSE(supported([](Scene& s) {  // a conductor
    MaterialDesc m = lambert("metal", {1, 1, 1});
    m.lobes[0].type = LobeType::GGXConductor;
    m.lobes[0].metal = "Au";
    s.add_mesh(0, quad("mirror", {-0.5f, 0.5f, -0.9f, 0.5f, 0.5f, -0.9f, 0.5f, 1, -0.9f, -0.5f, 1, -0.9f},
                       s.add_material(m)));
  }));
  EXPECT_TRUE(supported([](Scene& s) {  // a constant environment
    LightDesc env;
    env.name = "sky";
    env.type = LightType::EnvConstant;
    s.add_light(env);
  }));
  EXPECT_FALSE(supported([](Scene& s) {  // a point light
    LightDesc p;
    p.name = "bulb";
    p.position = {0, 1.5f, 0};
    s.add_light(p);
  }));
}

// Meshes beyond kPathLanesMaxTriangles take one path at a time (the lanes' tables would
// double the scene's memory).
TEST(PathLanes, LargeMeshesTakeOnePathAtATime) {
  auto grid = [](uint32_t quads) {
    MeshDesc m;
    m.name = "grid";
    m.face_size = 4;
    for (uint32_t i = 0; i <= quads; ++i) m.positions.insert(m.positions.end(), {float(i), 0, 0, float(i), 0, 1});
    for (uint32_t i = 0; i < quads; ++i) m.indices.insert(m.indices.end(), {2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1});
    m.material = 0;
    return m;
  };
  // The box holds 14 triangles (six walls and the light).
  auto supported = [&](uint32_t quads) {
    Scene s;
    add_box(s, false, false);
    s.add_mesh(0, grid(quads));
    return path_lanes_supported(s.compile(8, 8)->view());
  };
  EXPECT_TRUE(supported(uint32_t(kPathLanesMaxTriangles - 14) / 2));   // exactly the limit
  EXPECT_FALSE(supported(uint32_t(kPathLanesMaxTriangles - 14) / 2 + 1));
}

}  // namespace
}  // namespace kauri
