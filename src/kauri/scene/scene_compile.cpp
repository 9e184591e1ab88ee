// Scene::compile: description → render-ready arrays, lights and Embree scenes.
#include <cmath>
#include <algorithm>
#include <deque>
#include <map>
#include <stdexcept>

#include "kauri/scene/scene.h"
#include "kauri/light/env_importance.h"

namespace kauri {

namespace {

Float luminance(const Spectrum& s) { return fmax_(spectrum_to_y(s), 0); }

Spectrum emission_of(const EmissionDesc& e, const RGBColorSpace& cs) {
  if (e.temperature > 0) {
    Spectrum bb = Spectrum::make_blackbody(e.temperature, 1);
    Float y = spectrum_to_y(bb);
    return Spectrum::make_blackbody(e.temperature, y > 0 ? e.intensity / y : 0);
  }
  Spectrum s = rgb_illuminant(cs, e.rgb);
  if (s.type == SpectrumType::RGBIlluminant || s.type == SpectrumType::RGBUnbounded) s.rgb.scale *= e.intensity;
  else if (s.type == SpectrumType::Constant) s.constant *= e.intensity;
  return s;
}

bool same_dense(const DenselySampled& a, const DenselySampled& b) {
  return a.values == b.values && a.lambda_min == b.lambda_min && a.step == b.step && a.count == b.count;
}

/// Whether two spectra are the same function (field by field: equal fields, equal values;
/// unequal fields may still be one spectrum, which only costs EmissionCache a hit).
bool same_spectrum(const Spectrum& a, const Spectrum& b) {
  if (a.type != b.type) return false;
  switch (a.type) {
    case SpectrumType::Constant: return a.constant == b.constant;
    case SpectrumType::DenselySampled: return same_dense(a.dense, b.dense);
    case SpectrumType::RGBAlbedo:
    case SpectrumType::RGBUnbounded:
    case SpectrumType::RGBIlluminant:
      return a.rgb.poly.c0 == b.rgb.poly.c0 && a.rgb.poly.c1 == b.rgb.poly.c1 && a.rgb.poly.c2 == b.rgb.poly.c2 &&
             a.rgb.scale == b.rgb.scale && (a.type != SpectrumType::RGBIlluminant || same_dense(a.rgb.illuminant, b.rgb.illuminant));
    case SpectrumType::Blackbody:
      return a.blackbody.temperature == b.blackbody.temperature && a.blackbody.scale == b.blackbody.scale;
  }
  return false;
}

/// Gives lights with the same emission spectrum the same Light::emission_id (the
/// path's EmissionCache then evaluates it once) and their colour Le_rgb in the output
/// space (computed once per distinct spectrum); material lights and environment images,
/// whose radiance is not `Le`, get neither. The search for an equal spectrum stops at 256
/// distinct ones (beyond them each light gets an id and an integral of its own): the
/// compile stays linear in the number of lights, and a path meets few colours in a row.
/// An upper bound on how far a transform's linear part stretches a unit vector: its
/// Frobenius norm (≥ the largest singular value); 1 without a transform. Bounds a
/// scaled sphere or disk for light antialiasing's screen mask (render/light_aa.h).
Float frobenius_scale(const Transform* xf) {
  if (!xf) return 1;
  return std::sqrt(length_squared(xf->vector({1, 0, 0})) + length_squared(xf->vector({0, 1, 0})) +
                   length_squared(xf->vector({0, 0, 1})));
}

void assign_emission_ids(std::vector<Light>& lights, const RGBColorSpace& cs) {
  constexpr size_t kMaxSearched = 256;
  std::vector<const Spectrum*> distinct;  // distinct[k] has emission id k
  std::vector<Vec3> distinct_rgb;
  std::vector<char> rgb_known;
  int next_id = 0;
  for (Light& l : lights) {
    l.emission_id = -1;
    if (l.material >= 0 || l.type == LightType::EnvMap) continue;
    // Point and spot lights are never met by a ray: no colour to integrate for them.
    const bool can_be_seen = l.type != LightType::Point && l.type != LightType::Spot;
    size_t k = 0;
    while (k < distinct.size() && !same_spectrum(*distinct[k], l.Le)) ++k;
    if (k < distinct.size()) {
      l.emission_id = int(k);
      if (can_be_seen && !rgb_known[k]) {
        distinct_rgb[k] = cs.to_rgb(spectrum_to_xyz_expected(l.Le));
        rgb_known[k] = 1;
      }
      if (can_be_seen) l.Le_rgb = distinct_rgb[k];
      continue;
    }
    if (can_be_seen) l.Le_rgb = cs.to_rgb(spectrum_to_xyz_expected(l.Le));
    if (distinct.size() < kMaxSearched) {
      distinct.push_back(&l.Le);
      distinct_rgb.push_back(l.Le_rgb);
      rgb_known.push_back(char(can_be_seen));
    }
    l.emission_id = next_id++;
  }
}

}  // namespace

LobeParams lobe_params(const LobeDesc& m, const RGBColorSpace& cs, std::deque<std::vector<float>>* tables) {
  LobeParams p;
  p.type = m.type;
  if (m.emission) {
    p.emission = true;
    p.two_sided = m.two_sided;
    p.focus = m.focus;
    if (!m.spectrum_nm.empty()) {
      // Tabulated emission, resampled to 1 nm over 360..830 nm (linear, 0 outside).
      std::vector<float> t(471);
      for (int i = 0; i < 471; ++i) {
        float lam = 360.0f + float(i);
        const auto& x = m.spectrum_nm;
        const auto& y = m.spectrum_values;
        float v = 0;
        if (lam >= x.front() && lam <= x.back()) {
          size_t j = size_t(std::upper_bound(x.begin(), x.end(), lam) - x.begin());
          j = std::min(std::max<size_t>(j, 1), x.size() - 1);
          float f = (lam - x[j - 1]) / (x[j] - x[j - 1]);
          v = y[j - 1] + f * (y[j] - y[j - 1]);
        }
        t[size_t(i)] = v * m.intensity;
      }
      tables->push_back(std::move(t));
      p.a = Spectrum::make_dense(DenselySampled{tables->back().data(), 360, 1, 471});
    } else {
      p.a = emission_of(EmissionDesc{m.emission_rgb, m.temperature, m.intensity, m.two_sided}, cs);
    }
    return p;
  }
  // Anisotropy stretches α along the tangent and shrinks it along the bitangent
  // (the usual artist mapping; α = roughness²).
  Float alpha = GGXDistribution::roughness_to_alpha(m.roughness);
  Float aspect = std::sqrt(1 - 0.9f * std::fabs(m.anisotropy));
  p.alpha_x = m.anisotropy >= 0 ? alpha / aspect : alpha * aspect;
  p.alpha_y = m.anisotropy >= 0 ? alpha * aspect : alpha / aspect;
  p.a_texture = int16_t(m.albedo_texture);
  switch (m.type) {
    case LobeType::Lambert:
    case LobeType::DiffuseTransmission: p.a = rgb_albedo(cs, m.albedo); break;
    case LobeType::Sheen:
    case LobeType::OrenNayar:
      p.a = rgb_albedo(cs, m.albedo);
      p.alpha_x = p.alpha_y = m.roughness;  // these lobes take their roughness directly
      break;
    case LobeType::SmoothDielectric:
    case LobeType::RoughDielectric:
    case LobeType::ThinDielectric:
      p.ior = CauchyIOR::from_abbe(m.ior, m.abbe);
      p.compensate = m.compensate;
      break;
    case LobeType::GGXConductor: {
      p.microfacet = m.microfacet;
      p.compensate = m.compensate;
      if (m.artist) {
        p.artist = true;
        p.a = rgb_albedo(cs, m.reflectivity);
        p.b = rgb_albedo(cs, m.edge_tint);
      } else if (!m.metal.empty()) {
        const tables::MetalIOR* metal = tables::find_metal(m.metal);
        p.a = Spectrum::make_dense(metal_eta(*metal));
        p.b = Spectrum::make_dense(metal_k(*metal));
      } else {
        p.a = rgb_unbounded(cs, m.eta_rgb);
        p.b = rgb_unbounded(cs, m.k_rgb);
      }
      break;
    }
  }
  return p;
}

static bool layout_has_coat(const LayerLayout& layout) {
  for (const LayerNode& n : layout.nodes)
    if (n.op == LayerOp::Coat) return true;
  return false;
}

StandaloneMaterial::StandaloneMaterial(const MaterialDesc& m, ColorSpaceId cs_id) {
  CompiledMaterial c = compile_material(m);
  layout = c.layout;
  const RGBColorSpace& cs = color_space(cs_id);
  for (const LobeDesc& l : c.lobes) {
    if (l.albedo_texture >= 0)
      throw std::invalid_argument("material '" + m.name + "': a standalone material has no textures");
    lobes.push_back(lobe_params(l, cs, &tables));
    view.emissive = view.emissive || l.emission;
  }
  for (const ScalarInputDesc& w : c.node_weights) {
    if (!w.attribute.empty())
      throw std::invalid_argument("material '" + m.name + "': a standalone material has no vertex attributes");
    weights.push_back(ScalarInput{-1, w.value});
  }
  view.front = {layout.nodes.data(), layout.front_children.data(), int(layout.nodes.size())};
  view.has_coat = layout_has_coat(layout);
  view.back = {layout.nodes.data(), layout.back_children.data(), int(layout.nodes.size())};
  view.n_lobes = int(lobes.size());
  view.ior_accumulation = m.ior_accumulation;
  view.roughness_accumulation = m.roughness_accumulation;
}

void CompiledScene::add_shape_lights(const Scene::Shape& s, const Transform* xf, const RGBColorSpace& cs) {
  Light base;
  base.Le = emission_of(s.emission, cs);
  base.two_sided = s.emission.two_sided;
  auto P = [&](Point3 p) { return xf ? xf->point(p) : p; };
  switch (s.type) {
    case ShapeType::Mesh: {
      const MeshDesc& m = s.mesh;
      for (size_t f = 0; f < m.indices.size(); f += 3) {
        auto V = [&](uint32_t i) { return P(Point3{m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]}); };
        Light l = base;
        l.type = LightType::Triangle;
        l.p0 = V(m.indices[f]);
        l.p1 = V(m.indices[f + 1]);
        l.p2 = V(m.indices[f + 2]);
        Vec3 c = cross(l.p1 - l.p0, l.p2 - l.p0);
        l.area = length(c) / 2;
        // Degenerate triangles keep their slot (light = first + primID) but get zero power.
        l.n = l.area > 0 ? normalize(c) : Vec3{0, 0, 1};
        lights_.push_back(l);
      }
      break;
    }
    case ShapeType::Sphere: {
      Light l = base;
      l.type = LightType::Sphere;
      l.p0 = P(s.sphere.center);
      Float scale = xf ? std::cbrt(std::fabs(length(xf->vector({1, 0, 0})) * length(xf->vector({0, 1, 0})) *
                                             length(xf->vector({0, 0, 1}))))
                       : Float(1);
      l.radius = s.sphere.radius * scale;
      l.bound_radius = s.sphere.radius * frobenius_scale(xf);
      l.area = 4 * kPi * l.radius * l.radius;
      lights_.push_back(l);
      break;
    }
    case ShapeType::Disk: {
      Light l = base;
      l.type = LightType::Disk;
      l.p0 = P(s.disk.center);
      l.n = xf ? normalize(xf->normal(s.disk.normal)) : s.disk.normal;
      Float scale = xf ? length(xf->vector(Frame::from_z(s.disk.normal).x)) : Float(1);
      l.radius = s.disk.radius * scale;
      l.bound_radius = s.disk.radius * frobenius_scale(xf);
      l.area = kPi * l.radius * l.radius;
      l.frame = Frame::from_z(l.n);
      lights_.push_back(l);
      break;
    }
  }
}

