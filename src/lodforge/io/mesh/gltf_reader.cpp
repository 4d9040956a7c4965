#include "lodforge/io/mesh/gltf_reader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <unordered_map>
#include <vector>

#include <draco/compression/decode.h>
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/io/mesh/glb_container.h"
#include "lodforge/io/mesh/gltf_constants.h"
#include "lodforge/io/mesh/gltf_meshopt.h"
#include "lodforge/io/mesh/gltf_textures.h"

namespace lodforge {

namespace {

constexpr int kModePoints = 0, kModeTriangles = 4, kModeStrip = 5, kModeFan = 6;
using namespace gltf;  // the component types and chunk magics
// Debian's tinygltf (2.8) sizes the BIN chunk as everything after the JSON chunk, its 8-byte
// header included, so it copies a buffer up to 8 bytes longer than the chunk from past the end
// of the file. GLB is parsed from a copy with that many zero bytes after the end, and the
// buffer is checked against the real chunk length afterwards.
constexpr std::size_t kTinygltfOverread = 8;

std::size_t componentSize(int type) {
  switch (type) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

// One component, converted as glTF's normalisation rules say (spec 3.11, "Animations" table).
double loadComponent(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case kByte: {
      std::int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case kUnsignedByte:
      return normalized ? *p / 255.0 : *p;
    case kShort: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case kUnsignedShort: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case kUnsignedInt: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return static_cast<double>(v);
    }
  }
}

Mat4d localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    Mat4d m;
    std::copy(node.matrix.begin(), node.matrix.end(), m.m.begin());
    return m;
  }
  Mat4d t, r, s;
  if (node.translation.size() == 3)
    t = Mat4d::translation({node.translation[0], node.translation[1], node.translation[2]});
  if (node.rotation.size() == 4)
    r = Mat4d::rotation(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3]);
  if (node.scale.size() == 3) s = Mat4d::scale({node.scale[0], node.scale[1], node.scale[2]});
  return t * r * s;
}

bool refuseFileExists(const std::string&, void*) {
  return false;
}
std::string keepPath(const std::string& path, void*) {
  return path;
}
bool refuseRead(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external file '" + path + "' not allowed";
  return false;
}
bool refuseWrite(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
  return false;
}
class Loader {
 public:
  // `binOffset`, `fileBinBytes`: where the BIN chunk's data is in the file and how much of it
  // the file holds (decoded meshopt views come after it, in no byte of the file).
  Loader(const tinygltf::Model& gltf, const std::string& name, std::uint64_t binOffset,
         std::uint64_t fileBinBytes, const std::string& baseDir, std::vector<std::string>* warnings)
      : gltf_(gltf),
        name_(name),
        binOffset_(binOffset),
        fileBinBytes_(fileBinBytes),
        baseDir_(baseDir),
        warnings_(warnings) {}

  Model load() {
    readMaterials();
    texturing_ = readGltfTextures(gltf_, baseDir_, name_, model_, warnings_);
    decideColors();
    pointsOnly_ = drawsPointsOnly();
    traverseScene();
    placeAtOrigin();
    warnSkipped();
    return std::move(model_);
  }

 private:
  [[noreturn]] void fail(std::string_view what) const {
    throw ErrorException{badInput(name_, what)};
  }

  template <class T>
  const T& element(const std::vector<T>& list, int index, std::string_view kind,
                   std::string_view where) const {
    if (index < 0 || static_cast<std::size_t>(index) >= list.size())
      fail(fmt::format("{}: {} {} does not exist (there are {})", where, kind, index, list.size()));
    return list[static_cast<std::size_t>(index)];
  }

