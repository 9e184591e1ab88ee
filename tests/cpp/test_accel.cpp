// The CPU accelerator: quad-pair meshes given to Embree as quads must answer as their
// triangles; analytic spheres and disks of the root group tested directly
// (EmbreeAccel::kMaxDirectShapes) must answer queries as Embree's own sphere and disk
// primitives do: the same shape, the same distance to float precision, the same
// occlusion, including rays that leave a shape's surface (self-intersection) and rays
// from inside a sphere; and be exact to float precision on spheres at extreme scales.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
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

// Packets (a pixel's camera rays): every lane answers exactly as intersect() does for its
// ray, with the direct shapes and with Embree's own spheres, for full and partial packets,
// coherent bundles and scattered rays alike.
TEST(EmbreeAccel, PacketAnswersAsSingleRays) {
  TestScene sc;
  for (size_t max_direct : {EmbreeAccel::kMaxDirectShapes, size_t(0)}) {
    EmbreeAccel accel;
    accel.build({sc.shapes}, {}, {}, max_direct);
    std::vector<Ray> rays = test_rays(sc, 6000);
    // Coherent bundles too: rays from one eye through a small patch, as a pixel's are.
    PCG32 rng;
    rng.set_sequence(4, 9);
    for (int i = 0; i < 3000; ++i) {
      Point3 eye{0.3f, 2.2f, 4.5f};
      Point3 target{-1.5f + 3 * Float(i % 60) / 60 + 0.05f * rng.next_float(), 0.8f * rng.next_float(),
                    -1.5f + 3 * Float(i / 60) / 50};
      rays.push_back(Ray{eye, normalize(target - eye), kInfinity});
    }
    int lanes = 0, hits = 0, packets = 0;
    for (size_t i = 0, n = 0; i < rays.size(); i += n, ++packets) {
      n = std::min<size_t>(EmbreeAccel::kPacketSize - packets % 3, rays.size() - i);  // full and partial packets
      HitRecord packet[EmbreeAccel::kPacketSize];
      bool found[EmbreeAccel::kPacketSize];
      accel.intersect_packet(&rays[i], int(n), packet, found);
      for (size_t k = 0; k < n; ++k, ++lanes) {
        HitRecord single;
        const bool h = accel.intersect(rays[i + k], &single);
        ASSERT_EQ(found[k], h) << "ray " << i + k;
        if (!h) continue;
        ++hits;
        EXPECT_EQ(packet[k].geom, single.geom);
        EXPECT_EQ(packet[k].prim, single.prim);
        EXPECT_EQ(packet[k].inst, single.inst);
        EXPECT_NEAR(packet[k].t, single.t, 1e-5f * std::max(Float(1), single.t));
        EXPECT_NEAR(packet[k].u, single.u, 1e-5f);
        EXPECT_NEAR(packet[k].v, single.v, 1e-5f);
      }
    }
    EXPECT_EQ(lanes, int(rays.size()));
    EXPECT_GT(hits, 4000);
  }
}

// Streams (ray replay's packet mode): packets of 8 and 16 incoherent rays, the last one
// partial, answer closest hits and occlusion exactly as the single-ray queries do, with
// the direct shapes and with Embree's own spheres; a width Embree has no packet for is refused.
TEST(EmbreeAccel, StreamAnswersAsSingleRays) {
  TestScene sc;
  const std::vector<Ray> rays = test_rays(sc, 6001);  // not a multiple of 8 or 16
  for (size_t max_direct : {EmbreeAccel::kMaxDirectShapes, size_t(0)}) {
    EmbreeAccel accel;
    accel.build({sc.shapes}, {}, {}, max_direct);
    for (int width : {8, 16}) {
      std::vector<HitRecord> hits(rays.size());
      std::vector<char> found(rays.size()), blocked(rays.size());
      static_assert(sizeof(bool) == sizeof(char), "bool arrays as char storage");
      accel.intersect_stream(rays.data(), rays.size(), width, hits.data(), reinterpret_cast<bool*>(found.data()));
      accel.occluded_stream(rays.data(), rays.size(), width, reinterpret_cast<bool*>(blocked.data()));
      int n_hits = 0, n_blocked = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        HitRecord single;
        const bool h = accel.intersect(rays[i], &single);
        ASSERT_EQ(bool(found[i]), h) << "width " << width << " ray " << i;
        ASSERT_EQ(bool(blocked[i]), accel.occluded(rays[i])) << "width " << width << " ray " << i;
        n_blocked += blocked[i] ? 1 : 0;
        if (!h) continue;
        ++n_hits;
        EXPECT_EQ(hits[i].geom, single.geom);
        EXPECT_EQ(hits[i].prim, single.prim);
        EXPECT_NEAR(hits[i].t, single.t, 1e-5f * std::max(Float(1), single.t));
      }
      EXPECT_GT(n_hits, 3000);
      EXPECT_GT(n_blocked, 500);
      EXPECT_LT(n_blocked, 5500);
    }
    HitRecord h;
    bool f;
    EXPECT_THROW(accel.intersect_stream(rays.data(), 1, 4, &h, &f), std::invalid_argument);
    EXPECT_THROW(accel.occluded_stream(rays.data(), 1, 32, &f), std::invalid_argument);
  }
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

