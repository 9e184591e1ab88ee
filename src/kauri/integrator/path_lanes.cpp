// Which scenes trace_paths_lanes() runs (host code, once per render).
#include "kauri/integrator/path_lanes.h"

#include <algorithm>

namespace kauri {

namespace {
/// Where the lanes run the vertices of `material` (LaneMaterial): one lobe with a constant
/// weight across the lanes, Lambert, a rough GGX conductor, a rough dielectric without
/// dispersion, a mirror or smooth glass without dispersion; any other BSDF whose weights
/// read no vertex attribute (the lanes do not interpolate them) lane by lane; the rest, and
/// emissive materials (whose lights path_lanes_supported leaves out), handed over to
/// trace_path.
LaneMaterial lane_material(const SceneView& s, int material) {
  const MaterialView& m = s.materials[material];
  if (m.emissive) return kHandOver;
  for (int i = 0; i < m.front.n_nodes; ++i)  // one weight a node (the back program shares them)
    if (s.node_weights[m.first_weight + i].attribute >= 0) return kHandOver;
  const LobeParams* params = s.lobes + m.first_lobe;
  if (!material_detail::single_lobe(m, params)) return kLaneBsdf;
  const LobeParams& l = params[0];
  if (l.type == LobeType::Lambert) return kLaneLambert;
  // GGX microfacets (Beckmann's sampler stays lane by lane); below α 1e-3 a mirror.
  const bool rough = !MicrofacetDistribution{l.alpha_x, l.alpha_y, l.microfacet}.effectively_smooth();
  if (l.type == LobeType::GGXConductor && l.microfacet == MicrofacetType::GGX && rough) return kLaneConductor;
  if (l.type == LobeType::RoughDielectric && rough && !l.ior.dispersive()) return kLaneDielectric;
  if ((l.type == LobeType::GGXConductor && !rough) || (l.type == LobeType::SmoothDielectric && !l.ior.dispersive()))
    return kLaneSpecular;
  return kLaneBsdf;
}
}  // namespace

bool path_lanes_supported(const SceneView& s) {
#if KAURI_PATH_LANES
  if (s.n_instances != 1 || !s.instances[0].identity) return false;
  const GroupView& g = s.groups[s.instances[0].group];
  size_t triangles = 0;
  bool any_lane_vertex = false;  // a surface whose vertices run across the vector
  for (int i = 0; i < g.n_shapes; ++i) {
    if (g.shapes[i].type == ShapeType::Mesh) triangles += g.shapes[i].mesh.n_triangles;
    if (g.shapes[i].material < 0) continue;
    const LaneMaterial lm = lane_material(s, g.shapes[i].material);
    any_lane_vertex |= lm == kLaneLambert || lm == kLaneConductor || lm == kLaneDielectric;
  }
  if (!any_lane_vertex || triangles > kPathLanesMaxTriangles) return false;
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
  t.shapes = shapes.data();
  t.lights = lights.data();
  t.triangles = triangles.data();
  t.uv = uv.empty() ? nullptr : uv.data();
  t.normals = normals.empty() ? nullptr : normals.data();
  t.env = env.data();
  t.lane_material = lane_material.data();
  t.dielectric_ms = dielectric_ms.empty() ? nullptr : dielectric_ms.data();
  t.common_emission_light = common_emission_light;
  t.any_quads = any_quads;
  return t;
}

/// Appends the guide table of the n-bin distribution with CDF `cdf` (LaneEnvTables) to
/// `out`: G + 1 entries, G the power of two ≥ n. Returns G.
static int append_guide(const float* cdf, int n, std::vector<int32_t>* out) {
  int G = 1;
  while (G < n) G *= 2;
  for (int j = 0; j <= G; ++j) out->push_back(find_interval(cdf, n, Float(j) / Float(G)));
  return G;
}

/// The triangle light whose emission id the most triangle lights share, if at least half of
/// them share it and that emission is an RGB illuminant spectrum (a sigmoid times the
/// working space's illuminant, what every RGB light colour becomes); else −1. Ties: the
/// lowest id. Why half: where the colours are many, most paths would replace the prefilled
/// one (the hangar's three colours: +0.7% instructions with it, callgrind).
static int common_emission_light(const SceneView& s) {
  std::vector<int> count, first;
  int triangle_lights = 0;
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    if (l.type != LightType::Triangle) continue;
    ++triangle_lights;
    if (l.emission_id < 0 || l.Le.type != SpectrumType::RGBIlluminant) continue;
    const size_t id = size_t(l.emission_id);
    if (id >= count.size()) count.resize(id + 1, 0), first.resize(id + 1, -1);
    if (count[id]++ == 0) first[id] = i;
  }
  int best = -1;
  for (size_t id = 0; id < count.size(); ++id)
    if (count[id] > 0 && (best < 0 || count[id] > count[size_t(best)])) best = int(id);
  return best < 0 || 2 * count[size_t(best)] < triangle_lights ? -1 : first[size_t(best)];
}

