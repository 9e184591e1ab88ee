// SceneView: the compiled scene as plain data (pointers into host-owned arrays),
// everything render-time code needs besides the ray-query accelerator.
#pragma once

#include "kauri/bsdf/material.h"
#include "kauri/camera/camera.h"
#include "kauri/geometry/shapes.h"
#include "kauri/light/light.h"
#include "kauri/light/light_tree.h"
#include "kauri/spectral/wavelength_sampling.h"

namespace kauri {

struct GroupView {
  const ShapeView* shapes = nullptr;
  int n_shapes = 0;
};

/// Placement of a group. Instance 0 is the root group with the identity.
struct InstanceView {
  int group = 0;
  int shape_slot_base = 0;  // index into SceneView::emitter_first_light
  bool identity = true;
  Transform xf;
};

struct SceneView {
  const GroupView* groups = nullptr;
  const InstanceView* instances = nullptr;
  int n_instances = 0;
  int n_root_shapes = 0;                  // top-level geometry ids below this are root shapes
  const int* emitter_first_light = nullptr;  // per (instance, shape) slot, −1 if not emissive

  const MaterialView* materials = nullptr;
  const LobeParams* lobes = nullptr;
  const ScalarInput* node_weights = nullptr;
  const ImageTexture* textures = nullptr;

  const Light* lights = nullptr;
  int n_lights = 0;
  Distribution1D light_distribution;      // light selection ∝ power
  const int* infinite_lights = nullptr;
  int n_infinite_lights = 0;
  LightTreeView light_tree;               // finite lights ∝ importance at the point
  Distribution1D infinite_distribution;   // over infinite_lights, ∝ power
  Float finite_light_share = 0;           // probability that NEE picks a finite light

  Camera camera;
  Vec3 camera_forward{0, 0, -1};         // camera.forward(), set with `camera` by Scene::compile (the
                                          // depth AOV; computed per path it cost 2% of the hangar's render)
  Spectrum illuminant;                    // working-space white, Y = 1 (albedo AOV)
  Float xyz_to_rgb[3][3];                 // XYZ → working space
  WavelengthDistribution wavelengths;     // path wavelengths, matched to the working space