TEST(EmbreeAccel, HugeAndTinySpheresAreExactToFloatPrecision) {
  // A planet-sized ground sphere (its top at y = 0) and a 1 mm ball 1 km away, checked
  // against exact (double) geometry. For the planet, float cannot do better than the
  // spacing at the centre's distance (ulp(1e4) ≈ 1e-3: o − c cannot hold a smaller
  // offset), so its hit points must lie on the sphere within 4 such spacings. For the
  // ball, the perpendicular-offset discriminant decides hits to 0.1% of the radius; Embree
  // (compared where the ray passes clear of the silhouette) misses some hits just inside it.
  std::vector<ShapeView> shapes(2);
  shapes[0].type = shapes[1].type = ShapeType::Sphere;
  shapes[0].sphere = {{0, -1e4f, 0}, 1e4f};
  shapes[1].sphere = {{0, 1, -1000}, 1e-3f};
  EmbreeAccel direct, embree;
  direct.build({shapes}, {}, {});
  embree.build({shapes}, {}, {}, 0);
  ASSERT_EQ(direct.direct_shape_count(), 2u);
  PCG32 rng;
  rng.set_sequence(8, 1);
  int ground = 0, ball = 0, compared = 0;
  for (int i = 0; i < 20000; ++i) {
    HitRecord a, b;
    if (i % 2 == 0) {  // towards the ground from above
      const Ray r{{0, 1 + 5 * rng.next_float(), 0}, sample_uniform_sphere({rng.next_float(), rng.next_float()}),
                  kInfinity};
      const bool ha = direct.intersect(r, &a);
      // Rays above the horizon miss; those well below it (the horizon dips ~2.5° at 3 m)
      // meet the planet.
      if (r.d.y > 0) {
        ASSERT_FALSE(ha) << i;
      }
      if (r.d.y < -0.1f) {
        ASSERT_TRUE(ha) << i;
      }
      if (!ha) continue;
      ASSERT_EQ(a.geom, 0u);
      const double t = double(a.t);
      const double p[3] = {double(r.o.x) + t * double(r.d.x), double(r.o.y) + t * double(r.d.y) + 1e4,
                           double(r.o.z) + t * double(r.d.z)};
      ASSERT_NEAR(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), 1e4, 4e-3) << i;
      ++ground;
      continue;
    }
    // At the ball, within two radii of its centre.
    const Point3 o{0, 1, 0}, c = shapes[1].sphere.center;
    const Point3 t = c + Vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0} * 4e-3f;
    const Ray r{o, normalize(t - o), kInfinity};
    const double f[3] = {double(c.x) - double(o.x), double(c.y) - double(o.y), double(c.z) - double(o.z)};
    const double d[3] = {r.d.x, r.d.y, r.d.z};
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], fd = f[0] * d[0] + f[1] * d[1] + f[2] * d[2];
    const double ff = f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
    const double perp = std::sqrt(std::max(0.0, ff - fd * fd / dd)) / 1e-3;  // in radii
    const bool ha = direct.intersect(r, &a);
    if (perp < 0.999) {
      ASSERT_TRUE(ha) << i << " perp " << perp;
    }
    if (perp > 1.001) {
      ASSERT_FALSE(ha) << i << " perp " << perp;
    }
    if (ha) {
      ASSERT_EQ(a.geom, 1u);
      ++ball;
    }
    if (perp < 0.99 || perp > 1.01) {
      ++compared;
      ASSERT_EQ(ha, embree.intersect(r, &b)) << i << " perp " << perp;
      if (ha) {
        ASSERT_NEAR(a.t, b.t, 1e-4f * b.t) << i;
      }
    }
  }
  EXPECT_GT(ground, 4000);
  EXPECT_GT(ball, 1500);  // π/16 of the rays aimed at the 4 r × 4 r square
  EXPECT_GT(compared, 9000);
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

