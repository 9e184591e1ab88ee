#include "kauri/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace kauri {

namespace {

[[noreturn]] void fail(const std::string& object, const std::string& param, const std::string& what) {
  throw std::invalid_argument(object + ": parameter '" + param + "': " + what);
}

std::string quoted(const char* kind, const std::string& name) { return std::string(kind) + " '" + name + "'"; }

void check_finite(const std::string& obj, const char* param, Float v) {
  if (!std::isfinite(v)) fail(obj, param, "must be finite, got " + std::to_string(v));
}
void check_finite(const std::string& obj, const char* param, Vec3 v) {
  if (!is_finite(v)) fail(obj, param, "must be finite");
}
void check_range(const std::string& obj, const char* param, Float v, Float lo, Float hi) {
  if (!(v >= lo && v <= hi)) {
    std::ostringstream os;
    os << "must lie in [" << lo << ", " << hi << "], got " << v;
    fail(obj, param, os.str());
  }
}

void check_emission(const std::string& obj, const EmissionDesc& e) {
  check_finite(obj, "color", e.rgb);
  if (e.rgb.x < 0 || e.rgb.y < 0 || e.rgb.z < 0) fail(obj, "color", "components must be >= 0");
  check_finite(obj, "intensity", e.intensity);
  if (e.intensity < 0) fail(obj, "intensity", "must be >= 0");
  check_finite(obj, "temperature", e.temperature);
  if (e.temperature < 0 || (e.temperature > 0 && e.temperature < 100))
    fail(obj, "temperature", "must be 0 (use color) or a temperature >= 100 K");
}

Float triangle_area(Point3 a, Point3 b, Point3 c) { return length(cross(b - a, c - a)) / 2; }

}  // namespace

Scene::Scene() { groups_.push_back(Group{"root", {}}); }

void Scene::check_group(int group, const std::string& what) const {
  if (group < 0 || group >= int(groups_.size()))
    fail(what, "group", "unknown group id " + std::to_string(group));
}
void Scene::check_material(int material, const std::string& what) const {
  if (material < -1 || material >= int(materials_.size()))
    fail(what, "material", "unknown material id " + std::to_string(material));
}

namespace {
void check_lobe(const std::string& obj, const LobeDesc& m) {
  if (m.emission) {
    check_emission(obj, EmissionDesc{m.emission_rgb, m.temperature, m.intensity, m.two_sided});
    check_range(obj, "focus", m.focus, 0, 1000);
    if (m.spectrum_nm.size() != m.spectrum_values.size())
      fail(obj, "spectrum", "wavelengths and values must have the same length");
    if (!m.spectrum_nm.empty()) {
      if (m.spectrum_nm.size() < 2) fail(obj, "spectrum", "needs at least 2 samples");
      for (size_t i = 0; i < m.spectrum_nm.size(); ++i) {
        if (!std::isfinite(m.spectrum_nm[i]) || !std::isfinite(m.spectrum_values[i]) || m.spectrum_values[i] < 0)
          fail(obj, "spectrum", "samples must be finite, values >= 0");
        if (i > 0 && !(m.spectrum_nm[i] > m.spectrum_nm[i - 1]))
          fail(obj, "spectrum", "wavelengths must increase strictly");
      }
    }
    return;
  }
  switch (m.type) {
    case LobeType::OrenNayar:
      check_range(obj, "roughness", m.roughness, 0, 1);
      [[fallthrough]];
    case LobeType::Lambert:
      check_finite(obj, "albedo", m.albedo);
      for (int i = 0; i < 3; ++i) check_range(obj, "albedo", m.albedo[i], 0, 1);
      break;
    case LobeType::DiffuseTransmission:
    case LobeType::Sheen:
      check_finite(obj, m.type == LobeType::Sheen ? "color" : "transmittance", m.albedo);
      for (int i = 0; i < 3; ++i) check_range(obj, m.type == LobeType::Sheen ? "color" : "transmittance", m.albedo[i], 0, 1);
      if (m.type == LobeType::Sheen) check_range(obj, "roughness", m.roughness, 0, 1);
      break;
    case LobeType::SmoothDielectric:
    case LobeType::RoughDielectric:
    case LobeType::ThinDielectric:
      check_finite(obj, "ior", m.ior);
      check_range(obj, "ior", m.ior, 1.0f / 4, 4);
      check_finite(obj, "abbe", m.abbe);
      if (m.abbe < 0) fail(obj, "abbe", "must be >= 0 (0 = no dispersion)");
      if (m.type == LobeType::RoughDielectric) {
        check_range(obj, "roughness", m.roughness, 0, 1);
        check_range(obj, "anisotropy", m.anisotropy, -1, 1);
      }
      break;
    case LobeType::GGXConductor:
      check_range(obj, "roughness", m.roughness, 0, 1);
      check_range(obj, "anisotropy", m.anisotropy, -1, 1);
      if (m.artist) {
        for (int i = 0; i < 3; ++i) {
          check_range(obj, "reflectivity", m.reflectivity[i], 0, 0.999f);
          check_range(obj, "edge_tint", m.edge_tint[i], 0, 1);
        }
        break;
      }
      if (!m.metal.empty() && !tables::find_metal(m.metal))
        fail(obj, "metal", "unknown metal '" + m.metal + "'; known: " + tables::known_metal_names());
      if (m.metal.empty()) {
        check_finite(obj, "eta", m.eta_rgb);
        check_finite(obj, "k", m.k_rgb);
        if (m.eta_rgb.x <= 0 || m.eta_rgb.y <= 0 || m.eta_rgb.z <= 0) fail(obj, "eta", "components must be > 0");
        if (m.k_rgb.x < 0 || m.k_rgb.y < 0 || m.k_rgb.z < 0) fail(obj, "k", "components must be >= 0");
      }
      break;
    default:
      throw std::invalid_argument(obj + ": this lobe type is not available in materials yet");
  }
}
}  // namespace

