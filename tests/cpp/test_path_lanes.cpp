// trace_paths_lanes (integrator/path_lanes.h): which scenes it runs, and that its images
// are trace_path's, pixel for pixel up to float rounding, with the same ray counts:
// a box of Lambert walls lit by a one-sided quad light (seen by the camera and through
// the BSDF samples), walls with per-vertex normals and uvs (the shading frame from ∂p/∂u),
// a two-sided light, a dark wall (w_b = 0), an analytic sphere (EmbreeAccel's direct
// shapes), the bounce budgets and roulette.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "kauri/integrator/path_lanes.h"
#include "kauri/render/renderer.h"
#include "kauri/sampler/rng.h"
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
/// Materials other than Lambert: a rough glass sphere with dispersion and a layered
/// (two-lobe) wall, whose BSDFs the lanes build and sample lane by lane (kLaneBsdf), a rough
/// gold sphere and a brushed copper patch (kLaneConductor, across the lanes), a frosted and
/// a clouded (compensated) glass ball (kLaneDielectric), a smooth glass pane and a mirror
/// (kLaneSpecular), a small ball of uncompensated gold (kLaneConductor, its η and κ across
/// the lanes), and a wall whose lobe weight reads a vertex attribute, where the path goes on
/// one at a time from the hit (kHandOver).
void add_other_materials(Scene& s) {
  MaterialDesc gold = lambert("gold", {1, 1, 1});
  gold.lobes[0].type = LobeType::GGXConductor;
  gold.lobes[0].metal = "Au";
  gold.lobes[0].roughness = 0.3f;
  MaterialDesc glass = lambert("glass", {1, 1, 1});
  glass.lobes[0].type = LobeType::RoughDielectric;
  glass.lobes[0].roughness = 0.2f;
  glass.lobes[0].abbe = 30;  // dispersion: the path keeps one wavelength
  MaterialDesc pane = lambert("pane", {1, 1, 1});
  pane.lobes[0].type = LobeType::SmoothDielectric;
  MaterialDesc two = lambert("two", {0.4f, 0.5f, 0.6f});
  LobeDesc sheen = two.lobes[0];
  sheen.name = "sheen";
  sheen.type = LobeType::Sheen;
  two.lobes.push_back(sheen);
  LayerDesc coat;
  coat.name = "sheen_over_base";
  coat.op = LayerOp::Coat;
  coat.inputs = {"sheen", "base"};
  two.layers.push_back(coat);
  SphereDesc a;
  a.name = "gold_ball";
  a.center = {-0.45f, 0.35f, 0.2f};
  a.radius = 0.3f;
  a.material = s.add_material(gold);
  s.add_sphere(0, a);
  SphereDesc b = a;
  b.name = "glass_ball";
  b.center = {0.45f, 0.35f, -0.1f};
  b.material = s.add_material(glass);
  s.add_sphere(0, b);
  s.add_mesh(0, quad("pane", {-0.6f, 0.9f, 0.6f, 0.6f, 0.9f, 0.6f, 0.6f, 1.4f, 0.2f, -0.6f, 1.4f, 0.2f}, s.add_material(pane)));
  s.add_mesh(0, quad("sheen_patch", {-0.99f, 0.3f, 0.5f, -0.99f, 0.3f, -0.5f, -0.99f, 1.2f, -0.5f, -0.99f, 1.2f, 0.5f},
                     s.add_material(two)));
  // Brushed copper (RGB η and κ, anisotropic, without the multiple-scattering term) on a
  // quad with bent shading normals: the conductor lanes' frame, the ggx_conductor@1 lobe
  // and the shading-normal correction.
  MaterialDesc brushed = lambert("brushed", {1, 1, 1});
  brushed.lobes[0].type = LobeType::GGXConductor;
  brushed.lobes[0].eta_rgb = {0.27f, 0.68f, 1.22f};
  brushed.lobes[0].k_rgb = {3.6f, 2.6f, 2.3f};
  brushed.lobes[0].roughness = 0.45f;
  brushed.lobes[0].anisotropy = 0.7f;
  brushed.lobes[0].compensate = false;
  brushed.lobes[0].weight.value = 0.8f;
  MeshDesc floor_patch = quad("brushed_patch", {-0.8f, 0.02f, 0.9f, -0.1f, 0.02f, 0.9f, -0.1f, 0.02f, 0.3f, -0.8f, 0.02f, 0.3f},
                              s.add_material(brushed));
  floor_patch.normals = {0.2f, 1, 0.1f, -0.1f, 1, 0.2f, 0.1f, 1, -0.2f, -0.2f, 1, 0};
  floor_patch.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
  s.add_mesh(0, floor_patch);
  auto add_ball = [&](const char* name, Vec3 center, float radius, const MaterialDesc& m) {
    SphereDesc b;
    b.name = name;
    b.center = center;
    b.radius = radius;
    b.material = s.add_material(m);
    s.add_sphere(0, b);
  };
  // Frosted glass without dispersion or compensation (ggx_dielectric@1), anisotropic.
  MaterialDesc frosted = lambert("frosted", {1, 1, 1});
  frosted.lobes[0].type = LobeType::RoughDielectric;
  frosted.lobes[0].roughness = 0.35f;
  frosted.lobes[0].anisotropy = 0.3f;
  frosted.lobes[0].compensate = false;
  add_ball("frosted_ball", {0.05f, 0.25f, 0.55f}, 0.22f, frosted);
  // Clouded glass (ggx_dielectric@2: its multiple-scattering terms), without dispersion.
  MaterialDesc clouded = lambert("clouded", {1, 1, 1});
  clouded.lobes[0].type = LobeType::RoughDielectric;
  clouded.lobes[0].roughness = 0.6f;
  clouded.lobes[0].ior = 1.8f;
  add_ball("clouded_ball", {-0.55f, 1.25f, -0.5f}, 0.25f, clouded);
  // A silver mirror on the back wall (α = 0: a specular bounce).
  MaterialDesc mirror = lambert("mirror", {1, 1, 1});
  mirror.lobes[0].type = LobeType::GGXConductor;
  mirror.lobes[0].metal = "Ag";
  mirror.lobes[0].roughness = 0;
  s.add_mesh(0, quad("mirror", {0.1f, 0.6f, -0.98f, 0.8f, 0.6f, -0.98f, 0.8f, 1.5f, -0.98f, 0.1f, 1.5f, -0.98f},
                     s.add_material(mirror)));
  // Measured gold without the multiple-scattering term (ggx_conductor@1, as the glossy
  // bench scene's): its η and κ taken across the lanes (conductor_columns).
  MaterialDesc plain_gold = lambert("plain_gold", {1, 1, 1});
  plain_gold.lobes[0].type = LobeType::GGXConductor;
  plain_gold.lobes[0].metal = "Au";
  plain_gold.lobes[0].roughness = 0.15f;
  plain_gold.lobes[0].compensate = false;
  add_ball("plain_gold_ball", {0.65f, 1.65f, 0.35f}, 0.15f, plain_gold);
  MaterialDesc worn = lambert("worn", {0.3f, 0.6f, 0.9f});
  worn.lobes[0].weight.attribute = "wear";
  MeshDesc patch = quad("worn_patch", {0.99f, 0.3f, -0.5f, 0.99f, 0.3f, 0.5f, 0.99f, 1.2f, 0.5f, 0.99f, 1.2f, -0.5f},
                        s.add_material(worn));
  patch.attributes["wear"] = {0.2f, 1, 0.6f, 0.9f};
  s.add_mesh(0, patch);
}

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

