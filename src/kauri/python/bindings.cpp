// nanobind module kauri._core: the host scene API, render(), and image output.
// The friendly, keyword-checked API lives in python/kauri/; this layer is thin.
#include <chrono>
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "kauri/film/image_io.h"
#include "kauri/integrator/path_lanes.h"
#include "kauri/layer/layer_compiler.h"
#include "kauri/render/renderer.h"
#include "kauri/render/ray_replay.h"
#include "kauri/scene/scene.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace kauri {
namespace {

using FloatArray = nb::ndarray<const float, nb::c_contig, nb::device::cpu>;
using IndexArray = nb::ndarray<const uint32_t, nb::c_contig, nb::device::cpu>;
using Vec3T = std::tuple<float, float, float>;

Vec3 v3(const Vec3T& t) { return {std::get<0>(t), std::get<1>(t), std::get<2>(t)}; }

std::vector<float> to_vector(const FloatArray& a) { return std::vector<float>(a.data(), a.data() + a.size()); }

EmissionDesc emission(Vec3T color, float intensity, float temperature, bool two_sided) {
  return EmissionDesc{v3(color), temperature, intensity, two_sided};
}

/// Fetches a scene's compiled form (reused while the scene is unchanged) and records in
/// a render's stats how long compiling took, or that it was reused.
struct CompileTimer {
  double seconds = 0;
  bool reused = false;
  std::shared_ptr<const CompiledScene> get(const Scene& scene, int width, int height) {
    auto t0 = std::chrono::steady_clock::now();
    auto c = scene.compiled(width, height, &reused);
    seconds = reused ? 0 : std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return c;
  }
  void record(RenderStats* stats) const {
    stats->compile_seconds = seconds;
    stats->scene_reused = reused;
  }
};

void read_matrix(const FloatArray& m, const std::string& what, double out[3][4]) {
  if (!((m.ndim() == 2 && (m.shape(0) == 3 || m.shape(0) == 4) && m.shape(1) == 4)))
    throw std::invalid_argument(what + ": parameter 'transform': must be a 3x4 or 4x4 matrix");
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[r][c] = m.data()[r * 4 + c];
}

ColorSpaceId parse_cs(const std::string& name) {
  ColorSpaceId id;
  if (!parse_color_space(name, &id))
    throw std::invalid_argument("parameter 'color_space': unknown colour space '" + name + "' (expected 'acescg' or 'srgb')");
  return id;
}

ScalarInputDesc weight_from_dict(const nb::dict& d) {
  ScalarInputDesc w;
  w.value = nb::cast<float>(d["weight"]);
  if (d.contains("weight_attribute")) w.attribute = nb::cast<std::string>(d["weight_attribute"]);
  return w;
}

LobeDesc lobe_from_dict(const nb::dict& d) {
  LobeDesc l;
  l.name = nb::cast<std::string>(d["name"]);
  std::string type = nb::cast<std::string>(d["type"]);
  if (type == "lambert") {
    l.type = LobeType::Lambert;
    l.albedo = v3(nb::cast<Vec3T>(d["albedo"]));
  } else if (type == "dielectric") {
    l.type = LobeType::SmoothDielectric;
    l.ior = nb::cast<float>(d["ior"]);
    l.abbe = nb::cast<float>(d["abbe"]);
  } else if (type == "conductor") {
    l.type = LobeType::GGXConductor;
    l.metal = nb::cast<std::string>(d["metal"]);
    l.eta_rgb = v3(nb::cast<Vec3T>(d["eta"]));
    l.k_rgb = v3(nb::cast<Vec3T>(d["k"]));
    l.roughness = nb::cast<float>(d["roughness"]);
    l.anisotropy = nb::cast<float>(d["anisotropy"]);
    std::string mf = nb::cast<std::string>(d["microfacet"]);
    if (mf == "beckmann") l.microfacet = MicrofacetType::Beckmann;
    else if (mf != "ggx") throw std::invalid_argument("lobe '" + l.name + "': unknown microfacet model '" + mf + "'");
    l.compensate = nb::cast<bool>(d["compensate"]);
    if (!d["reflectivity"].is_none()) {
      l.artist = true;
      l.reflectivity = v3(nb::cast<Vec3T>(d["reflectivity"]));
      l.edge_tint = v3(nb::cast<Vec3T>(d["edge_tint"]));
    }
  } else if (type == "rough_dielectric" || type == "thin_dielectric") {
    l.type = type == "thin_dielectric" ? LobeType::ThinDielectric : LobeType::RoughDielectric;
    l.ior = nb::cast<float>(d["ior"]);
    l.abbe = nb::cast<float>(d["abbe"]);
    if (type == "rough_dielectric") {
      l.roughness = nb::cast<float>(d["roughness"]);
      l.anisotropy = nb::cast<float>(d["anisotropy"]);
      l.compensate = nb::cast<bool>(d["compensate"]);
    }
  } else if (type == "diffuse_transmission") {
    l.type = LobeType::DiffuseTransmission;
    l.albedo = v3(nb::cast<Vec3T>(d["transmittance"]));
  } else if (type == "oren_nayar") {
    l.type = LobeType::OrenNayar;
    l.albedo = v3(nb::cast<Vec3T>(d["albedo"]));
    l.roughness = nb::cast<float>(d["roughness"]);
  } else if (type == "emission") {
    l.emission = true;
    l.emission_rgb = v3(nb::cast<Vec3T>(d["color"]));
    l.temperature = nb::cast<float>(d["temperature"]);
    l.intensity = nb::cast<float>(d["intensity"]);
    l.focus = nb::cast<float>(d["focus"]);
    l.two_sided = nb::cast<bool>(d["two_sided"]);
    if (!d["spectrum"].is_none()) {
      for (nb::handle pair : nb::cast<nb::list>(d["spectrum"])) {
        nb::tuple t = nb::cast<nb::tuple>(pair);
        l.spectrum_nm.push_back(nb::cast<float>(t[0]));
        l.spectrum_values.push_back(nb::cast<float>(t[1]));
      }
    }
  } else if (type == "sheen") {
    l.type = LobeType::Sheen;
    l.albedo = v3(nb::cast<Vec3T>(d["color"]));
    l.roughness = nb::cast<float>(d["roughness"]);
  } else {
    throw std::invalid_argument("lobe '" + l.name + "': unknown lobe type '" + type + "'");
  }
  if (d.contains("texture")) l.albedo_texture = nb::cast<int>(d["texture"]);
  l.weight = weight_from_dict(d);
  return l;
}

nb::ndarray<nb::numpy, float> to_numpy(const std::vector<float>& v, std::initializer_list<size_t> shape) {
  auto* copy = new std::vector<float>(v);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  return nb::ndarray<nb::numpy, float>(copy->data(), shape, owner);
}

struct PyRenderResult {
  RenderResult r;
  ColorSpaceId cs;
  uint64_t seed;
};

/// An AOV as an (h, w, channels) array ((h, w) for one channel), or None if not rendered.
nb::object aov_or_none(const PyRenderResult& p, const std::vector<float>& v, size_t channels) {
  if (v.empty()) return nb::none();
  const size_t h = size_t(p.r.height), w = size_t(p.r.width);
  return nb::cast(channels == 1 ? to_numpy(v, {h, w}) : to_numpy(v, {h, w, channels}), nb::rv_policy::move);
}

RenderSettings render_settings(int width, int height, int spp, uint64_t seed, int threads, double time_limit,
                               const std::string& sampler, int max_depth, int max_diffuse, int max_glossy,
                               int max_transmission, float clamp, const std::string& filter, float filter_radius,
                               float filter_sigma, const std::string& reconstruction, bool progress) {
  if (spp <= 0) throw std::invalid_argument("render: parameter 'spp': must be > 0");
  if (threads < 0) throw std::invalid_argument("render: parameter 'threads': must be >= 0");
  if (!(time_limit >= 0)) throw std::invalid_argument("render: parameter 'time_limit': must be >= 0");
  if (width <= 0 || height <= 0 || width > 65536 || height > 65536)
    throw std::invalid_argument("render: parameter 'resolution': must be between 1 and 65536");
  RenderSettings cfg;
  cfg.width = width;
  cfg.height = height;
  cfg.spp = spp;
  cfg.seed = seed;
  cfg.threads = threads;
  cfg.time_limit = time_limit;
  if (sampler == "sobol") cfg.sampler = SamplerType::Sobol;
  else if (sampler == "zsobol") cfg.sampler = SamplerType::ZSobol;
  else if (sampler == "independent") cfg.sampler = SamplerType::Independent;
  else throw std::invalid_argument("render: parameter 'sampler': expected 'zsobol', 'sobol' or 'independent', got '" + sampler + "'");
  cfg.integrator.max_depth = max_depth;
  cfg.integrator.max_diffuse = max_diffuse;
  cfg.integrator.max_glossy = max_glossy;
  cfg.integrator.max_transmission = max_transmission;
  if (!(clamp >= 0)) throw std::invalid_argument("render: parameter 'clamp': must be >= 0 (0 = off)");
  cfg.integrator.clamp = clamp;
  if (filter == "gaussian") cfg.filter.type = FilterType::Gaussian;
  else if (filter == "box") cfg.filter.type = FilterType::Box;
  else throw std::invalid_argument("render: parameter 'filter': expected 'gaussian' or 'box', got '" + filter + "'");
  if (!(filter_radius > 0 && filter_radius <= kMaxFilterRadius))
    throw std::invalid_argument("render: parameter 'filter_radius': must be in (0, 8]");
  cfg.filter.radius = filter_radius;
  if (!(filter_sigma > 0)) throw std::invalid_argument("render: parameter 'filter_sigma': must be > 0");
  cfg.filter.sigma = filter_sigma;
  if (reconstruction == "splat") cfg.reconstruction = FilmReconstruction::Splat;
  else if (reconstruction == "filter_importance") cfg.reconstruction = FilmReconstruction::FilterImportance;
  else
    throw std::invalid_argument("render: parameter 'reconstruction': expected 'splat' or 'filter_importance', got '" +
                                reconstruction + "'");
  cfg.progress = progress;
  return cfg;
}

}  // namespace
}  // namespace kauri

