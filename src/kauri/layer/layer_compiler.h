// Host side of the layer system: material graphs as authored (named lobes and
// operator nodes), validated and compiled into layer programs.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "kauri/bsdf/lobe.h"
#include "kauri/core/math.h"
#include "kauri/layer/layer_program.h"

namespace kauri {

/// A constant, or a named per-vertex attribute times `value`.
struct ScalarInputDesc {
  std::string attribute;
  Float value = 1;
};

struct LobeDesc {
  std::string name;
  LobeType type = LobeType::Lambert;
  Vec3 albedo{0.8f, 0.8f, 0.8f};   // Lambert albedo; diffuse-transmission τ; sheen colour
  int albedo_texture = -1;         // ≥ 0: that colour comes from this scene texture instead
  Float ior = 1.5f, abbe = 0;      // dielectric
  std::string metal;               // conductor: measured IOR by name, or
  Vec3 eta_rgb{0, 0, 0}, k_rgb{0, 0, 0};  // conductor: RGB η, κ (used when metal is empty)
  Float roughness = 0.3f, anisotropy = 0;  // microfacet lobes; sheen roughness
  MicrofacetType microfacet = MicrofacetType::GGX;
  bool compensate = true;          // conductor: Kulla–Conty multiple scattering (ggx_conductor@2)
  bool artist = false;             // conductor: reflectivity + edge tint (Gulbrandsen 2014) instead of η, κ
  Vec3 reflectivity{0.9f, 0.9f, 0.9f}, edge_tint{0.9f, 0.9f, 0.9f};
  // Emission node (EDF): radiance as RGB (working space), blackbody temperature or a
  // tabulated spectrum (wavelength nm, value pairs), times intensity.
  bool emission = false;
  Vec3 emission_rgb{1, 1, 1};
  Float temperature = 0, intensity = 1, focus = 0;
  bool two_sided = false;
  std::vector<float> spectrum_nm, spectrum_values;
  ScalarInputDesc weight;          // w_b
};

struct LayerDesc {
  std::string name;
  LayerOp op = LayerOp::Coat;
  std::vector<std::string> inputs;  // coat: top first
  ScalarInputDesc weight;           // w_l
};

struct MaterialDesc {
  std::string name;
  std::vector<LobeDesc> lobes;
  std::vector<LayerDesc> layers;
  std::string root;                 // empty: the one node nothing else uses
  bool symmetric = true;            // back hits see the same stack (mirrored)
  bool ior_accumulation = false;
  bool roughness_accumulation = false;
};

/// A compiled layout: nodes in post-order (root last) and the child lists of the
/// front (as authored) and back (vertical operators reversed) programs.
struct LayerLayout {
  std::vector<LayerNode> nodes;
  std::vector<uint16_t> front_children, back_children;
  std::string key() const;  // identical layouts have identical keys
};

struct CompiledMaterial {
  LayerLayout layout;
  std::vector<LobeDesc> lobes;              // in program lobe-index order
  std::vector<ScalarInputDesc> node_weights;  // one per node
  std::vector<std::string> warnings;
};

/// Validates and compiles; throws std::invalid_argument naming the material and node.
CompiledMaterial compile_material(const MaterialDesc& m);

}  // namespace kauri