TEST(EmbreeAccel, QuadPairsAreRecognised) {
  const Point3 p[5] = {};
  const uint32_t pairs[] = {0, 1, 2, 0, 2, 3, 1, 2, 3, 1, 3, 4};
  const uint32_t turned[] = {0, 1, 2, 2, 3, 0};  // the same quad split the other way round
  MeshView m;
  m.p = p;
  m.n_vertices = 5;
  m.index = pairs;
  m.n_triangles = 4;
  EXPECT_TRUE(EmbreeAccel::quad_pairs(m));
  m.n_triangles = 3;
  EXPECT_FALSE(EmbreeAccel::quad_pairs(m));
  m.index = turned;
  m.n_triangles = 2;
  EXPECT_FALSE(EmbreeAccel::quad_pairs(m));
}

// A root group of quad-pair meshes goes to Embree as quads (EmbreeAccel::quad_pairs);
// its hits must be the triangles' own: the same triangle, distance and barycentrics as
// the same mesh given as triangles (a lone triangle beside it keeps the group in
// triangles), on bent quads whose two triangles are not coplanar.
TEST(EmbreeAccel, QuadPairsHitAsTheirTriangles) {
  constexpr int kN = 4;  // kN × kN quads over [−2, 2]², heights bent at random
  PCG32 rng;
  rng.set_sequence(7, 3);
  std::vector<Point3> p;
  for (int j = 0; j <= kN; ++j)
    for (int i = 0; i <= kN; ++i) p.push_back({-2 + 4 * Float(i) / kN, 0.6f * rng.next_float(), -2 + 4 * Float(j) / kN});
  p.push_back({0, 0, 0});  // Embree padding
  std::vector<uint32_t> index;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const uint32_t a = uint32_t(j * (kN + 1) + i), b = a + 1, c = b + kN + 1, d = a + kN + 1;
      for (uint32_t v : {a, b, c, a, c, d}) index.push_back(v);  // scene.cpp's split of quad (a b c d)
    }
  std::vector<Point3> far{{50, 50, 50}, {51, 50, 50}, {50, 51, 50}, {0, 0, 0}};
  const std::vector<uint32_t> far_index{0, 1, 2};
  ShapeView grid, lone;
  grid.mesh.p = p.data();
  grid.mesh.index = index.data();
  grid.mesh.n_triangles = uint32_t(index.size() / 3);
  grid.mesh.n_vertices = uint32_t(p.size() - 1);
  lone.mesh.p = far.data();
  lone.mesh.index = far_index.data();
  lone.mesh.n_triangles = 1;
  lone.mesh.n_vertices = 3;
  EmbreeAccel quads, triangles;
  quads.build({{grid}}, {}, {});
  triangles.build({{grid, lone}}, {}, {});
  ASSERT_EQ(quads.root_quads(), std::vector<uint8_t>{1});
  ASSERT_EQ(triangles.root_quads(), (std::vector<uint8_t>{0, 0}));
  int hits = 0, second = 0;
  for (int k = 0; k < 4000; ++k) {
    const Point3 o{-2.5f + 5 * rng.next_float(), 2 + rng.next_float(), -2.5f + 5 * rng.next_float()};
    const Point3 target{-2 + 4 * rng.next_float(), 0.3f, -2 + 4 * rng.next_float()};
    const Ray r{o, normalize(target - o), kInfinity};
    HitRecord hq, ht;
    const bool fq = quads.intersect(r, &hq), ft = triangles.intersect(r, &ht);
    ASSERT_EQ(fq, ft) << "ray " << k;
    if (!ft) continue;
    ++hits;
    EXPECT_NEAR(hq.t, ht.t, 1e-4f * ht.t) << "ray " << k;
    // The hit point from each record's own triangle and barycentrics.
    auto point = [&](const HitRecord& h) {
      const uint32_t* t = index.data() + 3 * h.prim;
      return p[t[0]] * (1 - h.u - h.v) + p[t[1]] * h.u + p[t[2]] * h.v;
    };
    EXPECT_LT(length(point(hq) - point(ht)), 1e-4f) << "ray " << k;
    // Away from the shared diagonal a–c (weight 0 on b or on d) the triangle is the same.
    const Float off_diagonal = ht.prim % 2 == 0 ? ht.u : ht.v;
    if (off_diagonal > 1e-3f) {
      EXPECT_EQ(hq.prim, ht.prim) << "ray " << k;
      EXPECT_NEAR(hq.u, ht.u, 1e-4f) << "ray " << k;
      EXPECT_NEAR(hq.v, ht.v, 1e-4f) << "ray " << k;
    }
    second += int(ht.prim % 2);
  }
  EXPECT_GT(hits, 3000);
  EXPECT_GT(second, 1000);  // both triangles of the quads are met
}

