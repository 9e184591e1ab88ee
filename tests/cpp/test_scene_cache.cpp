// Scene::compiled keeps the compiled scene while the scene is unchanged and the image
// size is the same; any change, another size, a copy or an assignment compiles afresh.
#include <gtest/gtest.h>

#include "kauri/scene/scene.h"

namespace kauri {
namespace {

Scene scene_with_sphere(Float radius, Point3 eye) {
  Scene s;
  CameraDesc cam;
  cam.eye = eye;
  s.set_camera(cam);
  SphereDesc sphere;
  sphere.name = "ball";
  sphere.radius = radius;
  s.add_sphere(0, sphere);
  return s;
}

TEST(SceneCache, ReusedWhileUnchanged) {
  Scene s = scene_with_sphere(1, {0, 0, 5});
  bool reused = true;
  auto first = s.compiled(8, 8, &reused);
  EXPECT_FALSE(reused);
  auto second = s.compiled(8, 8, &reused);
  EXPECT_TRUE(reused);
  EXPECT_EQ(first.get(), second.get());
  s.compiled(16, 8, &reused);  // another size
  EXPECT_FALSE(reused);
  auto back = s.compiled(8, 8, &reused);  // one entry: the 8 × 8 form was replaced
  EXPECT_FALSE(reused);
  SphereDesc more;
  more.name = "more";
  more.center = {2, 0, 0};
  s.add_sphere(0, more);  // a change
  auto changed = s.compiled(8, 8, &reused);
  EXPECT_FALSE(reused);
  EXPECT_NE(changed.get(), back.get());
}

TEST(SceneCache, CopiesAndAssignmentsCompileAfresh) {
  // Same number of changes, so equal revision counters: only the cache reset tells them apart.
  Scene a = scene_with_sphere(1, {0, 0, 5});
  Scene b = scene_with_sphere(2, {0, 1, 6});
  bool reused = true;
  auto from_a = a.compiled(8, 8, &reused);
  Scene copy = a;
  copy.compiled(8, 8, &reused);
  EXPECT_FALSE(reused);
  a = b;
  auto from_b = a.compiled(8, 8, &reused);
  EXPECT_FALSE(reused);
  EXPECT_NE(from_a.get(), from_b.get());
  EXPECT_FLOAT_EQ(from_b->view().camera.forward().y, b.compile(8, 8)->view().camera.forward().y);
}

}  // namespace
}  // namespace kauri