// The module's name comes from the build: `_core`, and `_core_v4` for the x86-64-v4 build of
// the instruction-set dispatch (CMakeLists.txt, python/kauri/_isa.py). NB_MODULE pastes its
// argument into PyInit_<name>, so the macro is expanded one level up.
#ifndef KAURI_MODULE_NAME
#define KAURI_MODULE_NAME _core
#endif
#define KAURI_NB_MODULE(name, m) NB_MODULE(name, m)

KAURI_NB_MODULE(KAURI_MODULE_NAME, m) {
  using namespace kauri;
  m.doc() = "kauri core: spectral path tracer";
  m.attr("__version__") = KAURI_VERSION;
  // How this binary was compiled (kauri --version, the benchmark report): figures are
  // only comparable between builds with the same compiler, target and profile.
  nb::dict build;
  build["compiler"] = KAURI_BUILD_COMPILER;
  build["march"] = KAURI_BUILD_MARCH;
  build["pgo"] = KAURI_BUILD_PGO;
  build["path_lanes"] = KAURI_PATH_LANES ? kPathLanes : 0;  // paths a group traces in vector lanes
  m.attr("build_info") = build;

  nb::class_<Scene>(m, "Scene")
      .def(nb::init<>())
      .def("set_color_space", [](Scene& s, const std::string& n) { s.set_color_space(parse_cs(n)); })
      .def("add_texture", [](Scene& s, const std::string& name, const FloatArray& img, const std::string& wrap) {
        if (img.ndim() != 3 || img.shape(2) != 3)
          throw std::invalid_argument("texture '" + name + "': parameter 'image': expected an (height, width, 3) array");
        TextureDesc t;
        t.name = name;
        t.height = int(img.shape(0));
        t.width = int(img.shape(1));
        t.texels = std::make_shared<const std::vector<float>>(img.data(), img.data() + img.size());
        if (wrap == "clamp") t.wrap = TextureWrap::Clamp;
        else if (wrap != "repeat")
          throw std::invalid_argument("texture '" + name + "': parameter 'wrap': expected 'repeat' or 'clamp', got '" + wrap + "'");
        return s.add_texture(std::move(t));
      }, "name"_a, "image"_a, "wrap"_a)
      .def("add_material", [](Scene& s, const std::string& name, nb::list lobes, nb::list layers,
                              const std::string& root, bool symmetric, bool ior_acc, bool rough_acc) {
        MaterialDesc m;
        m.name = name;
        m.root = root;
        m.symmetric = symmetric;
        m.ior_accumulation = ior_acc;
        m.roughness_accumulation = rough_acc;
        for (nb::handle h : lobes) m.lobes.push_back(lobe_from_dict(nb::cast<nb::dict>(h)));
        for (nb::handle h : layers) {
          nb::dict d = nb::cast<nb::dict>(h);
          LayerDesc l;
          l.name = nb::cast<std::string>(d["name"]);
          std::string op = nb::cast<std::string>(d["op"]);
          if (op == "mix") l.op = LayerOp::Mix;
          else if (op == "coat") l.op = LayerOp::Coat;
          else if (op == "blend") l.op = LayerOp::Blend;
          else if (op == "add") l.op = LayerOp::Add;
          else throw std::invalid_argument("material '" + name + "', node '" + l.name + "': unknown operator '" + op + "'");
          for (nb::handle in : nb::cast<nb::list>(d["inputs"])) l.inputs.push_back(nb::cast<std::string>(in));
          l.weight = weight_from_dict(d);
          m.layers.push_back(std::move(l));
        }
        return s.add_material(m);
      })
      .def("warnings", [](const Scene& s) { return s.warnings(); })
      .def("add_group", &Scene::add_group)
      .def("add_instance", [](Scene& s, const std::string& name, int group, const FloatArray& xf) {
        double rows[3][4];
        read_matrix(xf, "instance '" + name + "'", rows);
        return s.add_instance(name, group, rows);
      })
      .def("add_mesh", [](Scene& s, int group, const std::string& name, const FloatArray& positions,
                          const IndexArray& indices, int face_size, std::optional<FloatArray> normals,
                          std::optional<FloatArray> uvs, nb::dict attributes, int material, bool emissive,
                          Vec3T color, float intensity, float temperature, bool two_sided) {
        MeshDesc d;
        d.name = name;
        d.positions = to_vector(positions);
        d.indices.assign(indices.data(), indices.data() + indices.size());
        d.face_size = face_size;
        if (normals) d.normals = to_vector(*normals);
        if (uvs) d.uvs = to_vector(*uvs);
        for (auto [k, v] : attributes) d.attributes[nb::cast<std::string>(k)] = to_vector(nb::cast<FloatArray>(v));
        d.material = material;
        d.emissive = emissive;
        d.emission = emission(color, intensity, temperature, two_sided);
        return s.add_mesh(group, std::move(d));
      }, "group"_a, "name"_a, "positions"_a, "indices"_a, "face_size"_a, "normals"_a.none(), "uvs"_a.none(),
         "attributes"_a, "material"_a, "emissive"_a, "color"_a, "intensity"_a, "temperature"_a, "two_sided"_a)
      .def("add_sphere", [](Scene& s, int group, const std::string& name, Vec3T center, float radius, int material,
                            bool emissive, Vec3T color, float intensity, float temperature, bool two_sided) {
        SphereDesc d{name, v3(center), radius, material, emissive, emission(color, intensity, temperature, two_sided)};
        return s.add_sphere(group, d);
      })
      .def("add_disk", [](Scene& s, int group, const std::string& name, Vec3T center, Vec3T normal, float radius,
                          int material, bool emissive, Vec3T color, float intensity, float temperature, bool two_sided) {
        DiskDesc d{name, v3(center), v3(normal), radius, material, emissive,
                   emission(color, intensity, temperature, two_sided)};
        return s.add_disk(group, d);
      })
      .def("add_light", [](Scene& s, const std::string& kind, const std::string& name, Vec3T position, Vec3T direction,
                           Vec3T color, float intensity, float temperature, float cone_angle, float cone_softness,
                           float angle, std::optional<FloatArray> image, std::optional<FloatArray> rotation) {
        LightDesc d;
        d.name = name;
        if (kind == "point") d.type = LightType::Point;
        else if (kind == "spot") d.type = LightType::Spot;
        else if (kind == "distant") d.type = LightType::Distant;
        else if (kind == "environment") d.type = image ? LightType::EnvMap : LightType::EnvConstant;
        else throw std::invalid_argument("light '" + name + "': unknown light type '" + kind + "'");
        d.position = v3(position);
        d.direction = v3(direction);
        d.emission = emission(color, intensity, temperature, false);
        d.cone_angle = cone_angle;
        d.cone_softness = cone_softness;
        d.angle = angle;
        if (image) {
          if (image->ndim() != 3 || image->shape(2) != 3)
            throw std::invalid_argument("light '" + name + "': parameter 'image': must be a (height, width, 3) array");
          d.height = int(image->shape(0));
          d.width = int(image->shape(1));
          d.image = to_vector(*image);
        }
        if (rotation) read_matrix(*rotation, "light '" + name + "'", d.rotation);
        return s.add_light(d);
      }, "kind"_a, "name"_a, "position"_a, "direction"_a, "color"_a, "intensity"_a, "temperature"_a, "cone_angle"_a,
         "cone_softness"_a, "angle"_a, "image"_a.none(), "rotation"_a.none())
      .def("set_camera", [](Scene& s, const std::string& kind, Vec3T eye, Vec3T target, Vec3T up, float fov,
                            const std::string& fov_axis, float width, float aperture_radius, float focus_distance) {
        CameraDesc c;
        if (kind == "perspective") c.type = CameraType::Perspective;
        else if (kind == "orthographic") c.type = CameraType::Orthographic;
        else throw std::invalid_argument("camera: unknown camera type '" + kind + "'");
        c.eye = v3(eye);
        c.target = v3(target);
        c.up = v3(up);
        c.fov = fov;
        c.fov_axis = fov_axis.size() == 1 ? fov_axis[0] : '?';
        c.ortho_width = width;
        c.aperture_radius = aperture_radius;
        c.focus_distance = focus_distance;
        s.set_camera(c);
      });

  nb::class_<PyRenderResult>(m, "RenderResult")
      .def_prop_ro("rgba", [](const PyRenderResult& p) { return to_numpy(p.r.rgba, {size_t(p.r.height), size_t(p.r.width), 4}); }, nb::rv_policy::move)
      // AOVs are None when the render skipped them (aovs=False).
      .def_prop_ro("albedo", [](const PyRenderResult& p) { return aov_or_none(p, p.r.albedo, 3); })
      .def_prop_ro("normal", [](const PyRenderResult& p) { return aov_or_none(p, p.r.normal, 3); })
      .def_prop_ro("depth", [](const PyRenderResult& p) { return aov_or_none(p, p.r.depth, 1); })
      .def_prop_ro("stats", [](const PyRenderResult& p) {
        const RenderStats& s = p.r.stats;
        nb::dict d;
        d["seconds"] = s.seconds;
        d["spp"] = s.spp;
        d["samples"] = s.samples;
        d["rays"] = s.rays;
        d["samples_per_second"] = s.samples_per_second();
        d["rays_per_second"] = s.rays_per_second();
        d["nan_samples"] = s.nan_samples;
        nb::list nan;
        for (const NaNReport& r : s.nan_pixels) nan.append(nb::make_tuple(r.x, r.y, r.sample));
        d["nan_pixels"] = nan;
        d["scene_bytes"] = s.scene_bytes;
        d["materials"] = s.materials;
        d["layer_layouts"] = s.layer_layouts;
        d["peak_rss_bytes"] = s.peak_rss_bytes;
        d["compile_seconds"] = s.compile_seconds;
        d["scene_reused"] = s.scene_reused;
        d["light_aa_pixels"] = s.light_aa_pixels;
        d["path_lanes"] = s.path_lanes;
        d["summary"] = s.summary();
        return d;
      })
      .def_prop_ro("color_space", [](const PyRenderResult& p) { return std::string(color_space_name(p.cs)); })
      .def("write_exr", [](const PyRenderResult& p, const std::string& path, const std::string& scene_name) {
        nb::gil_scoped_release release;
        write_exr(path, p.r, ExrMetadata{p.cs, p.seed, scene_name});
      }, "path"_a, "scene_name"_a = "")
      .def("write_png", [](const PyRenderResult& p, const std::string& path, float exposure) {
        nb::gil_scoped_release release;
        write_png_preview(path, p.r, p.cs, exposure);
      }, "path"_a, "exposure"_a = 0.0f);

  m.def("render", [](const Scene& scene, int width, int height, int spp, uint64_t seed, int threads, double time_limit,
                     const std::string& sampler, int max_depth, int max_diffuse, int max_glossy, int max_transmission,
                     float clamp, const std::string& filter, float filter_radius, float filter_sigma,
                     const std::string& reconstruction, bool progress, bool aovs, const std::string& light_sampler,
                     int rr_depth, int light_aa, bool path_lanes) {
    RenderSettings cfg = render_settings(width, height, spp, seed, threads, time_limit, sampler, max_depth, max_diffuse,
                                         max_glossy, max_transmission, clamp, filter, filter_radius, filter_sigma,
                                         reconstruction, progress);
    cfg.aovs = aovs;
    if (rr_depth < 0) throw std::invalid_argument("render: parameter 'rr_depth': must be >= 0");
    cfg.integrator.rr_min_depth = rr_depth;
    if (light_aa < 0 || light_aa > kLightAAMaxRays)
      throw std::invalid_argument("render: parameter 'light_aa': must be in [0, 64]");
    cfg.light_aa = light_aa;
    cfg.integrator.path_lanes = path_lanes;
    if (light_sampler == "tree") cfg.integrator.light_tree = true;
    else if (light_sampler == "power") cfg.integrator.light_tree = false;
    else
      throw std::invalid_argument("render: parameter 'light_sampler': expected 'tree' or 'power', got '" +
                                  light_sampler + "'");
    auto* out = new PyRenderResult{{}, scene.color_space_id(), seed};
    try {
      nb::gil_scoped_release release;
      CompileTimer timer;
      auto compiled = timer.get(scene, width, height);
      out->r = render(*compiled, cfg);
      timer.record(&out->r.stats);
    } catch (...) {
      delete out;
      throw;
    }
    return out;
  }, nb::rv_policy::take_ownership);

  m.def("ray_replay", [](const Scene& scene, int width, int height, int spp, uint64_t seed, int threads,
                         const std::string& sampler, int max_depth, int max_diffuse, int max_glossy,
                         int max_transmission, const std::string& filter, float filter_radius, float filter_sigma,
                         const std::string& reconstruction,
                         size_t max_rays, int repeats, bool aovs, int light_aa, std::vector<int> packets) {
    RenderSettings cfg = render_settings(width, height, spp, seed, threads, 0, sampler, max_depth, max_diffuse,
                                         max_glossy, max_transmission, 0, filter, filter_radius, filter_sigma,
                                         reconstruction, false);
    cfg.aovs = aovs;
    if (light_aa < 0 || light_aa > kLightAAMaxRays)
      throw std::invalid_argument("ray_replay: parameter 'light_aa': must be in [0, 64]");
    cfg.light_aa = light_aa;
    for (int w : packets)
      if (!EmbreeAccel::stream_width_supported(w))
        throw std::invalid_argument("ray_replay: parameter 'packets': widths must be 8 or 16, not " + std::to_string(w));
    RayLog log;
    ReplayResult rep;
    std::vector<ReplayResult> rep_packets(packets.size());
    RenderStats stats;
    {
      nb::gil_scoped_release release;
      CompileTimer timer;
      auto compiled = timer.get(scene, width, height);
      log = record_rays(*compiled, cfg, max_rays);
      // The real render (multi-threaded, timed as usual) and the replay alternate, best of
      // `repeats` each: the machine's speed drifts between seconds, and one render timed
      // against the best of several replays moved the ratio by up to 14 points between
      // runs of the same code (docs/benchmarks.md).
      rep.closest_seconds = rep.shadow_seconds = 1e300;
      for (ReplayResult& b : rep_packets) b.closest_seconds = b.shadow_seconds = 1e300;
      for (int k = 0; k < std::max(1, repeats); ++k) {
        const RenderStats s = render(*compiled, cfg).stats;
        if (k == 0 || s.seconds < stats.seconds) stats = s;
        const ReplayResult r = replay_rays(compiled->accel(), log, threads, 1);
        rep.closest_seconds = std::min(rep.closest_seconds, r.closest_seconds);
        rep.shadow_seconds = std::min(rep.shadow_seconds, r.shadow_seconds);
        rep.closest_hits = r.closest_hits;
        rep.shadow_hits = r.shadow_hits;
        for (size_t i = 0; i < packets.size(); ++i) {  // in the same alternation
          const ReplayResult p = replay_rays(compiled->accel(), log, threads, 1, packets[i]);
          ReplayResult& b = rep_packets[i];
          b.closest_seconds = std::min(b.closest_seconds, p.closest_seconds);
          b.shadow_seconds = std::min(b.shadow_seconds, p.shadow_seconds);
          b.closest_hits = p.closest_hits;
          b.shadow_hits = p.shadow_hits;
        }
      }
      timer.record(&stats);
    }
    nb::dict d;
    d["render_rays"] = stats.rays;
    d["render_seconds"] = stats.seconds;
    d["closest_rays"] = log.closest.size();
    d["shadow_rays"] = log.shadow.size();
    d["recorded_closest_hits"] = log.closest_hits;
    d["recorded_shadow_hits"] = log.shadow_hits;
    d["replay_closest_hits"] = rep.closest_hits;
    d["replay_shadow_hits"] = rep.shadow_hits;
    d["replay_closest_seconds"] = rep.closest_seconds;
    d["replay_shadow_seconds"] = rep.shadow_seconds;
    d["complete"] = log.closest.size() + log.shadow.size() == stats.rays;
    nb::dict by_width;
    for (size_t i = 0; i < packets.size(); ++i) {
      nb::dict e;
      e["closest_seconds"] = rep_packets[i].closest_seconds;
      e["shadow_seconds"] = rep_packets[i].shadow_seconds;
      e["closest_hits"] = rep_packets[i].closest_hits;
      e["shadow_hits"] = rep_packets[i].shadow_hits;
      by_width[nb::int_(packets[i])] = e;
    }
    d["packets"] = by_width;
    return d;
  });

  m.def("read_rgb_image", [](const std::string& path) {
    std::vector<float> rgb;
    int w, h;
    read_rgb_image(path, &rgb, &w, &h);
    return to_numpy(rgb, {size_t(h), size_t(w), 3});
  });
}