void CompiledScene::build_lights(const Scene& scene, const RGBColorSpace& cs) {
  for (const LightDesc& d : scene.lights_) {
    Light l;
    l.type = d.type;
    l.Le = emission_of(d.emission, cs);
    l.p0 = d.position;
    l.n = d.direction;
    switch (d.type) {
      case LightType::Spot: {
        Float outer = d.cone_angle * kPi / 180, inner = (d.cone_angle - d.cone_softness) * kPi / 180;
        l.cos_outer = std::cos(outer);
        l.cos_inner = std::cos(fmax_(inner, 0));
        l.frame = Frame::from_z(l.n);
        break;
      }
      case LightType::Distant:
        l.cos_max = d.angle > 0 ? std::cos(d.angle * kPi / 360) : Float(1);
        l.frame = Frame::from_z(-l.n);
        break;
      case LightType::EnvMap: {
        Transform rot;
        if (!make_transform(d.rotation, &rot)) throw std::invalid_argument("light '" + d.name + "': parameter 'rotation': is singular");
        l.frame.x = normalize(rot.vector({1, 0, 0}));
        l.frame.y = normalize(rot.vector({0, 1, 0}));
        l.frame.z = normalize(rot.vector({0, 0, 1}));
        const int w = d.width, h = d.height;
        std::vector<EnvTexel> texels(size_t(w) * size_t(h));
        std::vector<Vec3> texel_rgb(texels.size());
        std::vector<Float> lum(texels.size()), weight(texels.size());
        for (size_t i = 0; i < texels.size(); ++i) {
          Vec3 rgb{d.image[3 * i], d.image[3 * i + 1], d.image[3 * i + 2]};
          Spectrum s = emission_of(EmissionDesc{rgb, 0, d.emission.intensity, false}, cs);
          EnvTexel t{0, 0, 0, 0};
          if (s.type == SpectrumType::RGBIlluminant) t = {s.rgb.scale, s.rgb.poly.c0, s.rgb.poly.c1, s.rgb.poly.c2};
          texels[i] = t;
          // The colour the spectrum is fitted to: a camera ray adds it as is. Integrating
          // each texel's spectrum (as Le_rgb is) would cost ~1400 sigmoids a texel, minutes
          // for a 16k map; the fit's own error is what separates the two (≤ 0.04% over
          // linear-sRGB colours; more for colours beyond the spectral locus, which no
          // spectrum of the fit has: tests/cpp/test_lights.cpp).
          texel_rgb[i] = rgb * d.emission.intensity;
          lum[i] = fmax_(cs.to_xyz(rgb).y, 0);
        }
        // Importance ∝ luminance × sinθ, dilated to cover the bilinear lookup.
        weight = env_importance(lum, w, h);
        env_distributions_.push_back(std::make_unique<Distribution2DStorage>(weight, w, h));
        l.distribution = env_distributions_.back()->view();
        bytes_ += env_distributions_.back()->bytes();
        env_distributions_.push_back(
            std::make_unique<Distribution2DStorage>(env_importance_compensated(lum, w, h), w, h));
        l.compensated = env_distributions_.back()->view();
        l.width = w;
        l.height = h;
        l.illuminant = *cs.illuminant;
        env_texels_.push_back(std::move(texels));
        l.texels = env_texels_.back().data();
        env_texel_rgb_.push_back(std::move(texel_rgb));
        l.texel_rgb = env_texel_rgb_.back().data();
        bytes_ += env_texels_.back().size() * (sizeof(EnvTexel) + sizeof(Vec3)) + env_distributions_.back()->bytes();
        break;
      }
      default: break;
    }
    lights_.push_back(l);
  }
}

