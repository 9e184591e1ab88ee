// Light::emission_id and EmissionCache: lights whose emission spectra are equal share an
// id when the scene compiles, lights of other colours, temperatures or intensities do
// not, and a path's cache answers exactly what evaluating the light's Le would.
#include <gtest/gtest.h>

#include "kauri/scene/scene.h"

namespace kauri {
namespace {

MeshDesc emissive_quad(const std::string& name, Float x, EmissionDesc e) {
  MeshDesc m;
  m.name = name;
  m.positions = {x, 0, 0, x + 1, 0, 0, x + 1, 1, 0, x, 1, 0};
  m.indices = {0, 1, 2, 3};
  m.face_size = 4;
  m.emissive = true;
  m.emission = e;
  return m;
}

EmissionDesc rgb_emission(Vec3 rgb, Float intensity) {
  EmissionDesc e;
  e.rgb = rgb;
  e.intensity = intensity;
  return e;
}

TEST(EmissionCache, EqualSpectraShareAnId) {
  Scene s;
  s.set_camera(CameraDesc{});
  s.add_mesh(0, emissive_quad("warm", 0, rgb_emission({1, 0.8f, 0.6f}, 5)));
  s.add_mesh(0, emissive_quad("warm again", 2, rgb_emission({1, 0.8f, 0.6f}, 5)));
  s.add_mesh(0, emissive_quad("brighter", 4, rgb_emission({1, 0.8f, 0.6f}, 7)));
  s.add_mesh(0, emissive_quad("blue", 6, rgb_emission({0.3f, 0.5f, 1}, 5)));
  EmissionDesc bb;
  bb.temperature = 3000;
  s.add_mesh(0, emissive_quad("blackbody", 8, bb));
  LightDesc point;
  point.name = "point";
  point.emission = rgb_emission({1, 0.8f, 0.6f}, 5);
  s.add_light(point);
  auto c = s.compile(8, 8);
  const SceneView& v = c->view();
  ASSERT_EQ(v.n_lights, 11);  // five quads of two triangles, one point light
  std::vector<int> id;
  for (int i = 0; i < v.n_lights; ++i) id.push_back(v.lights[i].emission_id);
  for (int x : id) EXPECT_GE(x, 0);
  // A quad's two triangles, and the two warm quads of equal intensity: one id.
  EXPECT_EQ(id[0], id[1]);
  EXPECT_EQ(id[0], id[2]);
  EXPECT_EQ(id[0], id[3]);
  // Another intensity, colour or kind of spectrum: ids of their own.
  EXPECT_EQ(id[4], id[5]);
  EXPECT_NE(id[4], id[0]);
  EXPECT_NE(id[6], id[0]);
  EXPECT_NE(id[6], id[4]);
  EXPECT_NE(id[8], id[0]);
  EXPECT_NE(id[8], id[4]);
  EXPECT_NE(id[8], id[6]);
  // The point light has the warm quads' radiance spectrum as its intensity: one function.
  EXPECT_EQ(id[10], id[0]);

  // The cache gives what the light's own Le gives, through any order of lights.
  const SampledWavelengths lambda = SampledWavelengths::sample_visible(0.37f);
  EmissionCache cache;
  const int order[] = {0, 1, 4, 4, 6, 0, 8, 10, 3, 8};
  for (int i : order) {
    const Light& l = v.lights[i];
    SampledSpectrum direct = l.Le.sample(lambda), cached = cache.emission(l, lambda);
    for (int k = 0; k < kSpectrumSamples; ++k) EXPECT_EQ(cached[k], direct[k]) << "light " << i << ", wavelength " << k;
  }
}

}  // namespace
}  // namespace kauri