  // Reads accessor values as doubles, `components` per element; checks every byte range.
  std::vector<double> readAccessor(int index, int components, std::string_view where) const {
    const auto& accessor = element(gltf_.accessors, index, "accessor", where);
    const std::string what = fmt::format("{} (accessor {})", where, index);
    const int actual = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type));
    if (actual != components)
      fail(fmt::format("{}: expected {} components per element, found {}", what, components,
                       actual));
    const std::size_t size = componentSize(accessor.componentType);
    if (size == 0) fail(fmt::format("{}: invalid component type {}", what, accessor.componentType));
    const std::size_t elementSize = size * static_cast<std::size_t>(components);
    std::vector<double> values;
    if (accessor.bufferView < 0) {
      // All zeros plus sparse substitutions; bound the count by what the file could mean.
      std::size_t bufferBytes = 0;
      for (const auto& b : gltf_.buffers) bufferBytes += b.data.size();
      if (!accessor.sparse.isSparse || accessor.count > 16 * bufferBytes + 1024)
        fail(fmt::format("{}: {} elements without a bufferView", what, accessor.count));
      values.assign(accessor.count * static_cast<std::size_t>(components), 0.0);
    } else {
      const auto& view = element(gltf_.bufferViews, accessor.bufferView, "bufferView", what);
      const auto& buffer = element(gltf_.buffers, view.buffer, "buffer", what);
      if (view.byteOffset > buffer.data.size() ||
          view.byteLength > buffer.data.size() - view.byteOffset)
        fail(fmt::format("{}: bufferView {} (bytes {}..{}) lies outside buffer {} ({} bytes)", what,
                         accessor.bufferView, view.byteOffset, view.byteOffset + view.byteLength,
                         view.buffer, buffer.data.size()));
      const std::size_t stride = view.byteStride ? view.byteStride : elementSize;
      if (stride < elementSize)
        fail(fmt::format("{}: byteStride {} is smaller than an element ({} bytes)", what, stride,
                         elementSize));
      const bool fits =
          accessor.count == 0 ||
          (accessor.byteOffset <= view.byteLength &&
           elementSize <= view.byteLength - accessor.byteOffset &&
           accessor.count - 1 <= (view.byteLength - accessor.byteOffset - elementSize) / stride);
      if (!fits) {
        // GLB only: buffer 0 is the BIN chunk, so the file position is known (not for a
        // decoded meshopt view's data, which no byte of the file holds).
        const std::uint64_t inBin = view.byteOffset + accessor.byteOffset;
        const std::uint64_t at =
            binOffset_ != 0 && view.buffer == 0 && inBin < fileBinBytes_ ? binOffset_ + inBin : 0;
        fail(fmt::format(
            "{}: {} elements of {} bytes (stride {}) starting at byte {} do not fit in "
            "bufferView {} ({} bytes){}",
            what, accessor.count, elementSize, stride, accessor.byteOffset, accessor.bufferView,
            view.byteLength, at ? fmt::format(", file byte {}", at) : std::string()));
      }
      values.resize(accessor.count * static_cast<std::size_t>(components));
      const unsigned char* base = buffer.data.data() + view.byteOffset + accessor.byteOffset;
      for (std::size_t i = 0; i < accessor.count; ++i) {
        for (int c = 0; c < components; ++c) {
          values[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] =
              loadComponent(base + i * stride + static_cast<std::size_t>(c) * size,
                            accessor.componentType, accessor.normalized);
        }
      }
    }
    if (accessor.sparse.isSparse) applySparse(accessor, components, size, values, what);
    return values;
  }

  void applySparse(const tinygltf::Accessor& accessor, int components, std::size_t size,
                   std::vector<double>& values, const std::string& what) const {
    const auto& sparse = accessor.sparse;
    if (sparse.count < 0 || static_cast<std::size_t>(sparse.count) > accessor.count)
      fail(fmt::format("{}: sparse count {} exceeds the element count {}", what, sparse.count,
                       accessor.count));
    const auto count = static_cast<std::size_t>(sparse.count);
    auto range = [&](int viewIndex, int offset, std::size_t bytes) -> const unsigned char* {
      const auto& view = element(gltf_.bufferViews, viewIndex, "bufferView", what);
      const auto& buffer = element(gltf_.buffers, view.buffer, "buffer", what);
      if (offset < 0 || view.byteOffset > buffer.data.size() ||
          view.byteLength > buffer.data.size() - view.byteOffset ||
          static_cast<std::size_t>(offset) > view.byteLength ||
          bytes > view.byteLength - static_cast<std::size_t>(offset))
        fail(fmt::format("{}: sparse data lies outside bufferView {}", what, viewIndex));
      return buffer.data.data() + view.byteOffset + static_cast<std::size_t>(offset);
    };
    const std::size_t indexSize = componentSize(sparse.indices.componentType);
    if (indexSize == 0 || sparse.indices.componentType == kByte ||
        sparse.indices.componentType == kShort || sparse.indices.componentType == kFloat)
      fail(fmt::format("{}: invalid sparse index type {}", what, sparse.indices.componentType));
    const unsigned char* indices =
        range(sparse.indices.bufferView, sparse.indices.byteOffset, count * indexSize);
    const std::size_t elementSize = size * static_cast<std::size_t>(components);
    const unsigned char* data =
        range(sparse.values.bufferView, sparse.values.byteOffset, count * elementSize);
    for (std::size_t i = 0; i < count; ++i) {
      const auto target = static_cast<std::size_t>(
          loadComponent(indices + i * indexSize, sparse.indices.componentType, false));
      if (target >= accessor.count)
        fail(fmt::format("{}: sparse index {} out of range", what, target));
      for (int c = 0; c < components; ++c) {
        values[target * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] =
            loadComponent(data + i * elementSize + static_cast<std::size_t>(c) * size,
                          accessor.componentType, accessor.normalized);
      }
    }
  }

  // The file's materials, in its order (objects refer to them by the same index). The base
  // colour also goes into the vertex colours (decideColors), which every writer carries.
  void readMaterials() {
    for (const auto& m : gltf_.materials) {
      Material material;
      material.name = m.name;
      const auto& pbr = m.pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() == 4)
        for (std::size_t k = 0; k < 4; ++k)
          material.baseColor[k] = static_cast<float>(pbr.baseColorFactor[k]);
      material.metallic = static_cast<float>(pbr.metallicFactor);
      material.roughness = static_cast<float>(pbr.roughnessFactor);
      material.alphaMode = m.alphaMode == "BLEND"  ? AlphaMode::kBlend
                           : m.alphaMode == "MASK" ? AlphaMode::kMask
                                                   : AlphaMode::kOpaque;
      material.alphaCutoff = static_cast<float>(m.alphaCutoff);
      material.doubleSided = m.doubleSided;
      if (m.emissiveFactor.size() == 3)
        for (std::size_t k = 0; k < 3; ++k)
          material.emissive[k] = static_cast<float>(m.emissiveFactor[k]);
      model_.materials.push_back(std::move(material));
    }
  }

  // Colours are kept when any drawn primitive has a material or COLOR_0, texture coordinates
  // when any has a texture.
  void decideColors() {
    for (const auto& mesh : gltf_.meshes) {
      for (const auto& primitive : mesh.primitives) {
        if (primitive.material >= 0 || primitive.attributes.count("COLOR_0")) withColors_ = true;
        if (texturing_.textured(primitive.material)) withUvs_ = true;
      }
    }
  }

  void traverseScene() {
    std::vector<int> roots;
    if (!gltf_.scenes.empty()) {
      const int scene = gltf_.defaultScene >= 0 ? gltf_.defaultScene : 0;
      roots = element(gltf_.scenes, scene, "scene", "scene").nodes;
    } else {
      // No scene: every node that is nobody's child is a root.
      std::vector<bool> isChild(gltf_.nodes.size(), false);
      for (const auto& node : gltf_.nodes) {
        for (int child : node.children) {
          if (child >= 0 && static_cast<std::size_t>(child) < isChild.size())
            isChild[static_cast<std::size_t>(child)] = true;
        }
      }
      for (std::size_t i = 0; i < gltf_.nodes.size(); ++i) {
        if (!isChild[i]) roots.push_back(static_cast<int>(i));
      }
    }
    visited_.assign(gltf_.nodes.size(), false);
    // Iterative depth-first walk: a hostile file cannot blow the stack. Each entry carries its
    // parent's transform and path (the node names from the root, "/"-separated).
    struct Entry {
      int index;
      Mat4d parent;
      std::string path;
    };
    std::vector<Entry> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, Mat4d{}, {}});
    while (!stack.empty()) {
      auto [index, parent, parentPath] = std::move(stack.back());
      stack.pop_back();
      const auto& node = element(gltf_.nodes, index, "node", "scene hierarchy");
      if (visited_[static_cast<std::size_t>(index)])
        fail(fmt::format("node {} appears twice in the hierarchy (a cycle or a shared child)",
                         index));
      visited_[static_cast<std::size_t>(index)] = true;
      const Mat4d world = parent * localTransform(node);
      const std::string name = node.name.empty() ? fmt::format("node {}", index) : node.name;
      const std::string path = parentPath.empty() ? name : parentPath + "/" + name;
      if (node.mesh >= 0) {
        const std::size_t first = model_.objects.size();
        addNode(index, node, world, path);
        setLayer(node, first);
      }
      for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
        stack.push_back({*child, world, path});
    }
  }

  // A node's CAD layers (extras.layer, as lodforge's GLB writer keeps them) on the objects it
  // added from `first` on.
  void setLayer(const tinygltf::Node& node, std::size_t first) {
    if (!node.extras.IsObject() || !node.extras.Has("layer")) return;
    const tinygltf::Value& value = node.extras.Get("layer");
    if (!value.IsString() || value.Get<std::string>().empty()) return;
    const std::uint32_t layer = layers_.index(value.Get<std::string>());
    for (std::size_t o = first; o < model_.objects.size(); ++o) model_.objects[o].layer = layer;
  }

  void addNode(int index, const tinygltf::Node& node, const Mat4d& world, const std::string& path) {
    const auto& mesh = element(gltf_.meshes, node.mesh, "mesh", fmt::format("node {}", index));
    std::string baseName = !node.name.empty()   ? node.name
                           : !mesh.name.empty() ? mesh.name
                                                : fmt::format("node {}", index);
    const auto instancing = node.extensions.find("EXT_mesh_gpu_instancing");
    if (instancing == node.extensions.end()) {
      addObject(baseName, path, node.mesh, mesh, world);
      return;
    }
    // GPU instancing: one object per instance, each with its own transform.
    const tinygltf::Value& attributes = instancing->second.Get("attributes");
    const std::string where = fmt::format("node {} EXT_mesh_gpu_instancing", index);
    auto attribute = [&](const char* key, int components) -> std::vector<double> {
      if (!attributes.Has(key)) return {};
      return readAccessor(attributes.Get(key).GetNumberAsInt(), components, where);
    };
    const std::vector<double> t = attribute("TRANSLATION", 3);
    const std::vector<double> r = attribute("ROTATION", 4);
    const std::vector<double> s = attribute("SCALE", 3);
    const std::size_t count = std::max({t.size() / 3, r.size() / 4, s.size() / 3});
    if ((!t.empty() && t.size() / 3 != count) || (!r.empty() && r.size() / 4 != count) ||
        (!s.empty() && s.size() / 3 != count))
      fail(fmt::format("{}: attributes differ in count", where));
    for (std::size_t i = 0; i < count; ++i) {
      Mat4d local;
      if (!t.empty()) local = Mat4d::translation({t[3 * i], t[3 * i + 1], t[3 * i + 2]});
      if (!r.empty())
        local = local * Mat4d::rotation(r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]);
      if (!s.empty()) local = local * Mat4d::scale({s[3 * i], s[3 * i + 1], s[3 * i + 2]});
      addObject(fmt::format("{}#{}", baseName, i), fmt::format("{}#{}", path, i), node.mesh, mesh,
                world * local);
    }
  }

  struct PrimitiveData {
    std::vector<double> positions, normals, colors, uvs;  // 3, 3, 4, 2 per vertex
    std::vector<std::uint32_t> triangles;
  };

  // A mesh whose primitives use a texture and another material becomes an object per material
  // (named "name (material)"): an object with a texture has one material (model.h).
  std::vector<std::vector<std::size_t>> primitiveGroups(const tinygltf::Mesh& mesh) const {
    std::vector<int> materials;
    bool textured = false;
    for (const auto& primitive : mesh.primitives) {
      textured = textured || texturing_.textured(primitive.material);
      if (std::find(materials.begin(), materials.end(), primitive.material) == materials.end())
        materials.push_back(primitive.material);
    }
    if (!textured || materials.size() < 2) {
      std::vector<std::size_t> all(mesh.primitives.size());
      for (std::size_t p = 0; p < all.size(); ++p) all[p] = p;
      return {all};
    }
    std::vector<std::vector<std::size_t>> groups(materials.size());
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      const auto g = std::find(materials.begin(), materials.end(), mesh.primitives[p].material) -
                     materials.begin();
      groups[static_cast<std::size_t>(g)].push_back(p);
    }
    return groups;
  }

  std::string groupName(const std::string& name, const tinygltf::Mesh& mesh,
                        const std::vector<std::size_t>& group, bool split) const {
    if (!split) return name;
    const int material = mesh.primitives[group.front()].material;
    if (material < 0) return name;
    const std::string& label = gltf_.materials[static_cast<std::size_t>(material)].name;
    return fmt::format("{} ({})", name,
                       label.empty() ? fmt::format("material {}", material) : label);
  }

  void addObject(const std::string& name, const std::string& path, int meshIndex,
                 const tinygltf::Mesh& mesh, const Mat4d& world) {
    const std::vector<std::vector<std::size_t>> groups = primitiveGroups(mesh);
    for (const std::vector<std::size_t>& group : groups) {
      ModelBuilder builder(model_);
      builder.beginObject(groupName(name, mesh, group, groups.size() > 1), path);
      for (std::size_t p : group) addPrimitive(meshIndex, mesh, p, world);
      // One material per object: its first drawn primitive's (the vertex colours keep the
      // others' base colours).
      for (std::size_t p : group) {
        const int material = mesh.primitives[p].material;
        if (material < 0 || static_cast<std::size_t>(material) >= model_.materials.size()) continue;
        model_.objects.back().material = static_cast<std::uint32_t>(material);
        break;
      }
      builder.endObject();
    }
  }

  // A file whose meshes (drawn or not) hold no triangles but points (a point tile, a scan
  // exported as glTF) is read as a point set, as a PLY without faces is; beside triangles,
  // points are reported (skip).
  bool drawsPointsOnly() const {
    bool points = false;
    for (const tinygltf::Mesh& mesh : gltf_.meshes) {
      for (const tinygltf::Primitive& primitive : mesh.primitives) {
        const int mode = primitive.mode < 0 ? kModeTriangles : primitive.mode;
        if (mode == kModeTriangles || mode == kModeStrip || mode == kModeFan) return false;
        points |= mode == kModePoints;
      }
    }
    return points;
  }

  void addPrimitive(int meshIndex, const tinygltf::Mesh& mesh, std::size_t p, const Mat4d& world) {
    const auto& primitive = mesh.primitives[p];
    const std::string where = fmt::format("mesh {} primitive {}", meshIndex, p);
    const int mode = primitive.mode < 0 ? kModeTriangles : primitive.mode;
    if (mode < kModePoints || mode > kModeFan)
      fail(fmt::format("{}: mode {} is no glTF primitive mode", where, mode));
    // An unindexed point primitive of a points-only file: its vertices are the points.
    const bool points = mode == kModePoints && pointsOnly_ && primitive.indices < 0 &&
                        primitive.extensions.count("KHR_draco_mesh_compression") == 0 &&
                        primitive.attributes.count("POSITION") != 0;
    if (!points && mode != kModeTriangles && mode != kModeStrip && mode != kModeFan) {
      skip(primitive, mode);
      return;
    }
    PrimitiveData data = primitive.extensions.count("KHR_draco_mesh_compression")
                             ? decodeDraco(primitive, where)
                             : readPrimitive(primitive, mode, where);
    const std::size_t vertexCount = data.positions.size() / 3;
    const auto base =
        static_cast<std::uint32_t>(model_.positions.size() - model_.objects.back().vertexOffset);
    if (vertexCount > std::numeric_limits<std::uint32_t>::max() - base)
      fail(fmt::format("{}: too many vertices in one object", where));
    addVertices(data, world, primitive.material, where);
    const bool mirrored = world.determinant3() < 0;  // winding flips under a mirror
    for (std::size_t t = 0; t + 2 < data.triangles.size(); t += 3) {
      std::uint32_t a = data.triangles[t], b = data.triangles[t + 1], c = data.triangles[t + 2];
      if (a >= vertexCount || b >= vertexCount || c >= vertexCount)
        fail(fmt::format("{}: index {} out of range ({} vertices)", where, std::max({a, b, c}),
                         vertexCount));
      if (mirrored) std::swap(b, c);
      model_.indices.insert(model_.indices.end(), {base + a, base + b, base + c});
    }
  }

  // Points and lines (a CAD export's edges, a scan's stray points) are not surfaces: counted per
  // placed instance and reported, not dropped in silence. What is lost is the corners the
  // primitive draws: its indices (edges often share the faces' vertices), else its vertices.
  void skip(const tinygltf::Primitive& primitive, int mode) {
    Skipped& skipped = mode == kModePoints ? skippedPoints_ : skippedLines_;
    ++skipped.primitives;
    int accessor = primitive.indices;
    if (accessor < 0) {
      const auto position = primitive.attributes.find("POSITION");
      if (position != primitive.attributes.end()) accessor = position->second;
    }
    if (accessor >= 0 && static_cast<std::size_t>(accessor) < gltf_.accessors.size())
      skipped.vertices += gltf_.accessors[static_cast<std::size_t>(accessor)].count;
  }

  void warnSkipped() const {
    if (warnings_ == nullptr) return;
    for (const auto& [skipped, kind] :
         {std::pair{&skippedPoints_, "point"}, std::pair{&skippedLines_, "line"}}) {
      if (skipped->primitives == 0) continue;
      // A points-only file reads its plain point primitives (drawsPointsOnly).
      const bool pointSet = pointsOnly_ && skipped == &skippedPoints_;
      warnings_->push_back(fmt::format(
          "{}: {} {} primitive{} ({} corners) not read: only {} are", name_, skipped->primitives,
          kind, skipped->primitives == 1 ? "" : "s", skipped->vertices,
          pointSet ? "unindexed, uncompressed point primitives with positions" : "triangles"));
    }
  }

  void addVertices(const PrimitiveData& data, const Mat4d& world, int material,
                   const std::string& where) {
    const Mat4d normalMatrix = world.normalMatrix();
    const Vec4Color factor = baseColor(material, where);
    const std::size_t vertexCount = data.positions.size() / 3;
    for (std::size_t v = 0; v < vertexCount; ++v) {
      const Vec3d local{data.positions[3 * v], data.positions[3 * v + 1],
                        data.positions[3 * v + 2]};
      if (!isFinite(local)) fail(fmt::format("{}: POSITION {} is not finite", where, v));
      world_.push_back(world.transformPoint(local));
      model_.positions.push_back({});  // filled by placeAtOrigin
      if (!data.normals.empty()) {
        const Vec3d n{data.normals[3 * v], data.normals[3 * v + 1], data.normals[3 * v + 2]};
        if (!isFinite(n)) fail(fmt::format("{}: NORMAL {} is not finite", where, v));
        normalsByVertex_.push_back(toFloat(normalizeOr(normalMatrix.transformVector(n), Vec3d{})));
      } else {
        normalsByVertex_.push_back({});
        missingNormals_ = true;
      }
      if (withColors_) model_.colors.push_back(vertexColor(data, factor, v));
      if (withUvs_) {
        model_.uvs.push_back(
            data.uvs.empty() ? Vec2f{}
                             : texturing_.apply(material, data.uvs[2 * v], data.uvs[2 * v + 1]));
      }
    }
  }

  static Rgba8 vertexColor(const PrimitiveData& data, const std::array<double, 4>& factor,
                           std::size_t v) {
    double c[4] = {factor[0], factor[1], factor[2], factor[3]};
    if (!data.colors.empty()) {
      for (int k = 0; k < 4; ++k) c[k] *= data.colors[4 * v + static_cast<std::size_t>(k)];
    }
    auto channel = [](double x) {
      return static_cast<std::uint8_t>(
          std::lround(std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0) * 255));
    };
    return {channel(c[0]), channel(c[1]), channel(c[2]), channel(c[3])};
  }

  using Vec4Color = std::array<double, 4>;
  Vec4Color baseColor(int material, std::string_view where) const {
    if (material < 0) return {1, 1, 1, 1};
    const auto& m = element(gltf_.materials, material, "material", where);
    const auto& f = m.pbrMetallicRoughness.baseColorFactor;
    if (f.size() != 4) return {1, 1, 1, 1};
    return {f[0], f[1], f[2], f[3]};
  }

  PrimitiveData readPrimitive(const tinygltf::Primitive& primitive, int mode,
                              const std::string& where) {
    PrimitiveData data;
    const auto position = primitive.attributes.find("POSITION");
    if (position == primitive.attributes.end())
      fail(fmt::format("{}: no POSITION attribute", where));
    data.positions = readAccessor(position->second, 3, where + " POSITION");
    const std::size_t vertexCount = data.positions.size() / 3;
    if (auto normal = primitive.attributes.find("NORMAL"); normal != primitive.attributes.end()) {
      data.normals = readAccessor(normal->second, 3, where + " NORMAL");
      if (data.normals.size() != data.positions.size())
        fail(fmt::format("{}: NORMAL and POSITION differ in count", where));
    }
    if (auto color = primitive.attributes.find("COLOR_0"); color != primitive.attributes.end()) {
      const auto& accessor =
          element(gltf_.accessors, color->second, "accessor", where + " COLOR_0");
      const int components =
          tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type));
      if (components != 3 && components != 4)
        fail(fmt::format("{}: COLOR_0 must be VEC3 or VEC4", where));
      const std::vector<double> raw = readAccessor(color->second, components, where + " COLOR_0");
      if (raw.size() / static_cast<std::size_t>(components) != vertexCount)
        fail(fmt::format("{}: COLOR_0 and POSITION differ in count", where));
      data.colors.resize(4 * vertexCount, 1.0);
      for (std::size_t v = 0; v < vertexCount; ++v) {
        for (int k = 0; k < components; ++k)
          data.colors[4 * v + static_cast<std::size_t>(k)] =
              raw[v * static_cast<std::size_t>(components) + static_cast<std::size_t>(k)];
      }
    }
    data.uvs = readUvs(primitive, vertexCount, where);
    std::vector<std::uint32_t> indices;
    if (primitive.indices >= 0) {
      const auto& accessor =
          element(gltf_.accessors, primitive.indices, "accessor", where + " indices");
      if (accessor.componentType != kUnsignedByte && accessor.componentType != kUnsignedShort &&
          accessor.componentType != kUnsignedInt)
        fail(fmt::format("{}: indices must be unsigned integers", where));
      const std::vector<double> raw = readAccessor(primitive.indices, 1, where + " indices");
      indices.reserve(raw.size());
      for (double i : raw) {
        if (i >= static_cast<double>(vertexCount))
          fail(fmt::format("{}: index {} out of range ({} vertices)", where, i, vertexCount));
        indices.push_back(static_cast<std::uint32_t>(i));
      }
    } else {
      if (vertexCount > std::numeric_limits<std::uint32_t>::max())
        fail(fmt::format("{}: too many vertices", where));
      indices.resize(vertexCount);
      for (std::uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
    }
    if (mode != kModePoints) data.triangles = toTriangles(indices, mode);
    return data;
  }

  // The TEXCOORD set the primitive's texture reads (2 per vertex), or nothing when it has no
  // texture; a textured primitive without them is a warning (its texture's corner is drawn).
  std::vector<double> readUvs(const tinygltf::Primitive& primitive, std::size_t vertexCount,
                              const std::string& where) {
    if (!texturing_.textured(primitive.material)) return {};
    const std::string semantic = fmt::format(
        "TEXCOORD_{}", texturing_.texCoord[static_cast<std::size_t>(primitive.material)]);
    const auto found = primitive.attributes.find(semantic);
    if (found == primitive.attributes.end()) {
      if (warnings_)
        warnings_->push_back(
            fmt::format("{}: {}: a textured primitive without {}; it is drawn in "
                        "its texture's corner colour",
                        name_, where, semantic));
      return {};
    }
    std::vector<double> uvs = readAccessor(found->second, 2, where + " " + semantic);
    if (uvs.size() != 2 * vertexCount)
      fail(fmt::format("{}: {} and POSITION differ in count", where, semantic));
    for (double& x : uvs) {
      if (!std::isfinite(x)) x = 0;
    }
    return uvs;
  }

  static std::vector<std::uint32_t> toTriangles(const std::vector<std::uint32_t>& indices,
                                                int mode) {
    if (mode == kModeTriangles) {
      std::vector<std::uint32_t> triangles(
          indices.begin(), indices.begin() + static_cast<std::ptrdiff_t>(indices.size() / 3 * 3));
      return triangles;
    }
    std::vector<std::uint32_t> triangles;
    for (std::size_t i = 2; i < indices.size(); ++i) {
      if (mode == kModeFan) {
        triangles.insert(triangles.end(), {indices[0], indices[i - 1], indices[i]});
      } else if (i % 2 == 0) {  // strips alternate winding
        triangles.insert(triangles.end(), {indices[i - 2], indices[i - 1], indices[i]});
      } else {
        triangles.insert(triangles.end(), {indices[i - 1], indices[i - 2], indices[i]});
      }
    }
    return triangles;
  }

  PrimitiveData decodeDraco(const tinygltf::Primitive& primitive, const std::string& where) {
    const tinygltf::Value& ext = primitive.extensions.at("KHR_draco_mesh_compression");
    const std::string what = where + " KHR_draco_mesh_compression";
    if (!ext.Has("bufferView") || !ext.Has("attributes"))
      fail(fmt::format("{}: missing bufferView or attributes", what));
    const int viewIndex = ext.Get("bufferView").GetNumberAsInt();
    const auto& view = element(gltf_.bufferViews, viewIndex, "bufferView", what);
    const auto& buffer = element(gltf_.buffers, view.buffer, "buffer", what);
    if (view.byteOffset > buffer.data.size() ||
        view.byteLength > buffer.data.size() - view.byteOffset)
      fail(fmt::format("{}: bufferView {} lies outside its buffer", what, viewIndex));
    draco::DecoderBuffer input;
    input.Init(reinterpret_cast<const char*>(buffer.data.data() + view.byteOffset),
               view.byteLength);
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&input);
    if (!decoded.ok())
      fail(fmt::format("{}: Draco cannot decode: {}", what, decoded.status().error_msg_string()));
    const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
    const tinygltf::Value& attributes = ext.Get("attributes");

    auto read = [&](const char* semantic, int components, std::vector<double>& out) {
      if (!attributes.Has(semantic)) return;
      const auto id = static_cast<std::uint32_t>(attributes.Get(semantic).GetNumberAsInt());
      const draco::PointAttribute* attribute = mesh->GetAttributeByUniqueId(id);
      if (!attribute)
        fail(fmt::format("{}: no Draco attribute with id {} for {}", what, id, semantic));
      out.resize(mesh->num_points() * static_cast<std::size_t>(components), 1.0);
      std::array<float, 4> value{};
      for (draco::PointIndex i(0); i < mesh->num_points(); ++i) {
        value.fill(1.0f);
        const int have = std::min<int>(components, attribute->num_components());
        if (!attribute->ConvertValue<float>(attribute->mapped_index(i),
                                            static_cast<std::int8_t>(have), value.data()))
          fail(fmt::format("{}: cannot convert {} of point {}", what, semantic, i.value()));
        for (int k = 0; k < components; ++k)
          out[i.value() * static_cast<std::size_t>(components) + static_cast<std::size_t>(k)] =
              static_cast<double>(value[static_cast<std::size_t>(k)]);
      }
    };
    PrimitiveData data;
    read("POSITION", 3, data.positions);
    if (data.positions.empty()) fail(fmt::format("{}: no POSITION attribute", what));
    read("NORMAL", 3, data.normals);
    read("COLOR_0", 4, data.colors);
    if (texturing_.textured(primitive.material))
      read(fmt::format("TEXCOORD_{}",
                       texturing_.texCoord[static_cast<std::size_t>(primitive.material)])
               .c_str(),
           2, data.uvs);
    data.triangles.reserve(mesh->num_faces() * 3);
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
      const auto& face = mesh->face(f);
      for (std::size_t k = 0; k < 3; ++k) data.triangles.push_back(face[k].value());
    }
    return data;
  }

  // World coordinates become float offsets from one double origin.
  void placeAtOrigin() {
    lodforge::placeAtOrigin(model_, world_);
    // Normals only when every vertex has one; partial normals would mislead more than help.
    if (!missingNormals_ && !normalsByVertex_.empty()) model_.normals = std::move(normalsByVertex_);
  }

  const tinygltf::Model& gltf_;
  const std::string& name_;
  std::uint64_t binOffset_;
  std::uint64_t fileBinBytes_;
  std::string baseDir_;  // where external images lie; empty: none may be read
  std::vector<std::string>* warnings_;
  struct Skipped {
    std::uint64_t primitives = 0, vertices = 0;
  };
  Skipped skippedPoints_, skippedLines_;
  GltfTexturing texturing_;
  Model model_;
  std::vector<Vec3d> world_;
  std::vector<Vec3f> normalsByVertex_;
  std::vector<bool> visited_;
  LayerTable layers_{model_.layers};
  bool withColors_ = false;
  bool withUvs_ = false;
  bool missingNormals_ = false;
  bool pointsOnly_ = false;  // drawsPointsOnly()
};

