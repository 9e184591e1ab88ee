#include "kauri/layer/layer_compiler.h"

#include "kauri/bsdf/bsdf.h"

#include <cmath>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace kauri {

namespace {

[[noreturn]] void fail(const MaterialDesc& m, const std::string& node, const std::string& what) {
  std::string where = "material '" + m.name + "'";
  if (!node.empty()) where += ", node '" + node + "'";
  throw std::invalid_argument(where + ": " + what);
}

void check_weight(const MaterialDesc& m, const std::string& node, const ScalarInputDesc& w) {
  if (!std::isfinite(w.value)) fail(m, node, "parameter 'weight': must be finite");
  if (w.attribute.empty() && (w.value < 0 || w.value > 1))
    fail(m, node, "parameter 'weight': must lie in [0, 1], got " + std::to_string(w.value));
  if (!w.attribute.empty() && w.value < 0) fail(m, node, "parameter 'weight': attribute scale must be >= 0");
}

const char* op_name(LayerOp op) {
  switch (op) {
    case LayerOp::Mix: return "mix";
    case LayerOp::Coat: return "coat";
    case LayerOp::Blend: return "blend";
    case LayerOp::Add: return "add";
    default: return "lobe";
  }
}

}  // namespace

std::string LayerLayout::key() const {
  std::ostringstream os;
  for (const LayerNode& n : nodes) os << int(n.op) << ':' << int(n.n_children) << ':' << n.first_child << ':' << n.lobe << ';';
  os << '|';
  for (uint16_t c : front_children) os << c << ',';
  os << '|';
  for (uint16_t c : back_children) os << c << ',';
  return os.str();
}