LaneTrianglesStore build_lane_triangles(const SceneView& s, const std::vector<uint8_t>& root_quads) {
  LaneTrianglesStore t;
  const InstanceView& root = s.instances[0];
  const GroupView& g = s.groups[root.group];
  size_t count = 0;
  bool reads_uv = false, any_n = false;
  for (int i = 0; i < g.n_shapes; ++i) {
    const ShapeView& shape = g.shapes[i];
    LaneShapeRow row;  // spheres and disks (first −1): their hits lane by lane, or a sphere's across the lanes
    row.material = shape.material;
    row.first_light = s.emitter_first_light[root.shape_slot_base + i];
    if (shape.type == ShapeType::Mesh) {
      row.first = int32_t(count);
      row.has_n = shape.mesh.n ? -1 : 0;
      count += shape.mesh.n_triangles;
      reads_uv |= shape.material >= 0 && s.materials[shape.material].reads_uv;
      any_n |= shape.mesh.n != nullptr;
    }
    row.quads = size_t(i) < root_quads.size() && root_quads[size_t(i)] ? -1 : 0;
    t.any_quads |= row.quads != 0;
    t.shapes.push_back(row);
  }
  if (t.shapes.empty()) t.shapes.emplace_back();  // the rows of dead lanes: entry 0
  // Per material of the root's shapes (the ones a lane's hit can be on): its LaneMaterial.
  int materials = 1;
  for (int i = 0; i < g.n_shapes; ++i) materials = std::max(materials, g.shapes[i].material + 1);
  t.lane_material.assign(size_t(materials), kHandOver);
  for (int i = 0; i < g.n_shapes; ++i)
    if (g.shapes[i].material >= 0) t.lane_material[size_t(g.shapes[i].material)] = lane_material(s, g.shapes[i].material);
  // The compensated rough dielectrics' multiple-scattering terms, for both sides: functions
  // of α and η alone, and η of a kLaneDielectric lobe is the same at every wavelength.
  for (int mi = 0; mi < materials; ++mi) {
    if (t.lane_material[size_t(mi)] != kLaneDielectric) continue;
    const int li = s.materials[mi].first_lobe;
    const LobeParams& p = s.lobes[li];
    const RoughDielectricLobe d = RoughDielectricLobe::make(SampledSpectrum(p.ior(550)), p.alpha_x, p.alpha_y, p.compensate);
    if (!d.compensated()) continue;
    if (t.dielectric_ms.size() < 2 * size_t(li + 1)) t.dielectric_ms.resize(2 * size_t(li + 1));
    for (int side = 0; side < 2; ++side) t.dielectric_ms[2 * size_t(li) + size_t(side)] = d.ms_terms(d.eta[0], side == 0);
  }
  t.lights.assign(std::max(s.n_lights, 1), LaneLightRow{});
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    if (l.type != LightType::Triangle) continue;
    LaneLightRow& r = t.lights[size_t(i)];
    for (int a = 0; a < 3; ++a) r.p0[a] = l.p0[a], r.p1[a] = l.p1[a], r.p2[a] = l.p2[a], r.n[a] = l.n[a];
    r.inv_area = 1 / l.area;
    r.two_sided = l.two_sided ? -1 : 0;
  }
  t.common_emission_light = common_emission_light(s);
  // Environment images: next-event estimation's density, read flat (Distribution2D's rows
  // lie one after another).
  t.env.assign(size_t(std::max(s.n_lights, 1)), LaneEnvTables{});
  t.env_guides.assign(t.env.size(), {});
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    if (l.type != LightType::EnvMap || !has_light_density(l, kNextEventDensity)) continue;
    const Distribution2D& d = env_distribution(l, kNextEventDensity);
    if (!(d.marginal.integral > 0)) continue;
    LaneEnvTables& e = t.env[size_t(i)];
    e.conditional_func = d.conditional[0].func, e.conditional_cdf = d.conditional[0].cdf;
    e.marginal_func = d.marginal.func, e.marginal_cdf = d.marginal.cdf, e.marginal_integral = d.marginal.integral;
    e.nu = d.nu, e.nv = d.nv;
    std::vector<int32_t>& g = t.env_guides[size_t(i)];
    e.gv = append_guide(d.marginal.cdf, d.nv, &g);
    for (int v = 0; v < d.nv; ++v) e.gu = append_guide(d.conditional[v].cdf, d.nu, &g);
    e.marginal_guide = g.data();
    e.conditional_guide = g.data() + e.gv + 1;
  }
  const size_t rows = std::max<size_t>(count, 1);
  t.triangles.assign(rows, LaneTriangleRow{});
  if (reads_uv) t.uv.assign(rows, LaneUvRow{});
  if (any_n) t.normals.assign(rows, LaneNormalRow{});
  for (int i = 0; i < g.n_shapes; ++i) {
    const ShapeView& shape = g.shapes[i];
    if (shape.type != ShapeType::Mesh) continue;
    const MeshView& m = shape.mesh;
    for (uint32_t prim = 0; prim < m.n_triangles; ++prim) {
      const size_t k = size_t(t.shapes[size_t(i)].first) + prim;
      // triangle_hit at barycentrics (0, 0): its normal and ∂p/∂u are the triangle's.
      SurfaceHit sh;
      triangle_hit(m, prim, 0, 0, &sh);
      const uint32_t* idx = m.index + 3 * prim;
      LaneTriangleRow& tr = t.triangles[k];
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) {
          tr.p[3 * v + a] = m.p[idx[v]][a];
          if (m.n) t.normals[k].n[3 * v + a] = m.n[idx[v]][a];
        }
      for (int a = 0; a < 3; ++a) tr.ng[a] = sh.ng[a], tr.dpdu[a] = sh.dpdu[a];
      if (!reads_uv) continue;
      // The default parameterisation uv = (0, 0), (1, 0), (1, 1) without uvs (triangle_hit).
      const Vec2 uv_default[3] = {{0, 0}, {1, 0}, {1, 1}};
      for (int v = 0; v < 3; ++v) {
        const Vec2 uv = m.uv ? m.uv[idx[v]] : uv_default[v];
        t.uv[k].uv[2 * v] = uv.x, t.uv[k].uv[2 * v + 1] = uv.y;
      }
    }
  }
  return t;
}

}  // namespace kauri