// Draco primitives name an indices accessor without a bufferView (the data is in the Draco
// stream), which Debian's tinygltf, built without Draco, rejects. The reader takes indices from
// the Draco stream anyway, so drop the reference before tinygltf sees it. Returns the rewritten
// file, or nothing when no primitive is Draco-compressed.
Result<std::optional<std::string>> withoutDracoIndices(std::span<const std::byte> bytes,
                                                       const std::string& name, bool glb) {
  const std::string_view all(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::uint32_t jsonLength = 0;
  if (glb) std::memcpy(&jsonLength, bytes.data() + 12, 4);
  const std::string_view text = glb ? all.substr(20, jsonLength) : all;
  if (text.find("KHR_draco_mesh_compression") == std::string_view::npos)
    return std::optional<std::string>();
  nlohmann::json document = nlohmann::json::parse(text, nullptr, false);
  if (document.is_discarded())
    return badInputAtByte(name, glb ? 20 : 0, "the glTF JSON does not parse");
  bool changed = false;
  if (document.contains("meshes") && document["meshes"].is_array()) {
    for (auto& mesh : document["meshes"]) {
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
        continue;
      for (auto& primitive : mesh["primitives"]) {
        if (primitive.is_object() && primitive.contains("extensions") &&
            primitive["extensions"].is_object() &&
            primitive["extensions"].contains("KHR_draco_mesh_compression") &&
            primitive.contains("indices")) {
          primitive.erase("indices");
          changed = true;
        }
      }
    }
  }
  if (!changed) return std::optional<std::string>();
  std::string json = document.dump();
  if (!glb) return std::optional<std::string>(std::move(json));
  Result<std::string> out = glbWithJson(std::move(json), {all.substr(20 + jsonLength)}, name);
  if (!out) return out.status();
  return std::optional<std::string>(std::move(*out));
}

// The GLB as tinygltf is given it: its container checked (`binOffset`: where the BIN chunk's
// data starts in the original file, `fileBinLength` bytes; `binLength`: its length once meshopt
// views are decoded after them), EXT_meshopt_compression views decoded, Draco primitives'
// indices dropped, and kTinygltfOverread zero bytes after the end.
Result<std::string> glbForTinygltf(std::span<const std::byte> bytes, const std::string& name,
                                   std::uint64_t& binOffset, std::uint64_t& binLength,
                                   std::uint64_t& fileBinLength) {
  LODFORGE_TRY(checkGlbContainer(bytes, name, binOffset, binLength));
  fileBinLength = binLength;
  Result<std::optional<std::string>> decoded =
      withMeshoptDecoded(bytes, name, binOffset, binLength);
  if (!decoded) return decoded.status();
  // Decoded views follow the original BIN chunk, whose bytes stay where they were.
  std::span<const std::byte> glb = bytes;
  if (*decoded) {
    glb = std::as_bytes(std::span<const char>(**decoded));
    std::uint64_t decodedBinOffset = 0;
    LODFORGE_TRY(checkGlbContainer(glb, name, decodedBinOffset, binLength));
  }
  Result<std::optional<std::string>> rewritten = withoutDracoIndices(glb, name, true);
  if (!rewritten) return rewritten.status();
  // A new JSON length changes no offset reported: they count from the original BIN chunk.
  std::string copy = *rewritten ? std::move(**rewritten)
                     : *decoded
                         ? std::move(**decoded)
                         : std::string(reinterpret_cast<const char*>(glb.data()), glb.size());
  copy.append(kTinygltfOverread, '\0');
  return copy;
}

Result<Model> parse(std::span<const std::byte> bytes, const std::string& name,
                    const std::string& baseDir, const GltfReadOptions& options) {
  if (bytes.size() > std::numeric_limits<unsigned>::max())
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: glTF files over 4 GiB are not supported", name)};
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keepEncodedImage, nullptr);
  if (!options.allowExternalFiles) {
    loader.SetFsCallbacks({refuseFileExists, keepPath, refuseRead, refuseWrite, nullptr});
  }
  tinygltf::Model gltf;
  std::string errors, warnings;
  std::uint64_t binOffset = 0, binLength = 0, fileBinLength = 0;
  bool ok = false;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  // tinygltf throws (nlohmann::json conversions of out-of-range numbers) on some bad files.
  try {
    std::uint32_t magic = 0;
    if (bytes.size() >= 4) std::memcpy(&magic, bytes.data(), 4);
    if (magic == kGlbMagic) {
      Result<std::string> copy = glbForTinygltf(bytes, name, binOffset, binLength, fileBinLength);
      if (!copy) return copy.status();
      const std::size_t size = copy->size() - kTinygltfOverread;
      ok = loader.LoadBinaryFromMemory(&gltf, &errors, &warnings,
                                       reinterpret_cast<const unsigned char*>(copy->data()),
                                       static_cast<unsigned>(size), baseDir);
      if (ok && !gltf.buffers.empty() && gltf.buffers[0].uri.empty() &&
          gltf.buffers[0].data.size() > binLength)
        return badInputAtByte(name, binOffset - 8,
                              fmt::format("buffer 0 declares {} bytes but the BIN chunk holds {}",
                                          gltf.buffers[0].data.size(), binLength));
    } else {
      const auto first = std::find_if(bytes.begin(), bytes.end(), [](std::byte b) {
        return !std::isspace(static_cast<unsigned char>(b));
      });
      if (first == bytes.end() || *first != std::byte{'{'})
        return badInputAtByte(name, 0, "neither GLB (magic 'glTF') nor glTF JSON");
      Result<std::optional<std::string>> rewritten = withoutDracoIndices(bytes, name, false);
      if (!rewritten) return rewritten.status();
      const std::string_view text =
          *rewritten ? std::string_view(**rewritten)
                     : std::string_view(reinterpret_cast<const char*>(data), bytes.size());
      ok = loader.LoadASCIIFromString(&gltf, &errors, &warnings, text.data(),
                                      static_cast<unsigned>(text.size()), baseDir);
    }
  } catch (const std::exception& e) {
    return badInput(name, fmt::format("tinygltf cannot parse the file: {}", e.what()));
  }
  if (!ok) {
    while (!errors.empty() && (errors.back() == '\n' || errors.back() == ' ')) errors.pop_back();
    for (char& c : errors) {
      if (c == '\n') c = ';';
    }
    return badInput(name, errors.empty() ? std::string("tinygltf cannot parse the file") : errors);
  }
  try {
    Loader builder(gltf, name, binOffset, fileBinLength,
                   options.allowExternalFiles ? baseDir : std::string(), options.warnings);
    return builder.load();
  } catch (const ErrorException& e) {
    return e.error;
  }
}

}  // namespace

Result<Model> readGltf(const std::string& path, const GltfReadOptions& options) {
  Result<std::string> text = readFileToString(path, std::numeric_limits<unsigned>::max());
  if (!text) return text.status();
  std::string baseDir = std::filesystem::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(text->data()),
                                         text->size());
  return parse(bytes, path, baseDir, options);
}

Result<Model> readGltfFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                 const GltfReadOptions& options) {
  return parse(bytes, name, "", options);
}

}  // namespace lodforge