std::shared_ptr<const CompiledScene> Scene::compiled(int width, int height, bool* reused) const {
  std::lock_guard<std::mutex> lock(cache_.mutex);
  const bool stale = !cache_.scene || cache_.revision != revision_ || cache_.width != width || cache_.height != height;
  if (reused) *reused = !stale;
  if (stale) {
    cache_.scene.reset();  // free the old one before building the next
    cache_.scene = compile(width, height);
    cache_.revision = revision_;
    cache_.width = width;
    cache_.height = height;
  }
  return cache_.scene;
}

std::unique_ptr<CompiledScene> Scene::compile(int width, int height) const {
  if (width <= 0 || height <= 0) throw std::invalid_argument("render: parameter 'resolution': must be positive");
  if (!has_camera_) throw std::invalid_argument("scene: no camera; call set_camera() first");
  auto cs_ptr = &color_space(color_space_);
  const RGBColorSpace& cs = *cs_ptr;
  auto out = std::unique_ptr<CompiledScene>(new CompiledScene());
  CompiledScene& c = *out;

  // Vertex attributes that material inputs read get scene-wide slots.
  std::map<std::string, int> attribute_slot;
  for (const CompiledMaterial& cm : compiled_materials_)
    for (const ScalarInputDesc& w : cm.node_weights)
      if (!w.attribute.empty() && !attribute_slot.count(w.attribute)) {
        if (int(attribute_slot.size()) == kMaxVertexAttributes)
          throw std::invalid_argument("scene: materials read more than " + std::to_string(kMaxVertexAttributes) +
                                      " distinct vertex attributes");
        int slot = int(attribute_slot.size());
        attribute_slot[w.attribute] = slot;
      }

  // Materials: lobe parameters, node weights and layer programs; identical layouts once.
  std::map<std::string, const LayerLayout*> layout_by_key;
  for (size_t mi = 0; mi < compiled_materials_.size(); ++mi) {
    const CompiledMaterial& cm = compiled_materials_[mi];
    const MaterialDesc& md = materials_[mi];
    const std::string key = cm.layout.key();
    const LayerLayout* layout;
    if (auto it = layout_by_key.find(key); it != layout_by_key.end()) {
      layout = it->second;
    } else {
      c.layouts_.push_back(std::make_unique<LayerLayout>(cm.layout));
      layout = c.layouts_.back().get();
      layout_by_key[key] = layout;
      c.bytes_ += layout->nodes.size() * sizeof(LayerNode) + 2 * layout->front_children.size() * sizeof(uint16_t);
    }
    MaterialView v;
    v.front = {layout->nodes.data(), layout->front_children.data(), int(layout->nodes.size())};
    v.has_coat = layout_has_coat(*layout);
    v.back = {layout->nodes.data(), layout->back_children.data(), int(layout->nodes.size())};
    v.first_lobe = int(c.lobes_.size());
    v.n_lobes = int(cm.lobes.size());
    v.first_weight = int(c.node_weights_.size());
    v.ior_accumulation = md.ior_accumulation;
    v.roughness_accumulation = md.roughness_accumulation;
    v.reads_uv = false;
    for (const LobeDesc& l : cm.lobes) {
      c.lobes_.push_back(lobe_params(l, cs, &c.emission_tables_));
      v.emissive = v.emissive || l.emission;
      v.reads_uv = v.reads_uv || l.albedo_texture >= 0;
    }
    for (const ScalarInputDesc& w : cm.node_weights)
      c.node_weights_.push_back(ScalarInput{int16_t(w.attribute.empty() ? -1 : attribute_slot[w.attribute]), w.value});
    c.materials_.push_back(v);
  }
  auto check_attributes = [&](const Shape& s) {
    if (s.material < 0) return;
    for (const ScalarInputDesc& w : compiled_materials_[size_t(s.material)].node_weights) {
      if (w.attribute.empty()) continue;
      if (s.type != ShapeType::Mesh || !s.mesh.attributes.count(w.attribute))
        throw std::invalid_argument("shape '" + s.name + "': its material '" + materials_[size_t(s.material)].name +
                                    "' reads vertex attribute '" + w.attribute + "', which the shape does not define");
    }
  };

  // Geometry, group by group.
  c.shape_views_.resize(groups_.size());
  for (size_t g = 0; g < groups_.size(); ++g) {
    for (const Shape& s : groups_[g].shapes) {
      check_attributes(s);
      ShapeView v;
      v.type = s.type;
      v.material = s.material;
      if (s.type == ShapeType::Mesh) {
        auto arrays = std::make_unique<CompiledScene::MeshArrays>();
        const MeshDesc& m = s.mesh;
        size_t nv = m.positions.size() / 3;
        arrays->p.resize(nv + 1);
        for (size_t i = 0; i < nv; ++i) arrays->p[i] = {m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]};
        if (!m.normals.empty()) {
          arrays->n.resize(nv);
          for (size_t i = 0; i < nv; ++i) arrays->n[i] = {m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]};
        }
        if (!m.uvs.empty()) {
          arrays->uv.resize(nv);
          for (size_t i = 0; i < nv; ++i) arrays->uv[i] = {m.uvs[2 * i], m.uvs[2 * i + 1]};
        }
        arrays->index = m.indices;
        for (const auto& [name, slot] : attribute_slot) {
          auto it = m.attributes.find(name);
          if (it == m.attributes.end()) continue;
          c.attribute_arrays_.push_back(it->second);
          arrays->attr[slot] = c.attribute_arrays_.back().data();
          c.bytes_ += it->second.size() * sizeof(float);
        }
        v.mesh = {arrays->p.data(), arrays->n.empty() ? nullptr : arrays->n.data(),
                  arrays->uv.empty() ? nullptr : arrays->uv.data(), arrays->index.data(),
                  uint32_t(m.indices.size() / 3), uint32_t(nv), {}};
        for (int a = 0; a < kMaxVertexAttributes; ++a) v.mesh.attr[a] = arrays->attr[a];
        c.bytes_ += arrays->p.size() * sizeof(Point3) + arrays->n.size() * sizeof(Normal3) +
                    arrays->uv.size() * sizeof(Vec2) + arrays->index.size() * sizeof(uint32_t);
        c.meshes_.push_back(std::move(arrays));
      } else if (s.type == ShapeType::Sphere) {
        v.sphere = {s.sphere.center, s.sphere.radius};
      } else {
        v.disk = {s.disk.center, s.disk.normal, s.disk.radius};
      }
      c.shape_views_[g].push_back(v);
    }
  }

  // Instances (instance 0 = the root group) and the emitters each of them places.
  std::vector<int> inst_groups;
  std::vector<Transform> inst_xf;
  c.instance_views_.push_back(InstanceView{0, 0, true, Transform{}});
  for (const Instance& inst : instances_) {
    inst_groups.push_back(inst.group);
    inst_xf.push_back(inst.xf);
  }
  int slot = 0;
  for (size_t k = 0; k < inst_groups.size() + 1; ++k) {
    int g = k == 0 ? 0 : inst_groups[k - 1];
    if (k > 0) c.instance_views_.push_back(InstanceView{g, slot, false, inst_xf[k - 1]});
    const Transform* xf = k == 0 ? nullptr : &inst_xf[k - 1];
    for (const Shape& s : groups_[size_t(g)].shapes) {
      const bool material_emits = s.material >= 0 && c.materials_[size_t(s.material)].emissive;
      if (s.emissive && material_emits)
        throw std::invalid_argument("shape '" + s.name + "': has both an emission parameter and an emissive material '" +
                                    materials_[size_t(s.material)].name + "'; use one");
      if (s.emissive || material_emits) {
        c.emitter_first_light_.push_back(int(c.lights_.size()));
        size_t first = c.lights_.size();
        c.add_shape_lights(s, xf, cs);
        if (material_emits) {
          // Light selection needs a power estimate: the sum of the EDFs' radiances.
          const MaterialView& mv = c.materials_[size_t(s.material)];
          Spectrum est = Spectrum::make_constant(0);
          Float y_total = 0;
          for (int k = 0; k < mv.n_lobes; ++k) {
            const LobeParams& lp = c.lobes_[size_t(mv.first_lobe + k)];
            if (lp.emission) y_total += luminance(lp.a);
          }
          est = Spectrum::make_constant(y_total);
          bool two_sided = false;
          for (int k = 0; k < mv.n_lobes; ++k) two_sided = two_sided || c.lobes_[size_t(mv.first_lobe + k)].two_sided;
          for (size_t li = first; li < c.lights_.size(); ++li) {
            c.lights_[li].material = s.material;
            c.lights_[li].Le = est;
            c.lights_[li].two_sided = two_sided;
          }
        }
      } else {
        c.emitter_first_light_.push_back(-1);
      }
    }
    slot += int(groups_[size_t(g)].shapes.size());
  }

  c.accel_.build(c.shape_views_, inst_groups, inst_xf);
  Point3 center;
  Float radius;
  c.accel_.bounds().bounding_sphere(&center, &radius);
  if (!(radius > 0)) radius = 1;

  c.build_lights(*this, cs);
  assign_emission_ids(c.lights_, cs);
  std::vector<Float> power(c.lights_.size());
  for (size_t i = 0; i < c.lights_.size(); ++i) {
    Light& l = c.lights_[i];
    l.scene_center = center;
    l.scene_radius = radius;
    if (l.is_infinite()) c.infinite_lights_.push_back(int(i));
    Float y = luminance(l.Le);
    switch (l.type) {
      case LightType::Point: power[i] = 4 * kPi * y; break;
      case LightType::Spot: power[i] = 2 * kPi * (1 - (l.cos_inner + l.cos_outer) / 2) * y; break;
      case LightType::Distant: power[i] = kPi * radius * radius * y; break;
      case LightType::Triangle:
      case LightType::Sphere:
      case LightType::Disk: power[i] = y * l.area * kPi * (l.two_sided ? 2 : 1); break;
      case LightType::EnvConstant: power[i] = 4 * kPi * kPi * radius * radius * y; break;
      case LightType::EnvMap: {
        // Mean radiance over the sphere: (1/4π)∫L dω = (π/2)∫∫ L sinθ du dv, the
        // integral of the sampling weights times π/2 (intensity scales it via y).
        power[i] = 4 * kPi * kPi * radius * radius * fmax_(l.distribution.marginal.integral, 0) * (kPi / 2) * y;
        break;
      }
    }
    if (!std::isfinite(power[i]) || power[i] < 0) power[i] = 0;
  }
  // Light selection: finite lights in proportion to their power; each infinite light
  // (environment, distant) gets the same share as all finite lights together (as
  // pbrt-v4's BVH light sampler does). An environment's "power" grows with the scene's
  // bounding sphere and would otherwise starve small bright lights of samples. A light
  // that NEE does not sample (a constant environment, whose MIS-compensated density is
  // empty: BSDF sampling alone covers it) gets no share, so no NEE sample is spent on it.
  if (!c.lights_.empty()) {
    double finite_total = 0;
    for (size_t i = 0; i < power.size(); ++i)
      if (!c.lights_[i].is_infinite()) finite_total += double(power[i]);
    for (size_t i = 0; i < power.size(); ++i) {
      if (!has_light_density(c.lights_[i], kNextEventDensity)) power[i] = 0;
      if (c.lights_[i].is_infinite() && power[i] > 0) power[i] = finite_total > 0 ? Float(finite_total) : Float(1);
    }
    Float total = 0;
    for (Float p : power) total += p;
    if (total > 0) c.light_distribution_ = Distribution1DStorage(power);
    // The light tree chooses among the finite lights in place of their power share.
    double finite = 0;
    std::vector<Float> infinite_power;
    for (size_t i = 0; i < power.size(); ++i) {
      if (c.lights_[i].is_infinite()) infinite_power.push_back(power[i]);
      else finite += double(power[i]);
    }
    if (total > 0) {
      c.finite_light_share_ = Float(finite / double(total));
      c.light_tree_ = build_light_tree(c.lights_, power);
      double inf_total = 0;
      for (Float p : infinite_power) inf_total += double(p);
      if (inf_total > 0) c.infinite_distribution_ = Distribution1DStorage(infinite_power);
    }
  }

  // Camera.
  Camera cam;
  cam.type = camera_.type;
  cam.width = width;
  cam.height = height;
  cam.camera_to_world = look_at(camera_.eye, camera_.target, camera_.up);
  Float aspect = Float(width) / Float(height);
  if (camera_.type == CameraType::Perspective) {
    Float t = std::tan(camera_.fov * kPi / 360);
    cam.tan_half_x = camera_.fov_axis == 'x' ? t : t * aspect;
    cam.tan_half_y = camera_.fov_axis == 'x' ? t / aspect : t;
  } else {
    cam.half_w = camera_.ortho_width / 2;
    cam.half_h = cam.half_w / aspect;
  }
  cam.lens_radius = camera_.aperture_radius;
  cam.focus_distance = camera_.focus_distance > 0 ? camera_.focus_distance : distance(camera_.eye, camera_.target);

  // Views.
  for (const auto& sv : c.shape_views_) c.group_views_.push_back(GroupView{sv.data(), int(sv.size())});
  SceneView& v = c.view_;
  v.groups = c.group_views_.data();
  v.instances = c.instance_views_.data();
  v.n_instances = int(c.instance_views_.size());
  v.n_root_shapes = int(c.shape_views_[0].size());
  v.emitter_first_light = c.emitter_first_light_.data();
  v.materials = c.materials_.data();
  v.lobes = c.lobes_.data();
  v.node_weights = c.node_weights_.data();
  for (const TextureDesc& t : textures_) {
    c.texture_data_.push_back(t.texels);
    c.texture_coeffs_.push_back(texel_coefficients(t.texels->data(), t.width, t.height, *cs.table));
    c.textures_.push_back(
        ImageTexture{t.texels->data(), t.width, t.height, t.wrap, cs.table, c.texture_coeffs_.back().data()});
    c.bytes_ += t.texels->size() * sizeof(float) + c.texture_coeffs_.back().size() * sizeof(SigmoidPolynomial);
  }
  v.textures = c.textures_.data();
  v.lights = c.lights_.data();
  v.n_lights = c.light_distribution_.integral() > 0 ? int(c.lights_.size()) : 0;
  v.light_distribution = c.light_distribution_.view();
  v.infinite_lights = c.infinite_lights_.data();
  v.n_infinite_lights = int(c.infinite_lights_.size());
  v.light_tree = c.light_tree_.view();
  v.infinite_distribution = c.infinite_distribution_.view();
  v.finite_light_share = c.finite_light_share_;
  v.camera = cam;
  v.camera_forward = cam.forward();
  v.illuminant = Spectrum::make_dense(*cs.illuminant);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) v.xyz_to_rgb[r][k] = cs.xyz_to_rgb[r][k];
  v.wavelengths = cs.wavelengths;
  c.bytes_ += c.lights_.size() * sizeof(Light) + c.lobes_.size() * sizeof(LobeParams) +
              c.emitter_first_light_.size() * sizeof(int) + c.light_distribution_.bytes() +
              c.light_tree_.bytes() + c.infinite_distribution_.bytes();
  (void)cs_ptr;
  return out;
}

}  // namespace kauri