int Scene::add_texture(TextureDesc t) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("texture", t.name);
  if (t.width <= 0 || t.height <= 0) fail(obj, "image", "must have at least one texel");
  if (!t.texels || t.texels->size() != size_t(t.width) * size_t(t.height) * 3)
    fail(obj, "image", "must hold width × height × 3 values");
  t.max_value = 0;
  for (float v : *t.texels) {
    if (!std::isfinite(v) || v < 0) fail(obj, "image", "texels must be finite and >= 0");
    t.max_value = std::max(t.max_value, v);
  }
  textures_.push_back(std::move(t));
  return int(textures_.size()) - 1;
}

void Scene::check_texture_use(const std::string& obj, const LobeDesc& l) const {
  if (l.albedo_texture < 0) return;
  const char* param = l.type == LobeType::Sheen ? "color"
                      : l.type == LobeType::DiffuseTransmission ? "transmittance" : "albedo";
  if (l.emission || !(l.type == LobeType::Lambert || l.type == LobeType::OrenNayar ||
                      l.type == LobeType::DiffuseTransmission || l.type == LobeType::Sheen))
    fail(obj, "texture", "only lambert, oren_nayar, diffuse_transmission and sheen colours can be textured");
  if (l.albedo_texture >= int(textures_.size()))
    fail(obj, param, "refers to texture " + std::to_string(l.albedo_texture) + ", which does not exist");
  const TextureDesc& t = textures_[size_t(l.albedo_texture)];
  if (t.max_value > 1)
    fail(obj, param, "texture '" + t.name + "' has texels up to " + std::to_string(t.max_value) +
                         "; a reflectance texture must lie in [0, 1]");
}

int Scene::add_material(const MaterialDesc& m) {
  ++revision_;  // any change invalidates the compiled-scene cache
  for (const LobeDesc& l : m.lobes) {
    // Single-lobe materials keep the short form "material 'x'" in messages.
    std::string obj = m.lobes.size() == 1 && m.layers.empty() ? quoted("material", m.name)
                                                               : "material '" + m.name + "', node '" + l.name + "'";
    check_lobe(obj, l);
    check_texture_use(obj, l);
  }
  CompiledMaterial c = compile_material(m);  // validates the graph
  for (const std::string& w : c.warnings) warnings_.push_back(w);
  materials_.push_back(m);
  compiled_materials_.push_back(std::move(c));
  return int(materials_.size()) - 1;
}

