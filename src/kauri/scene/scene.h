// Host scene description: what the Python API and (later) scene parsers build.
// Every add_* validates its input and throws std::invalid_argument with a
// message naming the object and parameter; compile() turns the description into
// a CompiledScene whose SceneView is plain data for render-time code.
#pragma once

#include <array>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "kauri/accel/embree_accel.h"
#include "kauri/layer/layer_compiler.h"
#include "kauri/sampler/distribution.h"
#include "kauri/scene/scene_view.h"
#include "kauri/spectral/color_space.h"

namespace kauri {

/// Emission of an area light (or a light's colour): RGB in the working space, or a
/// blackbody temperature (K) scaled to luminance `intensity`.
struct EmissionDesc {
  Vec3 rgb{1, 1, 1};
  Float temperature = 0;  // > 0 selects a blackbody
  Float intensity = 1;
  bool two_sided = false;
};

struct MeshDesc {
  std::string name;
  std::vector<float> positions;   // 3 per vertex
  std::vector<uint32_t> indices;  // face_size per face
  int face_size = 3;              // 3 (triangles) or 4 (quads, split into two triangles)
  std::vector<float> normals;     // optional, 3 per vertex
  std::vector<float> uvs;         // optional, 2 per vertex
  std::map<std::string, std::vector<float>> attributes;  // optional named per-vertex floats
  int material = -1;
  bool emissive = false;
  EmissionDesc emission;
};

/// An image texture: linear RGB texels in the working space, row 0 = top of the image.
struct TextureDesc {
  std::string name;
  int width = 0, height = 0;
  std::shared_ptr<const std::vector<float>> texels;  // shared with compiled scenes
  TextureWrap wrap = TextureWrap::Repeat;
  Float max_value = 0;  // largest component (an albedo texture must not exceed 1)
};

struct SphereDesc {
  std::string name;
  Point3 center;
  Float radius = 1;
  int material = -1;
  bool emissive = false;
  EmissionDesc emission;
};

struct DiskDesc {
  std::string name;
  Point3 center;
  Normal3 normal{0, 1, 0};
  Float radius = 1;
  int material = -1;
  bool emissive = false;
  EmissionDesc emission;
};

struct LightDesc {
  std::string name;
  LightType type = LightType::Point;
  Point3 position;
  Vec3 direction{0, -1, 0};       // spot axis / direction light travels (distant)
  EmissionDesc emission;
  Float cone_angle = 30, cone_softness = 5;  // spot, degrees
  Float angle = 0;                // distant: angular diameter in degrees (0.53 for the sun)
  std::vector<float> image;       // environment: height × width × 3 RGB
  int width = 0, height = 0;
  double rotation[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};  // environment orientation
};

struct CameraDesc {
  CameraType type = CameraType::Perspective;
  Point3 eye{0, 0, 5}, target{0, 0, 0};
  Vec3 up{0, 1, 0};
  Float fov = 40;          // degrees along fov_axis (perspective)
  char fov_axis = 'x';
  Float ortho_width = 2;   // world units across x (orthographic)
  Float aperture_radius = 0, focus_distance = 0;  // 0 focus = distance to target
};

class CompiledScene;

/// Render-time parameters of one lobe description in working space `cs`; tabulated
/// emission spectra are resampled into `tables` (which must outlive the result).
LobeParams lobe_params(const LobeDesc& lobe, const RGBColorSpace& cs, std::deque<std::vector<float>>* tables);

/// One material compiled for evaluation without a scene (tests, benchmarks, tools):
/// its lobes, constant node weights and layer programs. Not copyable: `view` points
/// into the members.
struct StandaloneMaterial {
  StandaloneMaterial(const MaterialDesc& m, ColorSpaceId cs);
  StandaloneMaterial(const StandaloneMaterial&) = delete;
  StandaloneMaterial& operator=(const StandaloneMaterial&) = delete;
  std::vector<LobeParams> lobes;
  std::vector<ScalarInput> weights;
  LayerLayout layout;
  MaterialView view;
  std::deque<std::vector<float>> tables;
};

class Scene {
 public:
  Scene();
  void set_color_space(ColorSpaceId id) {
    color_space_ = id;
    ++revision_;
  }
  ColorSpaceId color_space_id() const { return color_space_; }

  int add_texture(TextureDesc t);  // returns its id, which LobeDesc::albedo_texture refers to
  int add_material(const MaterialDesc& m);
  int add_group(const std::string& name);  // a prototype for instancing; returns its id (≥ 1)
  int add_instance(const std::string& name, int group, const double xf[3][4]);
  int add_mesh(int group, MeshDesc m);
  int add_sphere(int group, const SphereDesc& s);
  int add_disk(int group, const DiskDesc& d);
  int add_light(const LightDesc& l);
  void set_camera(const CameraDesc& c);