  KAURI_HOST_DEVICE Vec3 to_rgb(Vec3 xyz) const {
    return {xyz_to_rgb[0][0] * xyz.x + xyz_to_rgb[0][1] * xyz.y + xyz_to_rgb[0][2] * xyz.z,
            xyz_to_rgb[1][0] * xyz.x + xyz_to_rgb[1][1] * xyz.y + xyz_to_rgb[1][2] * xyz.z,
            xyz_to_rgb[2][0] * xyz.x + xyz_to_rgb[2][1] * xyz.y + xyz_to_rgb[2][2] * xyz.z};
  }
  /// u < finite_light_share (the finite lights' part of a light choice) rescaled to [0, 1)
  /// for the light tree.
  KAURI_HOST_DEVICE Float tree_u(Float u) const { return fmin_(u / finite_light_share, kOneMinusEpsilon); }
  /// The light next-event estimation samples from point p, and its probability (*pmf = 0:
  /// none). `tree`: finite lights through the light tree, with their total power share;
  /// otherwise every light ∝ power. Infinite lights keep their power share either way.
  /// `u_remapped` (optional) gets u rescaled to [0,1) within the chosen light's interval,
  /// so one coordinate of a stratified 2D sample can pick the light and then a point on it.
  KAURI_HOST_DEVICE int select_light(Float u, Point3 p, Normal3 n, bool tree, Float* pmf,
                                     Float* u_remapped = nullptr) const {
    if (!tree || light_tree.n_nodes == 0) return light_distribution.sample_discrete(u, pmf, u_remapped);
    const Float F = finite_light_share;
    if (u < F) {
      Float pt;
      const int li = light_tree.sample(tree_u(u), p, n, &pt, u_remapped);
      *pmf = F * pt;
      return li;
    }
    *pmf = 0;
    if (n_infinite_lights == 0 || !(infinite_distribution.integral > 0)) return -1;
    Float pi;
    const int k = infinite_distribution.sample_discrete(fmin_((u - F) / (1 - F), kOneMinusEpsilon), &pi, u_remapped);
    *pmf = (1 - F) * pi;
    return infinite_lights[k];
  }
  /// select_light(u[i], p[i], n[i], true, pmf + i, u_remapped + i) for count ≤
  /// kLightTreeBatch points at once: the tree's descents interleaved
  /// (LightTreeView::sample_many), the same choices bit for bit.
  KAURI_HOST_DEVICE void select_lights_tree(int count, const Float* u, const Point3* p, const Normal3* n, int* light,
                                            Float* pmf, Float* u_remapped) const {
    int index[kLightTreeBatch], chosen[kLightTreeBatch], m = 0;
    Float ut[kLightTreeBatch], pt[kLightTreeBatch], ur[kLightTreeBatch];
    Point3 pm[kLightTreeBatch];
    Normal3 nm[kLightTreeBatch];
    const Float F = finite_light_share;
    for (int i = 0; i < count; ++i) {
      if (light_tree.n_nodes == 0 || !(u[i] < F)) {  // the infinite lights' share: select_light's steps
        light[i] = select_light(u[i], p[i], n[i], true, pmf + i, u_remapped + i);
        continue;
      }
      index[m] = i, ut[m] = tree_u(u[i]), pm[m] = p[i], nm[m] = n[i];
      ++m;
    }
    light_tree.sample_many(m, ut, pm, nm, chosen, pt, ur);
    for (int j = 0; j < m; ++j) light[index[j]] = chosen[j], pmf[index[j]] = F * pt[j], u_remapped[index[j]] = ur[j];
  }
  /// Probability that select_light(·, p, n, tree) returns `light`.
  KAURI_HOST_DEVICE Float light_pmf(int light, Point3 p, Normal3 n, bool tree) const {
    if (!tree || light_tree.n_nodes == 0 || lights[light].is_infinite()) return light_distribution.discrete_pmf(light);
    return finite_light_share * light_tree.pmf(light, p, n);
  }
};

/// The instance a hit lies in (SceneView::instances; 0: the root's shapes).
KAURI_HOST_DEVICE inline int hit_instance(const SceneView& s, const HitRecord& h) {
  return h.inst == ~0u ? 0 : int(h.inst) - s.n_root_shapes + 1;
}

/// Whether a hit lies on an emissive shape (one with lights), without its surface geometry.
KAURI_HOST_DEVICE inline bool hit_may_emit(const SceneView& s, const HitRecord& h) {
  return s.emitter_first_light[s.instances[hit_instance(s, h)].shape_slot_base + int(h.geom)] >= 0;
}

/// Turns an accelerator hit into world-space surface geometry. Inlined into the path loop
/// (its one caller): out of line, the call, register saves and the SurfaceHit returned
/// through memory were ~45 of its ~250 instructions a hit.
KAURI_HOST_DEVICE KAURI_FORCE_INLINE SurfaceHit compute_surface_hit(const SceneView& s, const Ray& ray, const HitRecord& h) {
  SurfaceHit sh;
  const InstanceView& I = s.instances[hit_instance(s, h)];
  const ShapeView& shape = s.groups[I.group].shapes[h.geom];
  Ray r = ray;
  if (!I.identity) r = Ray{I.xf.inverse_point(ray.o), I.xf.inverse_vector(ray.d), ray.tmax};
  const bool need_uv = shape.material >= 0 && s.materials[shape.material].reads_uv;
  switch (shape.type) {
    case ShapeType::Mesh: triangle_hit(shape.mesh, h.prim, h.u, h.v, &sh); break;
    case ShapeType::Sphere: sphere_hit(shape.sphere, r, h.t, need_uv, &sh); break;
    case ShapeType::Disk: disk_hit(shape.disk, r, h.t, need_uv, &sh); break;
  }
  if (!I.identity) {
    sh.p = I.xf.point(sh.p);
    sh.ng = normalize(I.xf.normal(sh.ng));
    sh.ns = normalize(I.xf.normal(sh.ns));
    sh.dpdu = I.xf.vector(sh.dpdu);
  }
  sh.t = h.t;
  sh.material = shape.material;
  int first = s.emitter_first_light[I.shape_slot_base + int(h.geom)];
  sh.light = first < 0 ? -1 : first + (shape.type == ShapeType::Mesh ? int(h.prim) : 0);
  return sh;
}

}  // namespace kauri