RenderResult render_box(const CompiledScene& c, bool lanes, int max_diffuse, int rr_depth, int max_glossy,
                        int max_transmission, int spp) {
  RenderSettings cfg;
  cfg.width = cfg.height = 24;
  cfg.spp = spp;
  cfg.seed = 7;
  cfg.threads = 1;
  cfg.progress = false;
  cfg.integrator.path_lanes = lanes;
  cfg.integrator.max_diffuse = max_diffuse;
  cfg.integrator.rr_min_depth = rr_depth;
  cfg.integrator.max_glossy = max_glossy;
  cfg.integrator.max_transmission = max_transmission;
  return render(c, cfg);
}

void expect_same_images_of(Scene& s, int max_diffuse, int rr_depth, int max_glossy, int max_transmission, int spp);

void expect_same_images(bool normals_and_uvs, bool two_sided, int max_diffuse, int rr_depth, bool sphere = false,
                        bool sky = false, bool others = false, int max_glossy = 8, int max_transmission = 12,
                        int spp = 16) {
  Scene s;
  add_box(s, normals_and_uvs, two_sided, sphere, sky);
  if (others) add_other_materials(s);
  expect_same_images_of(s, max_diffuse, rr_depth, max_glossy, max_transmission, spp);
}

void expect_same_images_of(Scene& s, int max_diffuse, int rr_depth, int max_glossy, int max_transmission, int spp) {
  auto c = s.compile(24, 24);
  ASSERT_TRUE(path_lanes_supported(c->view()));
  const RenderResult a = render_box(*c, false, max_diffuse, rr_depth, max_glossy, max_transmission, spp);
  const RenderResult b = render_box(*c, true, max_diffuse, rr_depth, max_glossy, max_transmission, spp);
  EXPECT_FALSE(a.stats.path_lanes);
  EXPECT_TRUE(b.stats.path_lanes);
  // A path whose last-bit difference flips a comparison (a roulette test, a hemisphere
  // sign, a refraction near the critical angle) parts ways: allow a handful of rays in a
  // million, and at least 3 (these renders trace ~70 thousand).
  const double rays_a = double(a.stats.rays), rays_b = double(b.stats.rays);
  EXPECT_LE(std::fabs(rays_b - rays_a), std::max(3.0, 1e-5 * rays_a));
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
// 11 samples a pixel: a group of 8 and one of 3 camera rays, traced as 11 of 16 lanes with
// AVX-512 (kPathLanes) or as 8 and 3 of 8.
TEST(PathLanes, PixelsOfFewerSamplesThanLanes) {
  expect_same_images(false, false, 6, 4, true, true, true, 8, 12, 11);
}
TEST(PathLanes, ShadingNormalsUvFramesAndTwoSidedLight) { expect_same_images(true, true, 6, 4); }
TEST(PathLanes, RouletteFromTheFirstBounce) { expect_same_images(false, false, 6, 0); }
TEST(PathLanes, DiffuseBudgetOfOneAndNoRoulette) { expect_same_images(true, false, 1, 9); }
TEST(PathLanes, AnalyticSphereAndDisk) { expect_same_images(false, false, 6, 4, true); }
TEST(PathLanes, EnvironmentConstantAndDistantLights) { expect_same_images(false, false, 6, 4, true, true); }
// 24 small lamps under the ceiling beside the big one (52 triangle lights): the light tree
// chooses, the lanes' descents interleaved (SceneView::select_lights_tree), with the
// environment's share of the choices taken lane by lane.
TEST(PathLanes, ManyLampsChosenByTheLightTree) {
  Scene s;
  add_box(s, false, false, true, true);
  for (int i = 0; i < 24; ++i) {
    const float x = -0.9f + 0.15f * float(i % 12), z = i < 12 ? -0.8f : 0.6f, e = 0.04f;
    MeshDesc lamp = quad("lamp" + std::to_string(i), {x, 1.97f, z, x + e, 1.97f, z, x + e, 1.97f, z + e, x, 1.97f, z + e}, -1);
    lamp.emissive = true;
    lamp.emission.rgb = {1, 0.7f + 0.01f * float(i), 0.5f};
    lamp.emission.intensity = 40;
    s.add_mesh(0, lamp);
  }
  expect_same_images_of(s, 6, 4, 8, 12, 16);
}
// Paths that reach a conductor, a rough or smooth dielectric (with dispersion) or a
// two-lobe material scatter there lane by lane; at a material that reads vertex attributes
// they go on one at a time from that hit: the image is still trace_path's.
TEST(PathLanes, OtherMaterialsLaneByLaneOrHandedOver) { expect_same_images(false, false, 6, 4, true, true, true); }
// The same with a glossy budget of 1 and roulette from the start: the lanes' budgets and
// roulette see the BSDF lanes' glossy and transmission depths and η scale.
TEST(PathLanes, OtherMaterialsWithTightBudgets) {
  expect_same_images(false, false, 3, 0, true, true, true, 1, 2);
}

TEST(PathLanes, WhereEachMaterialsVerticesRun) {
  Scene s;
  add_box(s, false, false);
  add_other_materials(s);
  const LaneTrianglesStore t = build_lane_triangles(s.compile(8, 8)->view(), {});
  // white, red, green, dark (w_b = 0); gold, glass (dispersive, compensated), pane, sheen
  // over Lambert, brushed copper, frosted and clouded glass, a mirror, plain gold; the worn wall.
  const std::vector<uint8_t> expected = {kLaneLambert,   kLaneLambert,    kLaneLambert,    kLaneLambert,
                                         kLaneConductor, kLaneBsdf,       kLaneSpecular,   kLaneBsdf,
                                         kLaneConductor, kLaneDielectric, kLaneDielectric, kLaneSpecular,
                                         kLaneConductor, kHandOver};
  EXPECT_EQ(t.lane_material, expected);
}

TEST(PathLanes, WhichScenesRunInLanes) {
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
  EXPECT_TRUE(supported([](Scene& s) {  // a conductor: its vertices lane by lane
    MaterialDesc m = lambert("metal", {1, 1, 1});
    m.lobes[0].type = LobeType::GGXConductor;
    m.lobes[0].metal = "Au";
    s.add_mesh(0, quad("mirror", {-0.5f, 0.5f, -0.9f, 0.5f, 0.5f, -0.9f, 0.5f, 1, -0.9f, -0.5f, 1, -0.9f},
                       s.add_material(m)));
  }));
  auto only = [](auto&& set_lobe) {  // a scene of one quad, of one lobe
    Scene s;
    MaterialDesc m = lambert("only", {1, 1, 1});
    set_lobe(m.lobes[0]);
    s.add_mesh(0, quad("only", {-1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1}, s.add_material(m)));
    CameraDesc cam;
    cam.eye = {0, 1, 3};
    s.set_camera(cam);
    return path_lanes_supported(s.compile(8, 8)->view());
  };
  EXPECT_TRUE(only([](LobeDesc& l) {  // rough silver: across the lanes
    l.type = LobeType::GGXConductor;
    l.metal = "Ag";
  }));
  EXPECT_FALSE(only([](LobeDesc& l) {  // a mirror: nothing runs across the vector
    l.type = LobeType::GGXConductor;
    l.metal = "Ag";
    l.roughness = 0;
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

#if KAURI_PATH_LANES
// The environment image across the lanes (path_lanes_env.inl) against the scalar functions
// lane by lane: next-event samples (sample_light: direction, density, radiance) for
// stratified 2D samples, including u at the cells' edges where the scalar sampler nudges
// x back into its bin, and the radiance and density along escaped directions
// (infinite_light_Le_pdf).
TEST(PathLanes, EnvironmentImageAcrossTheLanesMatchesTheScalarFunctions) {
  using namespace path_lanes_detail;
  Scene scene;
  add_box(scene, false, false, false, true);
  const auto c = scene.compile(8, 8);
  const SceneView& v = c->view();
  const LaneTrianglesStore store = build_lane_triangles(v, {});
  int li = -1;
  for (int i = 0; i < v.n_lights; ++i)
    if (v.lights[i].type == LightType::EnvMap) li = i;
  ASSERT_GE(li, 0);
  const Light& l = v.lights[li];
  const LaneEnvTables& t = store.env[size_t(li)];
  ASSERT_NE(t.conditional_func, nullptr);
  SampledWavelengths lambda[W];
  for (int k = 0; k < W; ++k) lambda[k] = SampledWavelengths::sample_visible((Float(k) + 0.3f) / W);
  BatchColumns cols;
  for (int k = 0; k < W; ++k) cols.set_wavelengths(k, lambda[k]);
  LaneSpectra spectra;  // the illuminant across the lanes: checked in Le below
  spectra.prepare(cols, l.illuminant);
  auto near = [](Float a, Float b) { return std::fabs(a - b) <= 2e-5f * (1 + std::fabs(b)); };
  int samples = 0, nudged_checked = 0;
  for (int round = 0; round < 64; ++round) {
    alignas(32) float ux[W], uy[W];
    for (int k = 0; k < W; ++k) {
      const int j = round * W + k;
      // Even rounds: a 2D grid; odd rounds: exactly on the marginal's and a row's cdf steps.
      ux[k] = (Float(j % 23) + 0.5f) / 23, uy[k] = (Float(j / 23 % 29) + 0.5f) / 29;
      if (round % 2) {
        const int row = j % t.nv;
        uy[k] = t.marginal_cdf[row];
        ux[k] = t.conditional_cdf[row * (t.nu + 1) + j % t.nu];
        ++nudged_checked;
      }
    }
    V3 wi;
    LF pdf, Le[kSpectrumSamples];
    sample_env(l, t, load(ux), load(uy), ~LI{}, spectra, &wi, &pdf, Le);
    for (int k = 0; k < W; ++k) {
      const LightSample ls = sample_light(l, Point3{0, 1, 0}, Vec2{ux[k], uy[k]}, lambda[k], kNextEventDensity, nullptr);
      EXPECT_TRUE(near(pdf[k], ls.pdf)) << "round " << round << " lane " << k << ": " << pdf[k] << " vs " << ls.pdf;
      if (!(ls.pdf > 0)) continue;
      ++samples;
      EXPECT_TRUE(near(wi.x[k], ls.wi.x) && near(wi.y[k], ls.wi.y) && near(wi.z[k], ls.wi.z)) << "round " << round;
      for (int i = 0; i < kSpectrumSamples; ++i) EXPECT_TRUE(near(Le[i][k], ls.L[i])) << Le[i][k] << " vs " << ls.L[i];
    }
  }
  EXPECT_GT(samples, 250);  // the MIS-compensated density is zero below the mean: those samples fail
  EXPECT_GT(nudged_checked, 200);
  // Escaped directions: the radiance and density added by add_env_escaped, through a path
  // state of β = 1 that bounced once from a density of 1 (w_MIS = 1 / (1 + (pmf · pdf)²)).
  PCG32 rng(5, 9);
  for (int round = 0; round < 32; ++round) {
    Paths P{};
    V3Lanes dir;
    for (int k = 0; k < W; ++k) {
      const Vec3 w = sample_uniform_sphere({rng.next_float(), rng.next_float()});
      dir.set(k, w);
      P.depth[k] = 2, P.prev_pdf[k] = 1;
      P.beta.set(k, SampledSpectrum(1));
      P.L.set(k, SampledSpectrum(0)), P.L_direct.set(k, SampledSpectrum(0));
    }
    add_env_escaped(v, l, li, t, dir.load(), spectra, ~LI{}, P);
    // The colour camera rays see along the same directions (add_seen_directly), into the
    // outputs of the lanes in the mask only.
    PathOutput outs[W];
    const LI seen = (lane_index() & 1) == (round & 1);
    add_env_seen_directly(l, dir.load(), seen, outs);
    for (int k = 0; k < W; ++k) {
      Vec3 ref{0, 0, 0};
      if (seen[k]) ASSERT_TRUE(path_detail::add_seen_directly(l, dir.get(k), &ref));
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(near(outs[k].rgb_exact[c], ref[c])) << outs[k].rgb_exact[c] << " vs " << ref[c];
    }
    for (int k = 0; k < W; ++k) {
      Float pdf = 0;
      const SampledSpectrum Le = infinite_light_Le_pdf(l, dir.get(k), lambda[k], kNextEventDensity, &pdf);
      const Float pl = v.light_distribution.discrete_pmf(li) * pdf;
      const Float w_mis = 1 / (1 + pl * pl);
      for (int i = 0; i < kSpectrumSamples; ++i) {
        EXPECT_TRUE(near(P.L.v[i][k], Le[i] * w_mis)) << P.L.v[i][k] << " vs " << Le[i] * w_mis;
        EXPECT_EQ(P.L_direct.v[i][k], 0);  // after two bounces: indirect
      }
    }
  }
}
#endif

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