  /// Builds the render-time scene for an image of width × height pixels.
  std::unique_ptr<CompiledScene> compile(int width, int height) const;
  /// The same, kept and handed out again while the scene is unchanged (every add_* and
  /// set_* call changes it) and the image size is the same: renders after the first skip
  /// the BVH build and light preparation, as an interactive session re-rendering at more
  /// samples expects (on a million triangles the build takes longer than a preview).
  /// Thread-safe; the compiled scene lives until the Scene is changed or destroyed and no
  /// render still holds it.
  std::shared_ptr<const CompiledScene> compiled(int width, int height, bool* reused = nullptr) const;

  size_t material_count() const { return materials_.size(); }
  /// Warnings raised while adding materials (e.g. an 'add' turned into a 'coat').
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  struct Shape {
    ShapeType type;
    std::string name;
    MeshDesc mesh;  // geometry for meshes; name/material/emission for all
    SphereDesc sphere;
    DiskDesc disk;
    int material = -1;
    bool emissive = false;
    EmissionDesc emission;
  };
  struct Group {
    std::string name;
    std::vector<Shape> shapes;
  };
  struct Instance {
    std::string name;
    int group;
    Transform xf;
  };
  void check_group(int group, const std::string& what) const;
  void check_material(int material, const std::string& what) const;
  void check_texture_use(const std::string& obj, const LobeDesc& l) const;

  friend class CompiledScene;
  ColorSpaceId color_space_ = ColorSpaceId::ACEScg;
  std::vector<TextureDesc> textures_;
  std::vector<MaterialDesc> materials_;
  std::vector<CompiledMaterial> compiled_materials_;
  std::vector<std::string> warnings_;
  std::vector<Group> groups_;
  std::vector<Instance> instances_;
  std::vector<LightDesc> lights_;
  CameraDesc camera_;
  bool has_camera_ = false;

  /// The last compiled scene and what it was compiled from. A copied or assigned Scene
  /// starts with an empty cache: the mutex is not copyable, and an assigned scene's old
  /// compiled form must not survive under the revision number it takes over.
  struct CompileCache {
    std::mutex mutex;
    std::shared_ptr<const CompiledScene> scene;
    uint64_t revision = 0;
    int width = 0, height = 0;
    CompileCache() = default;
    CompileCache(const CompileCache&) {}
    CompileCache& operator=(const CompileCache&) {
      std::lock_guard<std::mutex> lock(mutex);
      scene.reset();
      return *this;
    }
  };
  uint64_t revision_ = 0;  // bumped by every change to the scene
  mutable CompileCache cache_;
};

/// Render-ready scene: owns every array the SceneView points into.
class CompiledScene {
 public:
  const SceneView& view() const { return view_; }
  const EmbreeAccel& accel() const { return accel_; }
  size_t bytes() const { return bytes_; }
  int light_count() const { return view_.n_lights; }
  /// Distinct layer-program layouts (identical ones are stored once) and materials.
  int layout_count() const { return int(layouts_.size()); }
  int material_count() const { return int(materials_.size()); }

 private:
  friend class Scene;
  void build_lights(const Scene& scene, const RGBColorSpace& cs);
  void add_shape_lights(const Scene::Shape& s, const Transform* xf, const RGBColorSpace& cs);

  EmbreeAccel accel_;
  SceneView view_;
  std::vector<std::vector<ShapeView>> shape_views_;
  std::vector<GroupView> group_views_;
  std::vector<InstanceView> instance_views_;
  std::vector<int> emitter_first_light_;
  std::vector<MaterialView> materials_;
  std::vector<LobeParams> lobes_;
  std::vector<ScalarInput> node_weights_;
  std::vector<ImageTexture> textures_;
  std::vector<std::shared_ptr<const std::vector<float>>> texture_data_;  // keeps texels alive
  std::deque<std::vector<SigmoidPolynomial>> texture_coeffs_;  // per-texel reflectance fits (ImageTexture::coeffs)
  std::vector<std::unique_ptr<LayerLayout>> layouts_;  // unique layouts, shared by materials
  std::deque<std::vector<float>> attribute_arrays_;  // deque: element addresses stay put
  std::deque<std::vector<float>> emission_tables_;   // tabulated EDF spectra (1 nm)
  std::vector<Light> lights_;
  std::vector<int> infinite_lights_;
  std::vector<std::vector<EnvTexel>> env_texels_;
  std::vector<std::vector<Vec3>> env_texel_rgb_;  // per environment image: its texels' colours
  std::vector<std::unique_ptr<Distribution2DStorage>> env_distributions_;
  Distribution1DStorage light_distribution_;
  LightTreeStorage light_tree_;                   // finite lights (light_tree.h)
  Distribution1DStorage infinite_distribution_;   // infinite lights, ∝ power
  Float finite_light_share_ = 0;                  // Σ finite power / Σ power
  struct MeshArrays {
    std::vector<Point3> p;  // plus one padding vertex (Embree reads 16 bytes)
    std::vector<Normal3> n;
    std::vector<Vec2> uv;
    std::vector<uint32_t> index;
    const float* attr[kMaxVertexAttributes] = {nullptr, nullptr, nullptr, nullptr};
  };
  std::vector<std::unique_ptr<MeshArrays>> meshes_;
  size_t bytes_ = 0;
};

}  // namespace kauri