CompiledMaterial compile_material(const MaterialDesc& m) {
  CompiledMaterial out;
  // Name table: lobes and layers share one namespace.
  std::map<std::string, int> lobe_index, layer_index;
  for (size_t i = 0; i < m.lobes.size(); ++i) {
    const LobeDesc& l = m.lobes[i];
    if (l.name.empty()) fail(m, "", "a lobe has no name");
    if (lobe_index.count(l.name)) fail(m, l.name, "duplicate node name");
    check_weight(m, l.name, l.weight);
    lobe_index[l.name] = int(i);
  }
  for (size_t i = 0; i < m.layers.size(); ++i) {
    const LayerDesc& l = m.layers[i];
    if (l.name.empty()) fail(m, "", "a layer has no name");
    if (lobe_index.count(l.name) || layer_index.count(l.name)) fail(m, l.name, "duplicate node name");
    check_weight(m, l.name, l.weight);
    layer_index[l.name] = int(i);
  }
  if (m.lobes.empty()) fail(m, "", "has no lobes");

  // Inputs must exist; find the root.
  std::set<std::string> used;
  for (const LayerDesc& l : m.layers) {
    const size_t n = l.inputs.size();
    if (l.op == LayerOp::Mix && (n < 2 || n > size_t(kMaxMixInputs)))
      fail(m, l.name, "mix takes 2 to " + std::to_string(kMaxMixInputs) + " inputs, got " + std::to_string(n));
    if (l.op != LayerOp::Mix && n != 2)
      fail(m, l.name, std::string(op_name(l.op)) + " takes exactly 2 inputs, got " + std::to_string(n));
    for (const std::string& in : l.inputs) {
      if (!lobe_index.count(in) && !layer_index.count(in))
        fail(m, l.name, "unknown input '" + in + "' (no lobe or layer of that name)");
      used.insert(in);
    }
  }
  std::string root = m.root;
  if (root.empty()) {
    std::vector<std::string> roots;
    for (const LobeDesc& l : m.lobes) if (!used.count(l.name)) roots.push_back(l.name);
    for (const LayerDesc& l : m.layers) if (!used.count(l.name)) roots.push_back(l.name);
    if (roots.size() != 1) {
      std::string list;
      for (const auto& r : roots) list += (list.empty() ? "'" : ", '") + r + "'";
      fail(m, "", roots.empty() ? "the layer graph has no root (every node is an input: a cycle)"
                                : "several unconnected nodes (" + list + "); combine them or name the root");
    }
    root = roots[0];
  } else if (!lobe_index.count(root) && !layer_index.count(root)) {
    fail(m, root, "the root names no lobe or layer");
  }

  // Post-order walk with cycle detection.
  std::set<std::string> on_stack, done;
  std::map<std::string, int> node_of;
  std::vector<std::vector<int>> child_nodes;
  std::vector<bool> all_emission;  // per node: its subtree holds only emission nodes
  std::function<int(const std::string&)> visit = [&](const std::string& name) -> int {
    if (on_stack.count(name)) fail(m, name, "the layer graph has a cycle through this node");
    if (done.count(name)) fail(m, name, "is used as an input more than once (layer graphs are trees)");
    on_stack.insert(name);
    LayerNode node;
    std::vector<int> kids;
    ScalarInputDesc weight;
    bool emission_only;
    if (lobe_index.count(name)) {
      const LobeDesc& l = m.lobes[size_t(lobe_index[name])];
      node.op = LayerOp::Lobe;
      node.lobe = int16_t(out.lobes.size());
      out.lobes.push_back(l);
      weight = l.weight;
      emission_only = l.emission;
    } else {
      const LayerDesc& l = m.layers[size_t(layer_index[name])];
      node.op = l.op;
      for (const std::string& in : l.inputs) kids.push_back(visit(in));
      weight = l.weight;
      emission_only = true;
      for (int k : kids) emission_only = emission_only && all_emission[size_t(k)];
      if (l.op == LayerOp::Add && !emission_only) {
        // Add creates energy: only meaningful on emission (notes §8.4.1), so on
        // anything that is not all EDFs it becomes a coat.
        node.op = LayerOp::Coat;
        out.warnings.push_back("material '" + m.name + "', node '" + name +
                               "': 'add' on scattering lobes would create energy; treated as 'coat'");
      }
    }
    on_stack.erase(name);
    done.insert(name);
    int index = int(out.layout.nodes.size());
    if (index >= kMaxLayerNodes)
      fail(m, name, "too many nodes (a material may have at most " + std::to_string(kMaxLayerNodes) + ")");
    node.n_children = uint8_t(kids.size());
    out.layout.nodes.push_back(node);
    out.node_weights.push_back(weight);
    all_emission.push_back(emission_only);
    child_nodes.push_back(kids);
    return index;
  };
  visit(root);
  bool has_emission = false;
  for (const LobeDesc& l : out.lobes) has_emission = has_emission || l.emission;
  if (has_emission)
    for (size_t i = 0; i < out.node_weights.size(); ++i)
      if (!out.node_weights[i].attribute.empty())
        fail(m, "", "emits light, so its weights must be constants (attribute-driven weights on emitters "
                    "are not supported yet)");
  if (out.lobes.size() > size_t(kMaxLobes))
    fail(m, "", "uses " + std::to_string(out.lobes.size()) + " lobes; at most " + std::to_string(kMaxLobes));
  for (const LobeDesc& l : m.lobes)
    if (!done.count(l.name)) out.warnings.push_back("material '" + m.name + "', node '" + l.name + "': unused");
  for (const LayerDesc& l : m.layers)
    if (!done.count(l.name)) out.warnings.push_back("material '" + m.name + "', node '" + l.name + "': unused");

  // Child lists; the back program reverses vertical operators (single-sided stacks, §8.4.2).
  for (size_t i = 0; i < out.layout.nodes.size(); ++i) {
    LayerNode& n = out.layout.nodes[i];
    n.first_child = uint16_t(out.layout.front_children.size());
    const auto& kids = child_nodes[i];
    bool vertical = n.op == LayerOp::Coat || n.op == LayerOp::Add;
    for (size_t k = 0; k < kids.size(); ++k) {
      out.layout.front_children.push_back(uint16_t(kids[k]));
      out.layout.back_children.push_back(uint16_t(m.symmetric || !vertical ? kids[k] : kids[kids.size() - 1 - k]));
    }
  }
  return out;
}

}  // namespace kauri