// A mesh without uvs has the default parameterisation (0, 0), (1, 0), (1, 1) at its three
// vertices: triangle_hit's closed form for it (uv = (u + v, v), ∂p/∂u = e1) must equal the
// general path given those uvs explicitly, bit for bit.
TEST(TriangleHit, MeshWithoutUVsHasTheDefaultParameterisation) {
  const std::vector<Point3> p{{0.3f, -1.2f, 2.0f}, {4.1f, 0.7f, -1.5f}, {-2.2f, 3.3f, 0.4f}, {0, 0, 0}};
  const std::vector<uint32_t> index{0, 1, 2};
  const std::vector<Vec2> uv{{0, 0}, {1, 0}, {1, 1}};
  MeshView bare;
  bare.p = p.data();
  bare.index = index.data();
  bare.n_triangles = 1;
  bare.n_vertices = 3;
  MeshView with_uv = bare;
  with_uv.uv = uv.data();
  PCG32 rng(31, 7);
  for (int k = 0; k < 1000; ++k) {
    Float u = rng.next_float(), v = rng.next_float();
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    SurfaceHit a, b;
    triangle_hit(bare, 0, u, v, &a);
    triangle_hit(with_uv, 0, u, v, &b);
    ASSERT_EQ(a.uv.x, b.uv.x);
    ASSERT_EQ(a.uv.y, b.uv.y);
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(a.dpdu[c], b.dpdu[c]);
      ASSERT_EQ(a.p[c], b.p[c]);
    }
  }
}

// offset_ray_origin's vector form against the definition it replaces (Wächter & Binder
// 2019), axis by axis, bit for bit: positions near the origin (the absolute offset),
// large and negative ones (the offset in float steps), signed zeros and normals along and
// off the axes.
TEST(RayOffset, VectorFormMatchesTheDefinitionBitForBit) {
  auto reference = [](Point3 p, Normal3 n) {
    Point3 r;
    for (int a = 0; a < 3; ++a) {
      int32_t of_i = int32_t(256.0f * n[a]);
      float pi = bits_as_float(uint32_t(int32_t(float_as_bits(p[a])) + (p[a] < 0 ? -of_i : of_i)));
      r[a] = std::fabs(p[a]) < 1.0f / 32 ? p[a] + (1.0f / 65536) * n[a] : pi;
    }
    return r;
  };
  PCG32 rng(7, 11);
  std::vector<Point3> points = {{0, 0, 0}, {-0.0f, 0.0f, -0.0f}, {1.0f / 32, -1.0f / 32, 0.03f}, {1e6f, -1e6f, 3e-8f}};
  std::vector<Normal3> normals = {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}, normalize(Vec3{1, 1, 1})};
  for (int i = 0; i < 4000; ++i) {
    const Float scale = std::pow(10.0f, 8 * rng.next_float() - 4);  // 1e-4 … 1e4
    points.push_back(Point3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f} * scale);
    normals.push_back(sample_uniform_sphere({rng.next_float(), rng.next_float()}));
  }
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = i % normals.size(); j < normals.size(); j += 997) {
      const Point3 got = offset_ray_origin(points[i], normals[j]), want = reference(points[i], normals[j]);
      for (int a = 0; a < 3; ++a)
        ASSERT_EQ(float_as_bits(got[a]), float_as_bits(want[a])) << "point " << i << " normal " << j << " axis " << a;
    }
}

}  // namespace
}  // namespace kauri
