// The CPU accelerator: analytic spheres and disks of the root group tested directly
// (EmbreeAccel::kMaxDirectShapes) must answer every query as Embree's own sphere and
// disk primitives do: the same shape, the same distance to float precision, the same
// occlusion, including rays that leave a shape's surface (self-intersection) and rays
// from inside a sphere.
#include <gtest/gtest.h>

#include <vector>

#include "kauri/accel/embree_accel.h"
#include "kauri/sampler/rng.h"
#include "kauri/sampler/sampling.h"

namespace kauri {
namespace {

struct TestScene {
  std::vector<Point3> p{{-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}, {0, 0, 0}};  // + Embree padding
  std::vector<uint32_t> index{0, 1, 2, 0, 2, 3};
  std::vector<ShapeView> shapes;
  TestScene() {
    ShapeView floor;
    floor.type = ShapeType::Mesh;
    floor.mesh.p = p.data();
    floor.mesh.index = index.data();
    floor.mesh.n_triangles = 2;
    floor.mesh.n_vertices = 4;
    shapes.push_back(floor);
    const SphereShape spheres[] = {{{0, 1, 0}, 1.0f}, {{1.7f, 0.5f, 0.3f}, 0.5f}, {{-1.2f, 0.3f, 1.1f}, 0.05f}};
    for (const SphereShape& s : spheres) {
      ShapeView v;
      v.type = ShapeType::Sphere;
      v.sphere = s;
      shapes.push_back(v);
    }
    ShapeView disk;
    disk.type = ShapeType::Disk;
    disk.disk = {{0.5f, 2.5f, -0.5f}, normalize(Vec3{0.2f, -1, 0.1f}), 0.8f};
    shapes.push_back(disk);
  }
};

Point3 random_point(PCG32& rng, Float extent) {
  return {(2 * rng.next_float() - 1) * extent, rng.next_float() * extent, (2 * rng.next_float() - 1) * extent};
}

/// Rays of three kinds: between random points (some inside the big sphere), and leaving a
/// point on a sphere's surface, outwards and inwards, as the path tracer spawns them.
std::vector<Ray> test_rays(const TestScene& sc, int n) {
  PCG32 rng;
  rng.set_sequence(21, 5);
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const int kind = i % 3;
    if (kind == 0) {
      Point3 o = random_point(rng, 3), t = random_point(rng, 3);
      rays.push_back(Ray{o, t - o, rng.next_float() < 0.5f ? kInfinity : Float(1)});
      continue;
    }
    const SphereShape& s = sc.shapes[1 + size_t(i) % 3].sphere;
    Vec3 n = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    Point3 p = s.center + n * s.radius;
    Vec3 d = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    if ((kind == 1) != (dot(d, n) > 0)) d = -d;  // kind 1 leaves outwards, kind 2 enters
    rays.push_back(spawn_ray(p, n, d));
  }
  return rays;
}

TEST(EmbreeAccel, DirectSpheresAndDisksMatchEmbree) {
  TestScene sc;
  EmbreeAccel direct, embree;
  direct.build({sc.shapes}, {}, {});
  embree.build({sc.shapes}, {}, {}, 0);
  ASSERT_EQ(direct.direct_shape_count(), 4u);
  ASSERT_EQ(embree.direct_shape_count(), 0u);
  int hits = 0, sphere_hits = 0, occluded = 0;
  for (const Ray& r : test_rays(sc, 30000)) {
    HitRecord a, b;
    const bool ha = direct.intersect(r, &a), hb = embree.intersect(r, &b);
    ASSERT_EQ(ha, hb) << "o " << r.o.x << " " << r.o.y << " " << r.o.z << " d " << r.d.x << " " << r.d.y << " "
                      << r.d.z;
    ASSERT_EQ(direct.occluded(r), embree.occluded(r));
    occluded += direct.occluded(r) ? 1 : 0;
    if (!ha) continue;
    ++hits;
    ASSERT_EQ(a.geom, b.geom);
    ASSERT_EQ(a.inst, b.inst);
    ASSERT_NEAR(a.t, b.t, 2e-5f * std::max(Float(1), b.t)) << "geom " << a.geom;
    if (sc.shapes[a.geom].type == ShapeType::Sphere) ++sphere_hits;
  }
  // The rays exercise what they should: many hits, many on spheres, both outcomes of occlusion.
  EXPECT_GT(hits, 15000);
  EXPECT_GT(sphere_hits, 6000);
  EXPECT_GT(occluded, 3000);
  EXPECT_LT(occluded, 27000);
}

TEST(EmbreeAccel, RayInsideASphereMeetsItOnTheWayOut) {
  TestScene sc;
  EmbreeAccel accel;
  accel.build({sc.shapes}, {}, {});
  HitRecord h;
  ASSERT_TRUE(accel.intersect(Ray{{0, 1, 0}, {1, 0, 0}, kInfinity}, &h));
  EXPECT_EQ(h.geom, 1u);
  EXPECT_NEAR(h.t, 1.0f, 1e-6f);
  // Unnormalised directions: t is in units of the direction's length.
  ASSERT_TRUE(accel.intersect(Ray{{0, 1, -4}, {0, 0, 2}, kInfinity}, &h));
  EXPECT_NEAR(h.t, 1.5f, 1e-6f);
  // A shadow ray that stops short of the sphere is not occluded by it.
  EXPECT_FALSE(accel.occluded(Ray{{0, 1, -4}, {0, 0, 2}, 1.4f}));
  EXPECT_TRUE(accel.occluded(Ray{{0, 1, -4}, {0, 0, 2}, 1.6f}));
}

TEST(EmbreeAccel, ManyAnalyticShapesStayInEmbree) {
  TestScene sc;
  for (int k = 0; k < int(EmbreeAccel::kMaxDirectShapes); ++k) {
    ShapeView v;
    v.type = ShapeType::Sphere;
    v.sphere = {{Float(k) * 0.3f - 1, 2.8f, 2.5f}, 0.1f};
    sc.shapes.push_back(v);
  }
  EmbreeAccel accel;
  accel.build({sc.shapes}, {}, {});
  EXPECT_EQ(accel.direct_shape_count(), 0u);
  HitRecord h;
  ASSERT_TRUE(accel.intersect(Ray{{-1, 2.8f, 0}, {0, 0, 1}, kInfinity}, &h));
  EXPECT_EQ(h.geom, 5u);
}

}  // namespace
}  // namespace kauri