int Scene::add_group(const std::string& name) {
  ++revision_;  // any change invalidates the compiled-scene cache
  groups_.push_back(Group{name, {}});
  return int(groups_.size()) - 1;
}

int Scene::add_instance(const std::string& name, int group, const double xf[3][4]) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("instance", name);
  if (group <= 0 || group >= int(groups_.size()))
    fail(obj, "group", "must name a prototype group created with add_group, got " + std::to_string(group));
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(xf[r][c])) fail(obj, "transform", "must be finite");
  if (!make_transform(xf, &t)) fail(obj, "transform", "is singular (not invertible)");
  instances_.push_back(Instance{name, group, t});
  return int(instances_.size()) - 1;
}

int Scene::add_mesh(int group, MeshDesc m) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("mesh", m.name);
  check_group(group, obj);
  check_material(m.material, obj);
  if (m.positions.empty() || m.positions.size() % 3) fail(obj, "positions", "must be an (n, 3) array with n > 0");
  const size_t nv = m.positions.size() / 3;
  for (size_t i = 0; i < m.positions.size(); ++i)
    if (!std::isfinite(m.positions[i]))
      fail(obj, "positions", "vertex " + std::to_string(i / 3) + " is not finite");
  if (m.face_size != 3 && m.face_size != 4) fail(obj, "indices", "faces must have 3 or 4 vertices");
  if (m.indices.empty() || m.indices.size() % size_t(m.face_size))
    fail(obj, "indices", "must be an (m, 3) or (m, 4) array with m > 0");
  for (size_t i = 0; i < m.indices.size(); ++i)
    if (m.indices[i] >= nv)
      fail(obj, "indices", "index " + std::to_string(m.indices[i]) + " at face " + std::to_string(i / size_t(m.face_size)) +
                               " is out of range (the mesh has " + std::to_string(nv) + " vertices)");
  if (!m.normals.empty()) {
    if (m.normals.size() != m.positions.size()) fail(obj, "normals", "must have one normal per vertex");
    for (float v : m.normals)
      if (!std::isfinite(v)) fail(obj, "normals", "must be finite");
  }
  for (const auto& [name, values] : m.attributes) {
    if (values.size() != nv) fail(obj, "attributes", "'" + name + "' must have one value per vertex");
    for (float v : values)
      if (!std::isfinite(v)) fail(obj, "attributes", "'" + name + "' must be finite");
  }
  if (!m.uvs.empty()) {
    if (m.uvs.size() != 2 * nv) fail(obj, "uvs", "must have one (u, v) pair per vertex");
    for (float v : m.uvs)
      if (!std::isfinite(v)) fail(obj, "uvs", "must be finite");
  }
  if (m.face_size == 4) {  // split each quad (a b c d) into (a b c) and (a c d)
    std::vector<uint32_t> tri;
    tri.reserve(m.indices.size() / 4 * 6);
    for (size_t f = 0; f < m.indices.size(); f += 4) {
      const uint32_t* q = &m.indices[f];
      tri.insert(tri.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
    }
    m.indices = std::move(tri);
    m.face_size = 3;
  }
  if (m.emissive) {
    check_emission(obj, m.emission);
    double area = 0;
    for (size_t f = 0; f < m.indices.size(); f += 3) {
      auto P = [&](uint32_t i) { return Point3{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]}; };
      area += double(triangle_area(P(m.indices[f]), P(m.indices[f + 1]), P(m.indices[f + 2])));
    }
    if (!(area > 0)) fail(obj, "emission", "an emitter must have non-zero area");
  }
  Shape s;
  s.type = ShapeType::Mesh;
  s.name = m.name;
  s.material = m.material;
  s.emissive = m.emissive;
  s.emission = m.emission;
  s.mesh = std::move(m);
  groups_[size_t(group)].shapes.push_back(std::move(s));
  return int(groups_[size_t(group)].shapes.size()) - 1;
}

