// Which scenes trace_paths_lanes() runs (host code, once per render).
#include "kauri/integrator/path_lanes.h"

#include <algorithm>

namespace kauri {

namespace {
/// A material whose BSDF is one Lambert lobe with an untextured albedo and a constant
/// weight, and no emission: the vertex kind the lanes run.
bool lane_material(const SceneView& s, int material) {
  if (material < 0) return true;  // a pure emitter: the path ends there
  const MaterialView& m = s.materials[material];
  const LobeParams* params = s.lobes + m.first_lobe;
  return !m.emissive && material_detail::single_lobe(m, params) && params[0].type == LobeType::Lambert &&
         s.node_weights[m.first_weight].attribute < 0;
}
}  // namespace

bool path_lanes_supported(const SceneView& s) {
#if KAURI_PATH_LANES
  if (s.n_instances != 1 || !s.instances[0].identity) return false;
  const GroupView& g = s.groups[s.instances[0].group];
  size_t triangles = 0;
  for (int i = 0; i < g.n_shapes; ++i) {
    if (!lane_material(s, g.shapes[i].material)) return false;
    if (g.shapes[i].type == ShapeType::Mesh) triangles += g.shapes[i].mesh.n_triangles;
  }
  if (triangles > kPathLanesMaxTriangles) return false;
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    const bool triangle = l.type == LightType::Triangle && l.material < 0;
    const bool infinite = l.type == LightType::EnvConstant || l.type == LightType::EnvMap || l.type == LightType::Distant;
    if (!triangle && !infinite) return false;
  }
  return true;
#else
  (void)s;
  return false;
#endif
}

LaneTriangles LaneTrianglesStore::view() const {
  LaneTriangles t;
  t.first = first.data();
  t.quads = quads.data();
  t.any_quads = any_quads;
  for (int a = 0; a < 9; ++a) t.p[a] = p[a].data(), t.n[a] = n[a].data();
  for (int a = 0; a < 3; ++a) t.ng[a] = ng[a].data(), t.dpdu[a] = dpdu[a].data();
  for (int a = 0; a < 6; ++a) t.uv[a] = uv[a].data();
  t.has_n = has_n.data();
  t.material = material.data();
  t.light = light.data();
  t.reads_uv = reads_uv;
  return t;
}

LaneTrianglesStore build_lane_triangles(const SceneView& s, const std::vector<uint8_t>& root_quads) {
  LaneTrianglesStore t;
  const InstanceView& root = s.instances[0];
  const GroupView& g = s.groups[root.group];
  size_t count = 0;
  for (int i = 0; i < g.n_shapes; ++i) {
    const bool mesh = g.shapes[i].type == ShapeType::Mesh;
    t.first.push_back(mesh ? int32_t(count) : -1);  // spheres and disks: hits lane by lane
    t.quads.push_back(size_t(i) < root_quads.size() && root_quads[size_t(i)] ? -1 : 0);
    t.any_quads |= t.quads.back() != 0;
    if (mesh) count += g.shapes[i].mesh.n_triangles;
  }
  if (t.first.empty()) t.first.push_back(0), t.quads.push_back(0);  // gathers of dead lanes read entry 0
  for (auto* v : {t.p, t.n}) for (int a = 0; a < 9; ++a) v[a].resize(std::max<size_t>(count, 1));
  for (auto* v : {t.ng, t.dpdu}) for (int a = 0; a < 3; ++a) v[a].resize(std::max<size_t>(count, 1));
  for (int a = 0; a < 6; ++a) t.uv[a].resize(std::max<size_t>(count, 1));
  t.has_n.assign(std::max<size_t>(count, 1), 0);
  t.material.assign(std::max<size_t>(count, 1), -1);
  t.light.assign(std::max<size_t>(count, 1), -1);
  t.reads_uv = false;
  for (int i = 0; i < g.n_shapes; ++i) {
    const ShapeView& shape = g.shapes[i];
    if (shape.type != ShapeType::Mesh) continue;
    const MeshView& m = shape.mesh;
    t.reads_uv |= shape.material >= 0 && s.materials[shape.material].reads_uv;
    const int first_light = s.emitter_first_light[root.shape_slot_base + i];
    for (uint32_t prim = 0; prim < m.n_triangles; ++prim) {
      const size_t k = size_t(t.first[size_t(i)]) + prim;
      // triangle_hit at barycentrics (0, 0): its normal and ∂p/∂u are the triangle's.
      SurfaceHit sh;
      triangle_hit(m, prim, 0, 0, &sh);
      const uint32_t* idx = m.index + 3 * prim;
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) {
          t.p[3 * v + a][k] = m.p[idx[v]][a];
          if (m.n) t.n[3 * v + a][k] = m.n[idx[v]][a];
        }
      for (int a = 0; a < 3; ++a) t.ng[a][k] = sh.ng[a], t.dpdu[a][k] = sh.dpdu[a];
      // The default parameterisation uv = (0, 0), (1, 0), (1, 1) without uvs (triangle_hit).
      const Vec2 uv_default[3] = {{0, 0}, {1, 0}, {1, 1}};
      for (int v = 0; v < 3; ++v) {
        const Vec2 uv = m.uv ? m.uv[idx[v]] : uv_default[v];
        t.uv[2 * v][k] = uv.x, t.uv[2 * v + 1][k] = uv.y;
      }
      t.has_n[k] = m.n ? -1 : 0;
      t.material[k] = shape.material;
      t.light[k] = first_light < 0 ? -1 : first_light + int32_t(prim);
    }
  }
  return t;
}

}  // namespace kauri
