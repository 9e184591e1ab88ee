// Which scenes trace_paths_lanes() runs (host code, once per render).
#include "kauri/integrator/path_lanes.h"

namespace kauri {

namespace {
/// A material whose BSDF is one Lambert lobe with an untextured albedo and a constant
/// weight, and no emission: the vertex kind the lanes run.
bool lane_material(const SceneView& s, int material) {
  if (material < 0) return true;  // a pure emitter: the path ends there
  const MaterialView& m = s.materials[material];
  const LobeParams* params = s.lobes + m.first_lobe;
  return !m.emissive && material_detail::single_lobe(m, params) && params[0].type == LobeType::Lambert &&
         params[0].a_texture < 0 && s.node_weights[m.first_weight].attribute < 0;
}
}  // namespace

bool path_lanes_supported(const SceneView& s) {
#if KAURI_PATH_LANES
  if (s.n_instances != 1 || !s.instances[0].identity || s.n_infinite_lights != 0) return false;
  const GroupView& g = s.groups[s.instances[0].group];
  for (int i = 0; i < g.n_shapes; ++i)
    if (g.shapes[i].type != ShapeType::Mesh || !lane_material(s, g.shapes[i].material)) return false;
  for (int i = 0; i < s.n_lights; ++i)
    if (s.lights[i].type != LightType::Triangle || s.lights[i].material >= 0) return false;
  return true;
#else
  (void)s;
  return false;
#endif
}

}  // namespace kauri