int Scene::add_sphere(int group, const SphereDesc& d) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("sphere", d.name);
  check_group(group, obj);
  check_material(d.material, obj);
  check_finite(obj, "center", d.center);
  check_finite(obj, "radius", d.radius);
  if (!(d.radius > 0)) fail(obj, "radius", "must be > 0, got " + std::to_string(d.radius));
  if (d.emissive) check_emission(obj, d.emission);
  Shape s;
  s.type = ShapeType::Sphere;
  s.name = d.name;
  s.sphere = d;
  s.material = d.material;
  s.emissive = d.emissive;
  s.emission = d.emission;
  groups_[size_t(group)].shapes.push_back(std::move(s));
  return int(groups_[size_t(group)].shapes.size()) - 1;
}

int Scene::add_disk(int group, const DiskDesc& d) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("disk", d.name);
  check_group(group, obj);
  check_material(d.material, obj);
  check_finite(obj, "center", d.center);
  check_finite(obj, "normal", d.normal);
  check_finite(obj, "radius", d.radius);
  if (!(d.radius > 0)) fail(obj, "radius", "must be > 0, got " + std::to_string(d.radius));
  if (!(length(d.normal) > 0)) fail(obj, "normal", "must be non-zero");
  if (d.emissive) check_emission(obj, d.emission);
  Shape s;
  s.type = ShapeType::Disk;
  s.name = d.name;
  s.disk = d;
  s.disk.normal = normalize(d.normal);
  s.material = d.material;
  s.emissive = d.emissive;
  s.emission = d.emission;
  groups_[size_t(group)].shapes.push_back(std::move(s));
  return int(groups_[size_t(group)].shapes.size()) - 1;
}

int Scene::add_light(const LightDesc& l) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = quoted("light", l.name);
  check_emission(obj, l.emission);
  check_finite(obj, "position", l.position);
  check_finite(obj, "direction", l.direction);
  switch (l.type) {
    case LightType::Spot:
      check_range(obj, "cone_angle", l.cone_angle, 0.01f, 179);
      check_range(obj, "cone_softness", l.cone_softness, 0, l.cone_angle);
      [[fallthrough]];
    case LightType::Distant:
      if (!(length(l.direction) > 0)) fail(obj, "direction", "must be non-zero");
      if (l.type == LightType::Distant) check_range(obj, "angle", l.angle, 0, 90);
      break;
    case LightType::EnvMap:
      if (l.width <= 0 || l.height <= 0 || l.image.size() != size_t(l.width) * size_t(l.height) * 3)
        fail(obj, "image", "must be a (height, width, 3) RGB array");
      for (float v : l.image)
        if (!std::isfinite(v) || v < 0) fail(obj, "image", "texels must be finite and >= 0");
      break;
    default: break;
  }
  lights_.push_back(l);
  if (l.type == LightType::Spot || l.type == LightType::Distant) lights_.back().direction = normalize(l.direction);
  return int(lights_.size()) - 1;
}

void Scene::set_camera(const CameraDesc& c) {
  ++revision_;  // any change invalidates the compiled-scene cache
  std::string obj = "camera";
  check_finite(obj, "eye", c.eye);
  check_finite(obj, "target", c.target);
  check_finite(obj, "up", c.up);
  if (!(length(c.target - c.eye) > 0)) fail(obj, "target", "must differ from eye");
  if (!(length(cross(c.target - c.eye, c.up)) > 0)) fail(obj, "up", "must not be parallel to the view direction");
  if (c.type == CameraType::Perspective) check_range(obj, "fov", c.fov, 0.01f, 179);
  else if (!(c.ortho_width > 0)) fail(obj, "width", "must be > 0");
  if (c.fov_axis != 'x' && c.fov_axis != 'y') fail(obj, "fov_axis", "must be 'x' or 'y'");
  if (!(c.aperture_radius >= 0)) fail(obj, "aperture_radius", "must be >= 0");
  if (!(c.focus_distance >= 0)) fail(obj, "focus_distance", "must be >= 0");
  camera_ = c;
  has_camera_ = true;
}

}  // namespace kauri
