#include "lodforge/io/mesh/glb_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/instances.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/glb_container.h"
#include "lodforge/io/mesh/gltf_constants.h"
#include "lodforge/io/mesh/vertex_codec.h"

namespace lodforge {

namespace {
using namespace gltf;  // the component types, buffer targets and chunk magics
constexpr const char* kGenerator = "lodforge " LODFORGE_VERSION;
std::size_t elementBytes(int componentType, std::string_view type) {
  const std::size_t component = componentType == kByte || componentType == kUnsignedByte     ? 1
                                : componentType == kShort || componentType == kUnsignedShort ? 2
                                                                                             : 4;
  const std::size_t components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
  return component * components;
}

}  // namespace

double glbQuantizationStep(const Aabbd& bounds) {
  const double side = bounds.longestSide();
  return side > 0 ? side / 65535.0 : 1.0;
}

double glbQuantizationError(const Aabbd& bounds) {
  return bounds.longestSide() > 0 ? 0.5 * std::sqrt(3.0) * glbQuantizationStep(bounds) : 0.0;
}

struct GlbWriter::State {
  std::string path;
  GlbWriteOptions options;
  nlohmann::json accessors = nlohmann::json::array();
  nlohmann::json bufferViews = nlohmann::json::array();
  nlohmann::json meshes = nlohmann::json::array();
  nlohmann::json materials = nlohmann::json::array();
  nlohmann::json images = nlohmann::json::array();
  nlohmann::json samplers = nlohmann::json::array();
  nlohmann::json textures = nlohmann::json::array();
  bool webp = false;  // a texture uses EXT_texture_webp
  nlohmann::json nodes = nlohmann::json::array();
  std::string structuralMetadata;  // EXT_structural_metadata at the root, when set
  bool meshFeatures = false;       // a primitive uses EXT_mesh_features
  std::vector<std::uint32_t> rootChildren;
  std::vector<std::vector<std::uint32_t>> children;  // per node, those added under it
  std::optional<Vec3d> rootTranslation;
  std::string rootName = "root";
  std::optional<std::uint32_t> defaultMaterial;
  // Per mesh: the grid of its quantised positions (origin, step), for the nodes that draw it.
  std::vector<std::optional<std::pair<Vec3d, double>>> dequantize;

  // A mesh's vertex attributes into `attributes`; its indices (the accessor).
  Status addQuantizedAttributes(const GlbMeshData& mesh, const Aabb& bounds,
                                nlohmann::json& attributes);
  Status addFloatAttributes(const GlbMeshData& mesh, const Aabb& bounds,
                            nlohmann::json& attributes);
  Status addColors(const GlbMeshData& mesh, nlohmann::json& attributes);
  Status addUvs(const GlbMeshData& mesh, nlohmann::json& attributes);
  // finish()'s steps: the scene, the geometry's and the appearance's parts of the document,
  // and the file.
  nlohmann::json sceneDocument();
  void addGeometry(nlohmann::json& document);
  void addAppearance(nlohmann::json& document);
  Status writeFile(const std::string& json);
  Status addExtraAttributes(const GlbMeshData& mesh, nlohmann::json& attributes);
  Result<std::uint32_t> addIndices(const GlbMeshData& mesh);
  // A primitive over `attributes` drawing the mesh's indices with `material` (default: white).
  Result<nlohmann::json> primitive(const GlbMeshData& mesh, const nlohmann::json& attributes,
                                   std::optional<std::uint32_t> material, GlbWriter& writer);
  // Binary chunk: in memory until it exceeds options.spillBytes, then appended to `spill`.
  std::vector<std::byte> binary;
  std::optional<OutputFile> spill;
  std::string spillPath;
  std::uint64_t binaryBytes = 0;    // total, memory + spilled
  std::uint64_t fallbackBytes = 0;  // meshopt: the uncompressed layout the views describe
  std::vector<std::byte> scratch;
  std::unique_ptr<std::byte[]> encodeBuffer;  // EXT_meshopt_compression: a view's encoding
  std::size_t encodeCapacity = 0;

  // Room for a mesh's views at once (a tile's binary grew by doubling, copying its bytes about
  // twice), growing geometrically still for writers of many meshes; at most what stays in
  // memory before spilling.
  void reserveFor(const GlbMeshData& mesh) {
    const std::size_t n = mesh.positions.size();
    const std::size_t position = mesh.quantized ? 8 : 12, normal = mesh.quantized ? 4 : 12;
    const bool normals = !mesh.normals.empty() || !mesh.packedNormals.empty();
    const std::size_t bytes = n * position + (normals ? n * normal : 0) +
                              n * (mesh.colors.empty() ? 0 : 4) + n * (mesh.uvs.empty() ? 0 : 8) +
                              n * 4 * mesh.extraAttributes.size() + mesh.indices.size() * 4;
    const std::size_t want = binary.size() + bytes;
    if (want > binary.capacity())
      binary.reserve(std::min(std::max(want, 2 * binary.capacity()), options.spillBytes + 4));
  }

  Status appendBinary(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const std::byte*>(data);
    binary.insert(binary.end(), bytes, bytes + size);
    binaryBytes += size;
    // Keep every view 4-byte aligned (glTF requires it for 4-byte components).
    while (binaryBytes % 4 != 0) {
      binary.push_back(std::byte{0});
      ++binaryBytes;
    }
    if (binary.size() > options.spillBytes) {
      if (!spill) {
        spillPath = temporaryPathFor(path) + ".bin";
        Result<OutputFile> file = OutputFile::create(spillPath);
        if (!file) return file.status();
        spill.emplace(std::move(file.value()));
      }
      LODFORGE_TRY(spill->write(binary.data(), binary.size()));
      binary.clear();
    }
    return {};
  }

  // Room for a view's encoding, left uninitialised (a vector would zero its whole bound first).
  std::span<std::byte> encodeRoom(std::size_t bound) {
    if (bound > encodeCapacity) {
      encodeBuffer.reset(new std::byte[bound]);
      encodeCapacity = bound;
    }
    return {encodeBuffer.get(), bound};
  }
  std::span<const std::byte> encodeIndices(std::span<const std::uint32_t> indices,
                                           std::size_t vertices) {
    const std::span<std::byte> room =
        encodeRoom(meshopt_encodeIndexBufferBound(indices.size(), vertices));
    return room.first(meshopt_encodeIndexBuffer(reinterpret_cast<unsigned char*>(room.data()),
                                                room.size(), indices.data(), indices.size()));
  }
  // Our encoder: the same bytes as meshopt_encodeVertexBuffer, 3 to 7 times as fast.
  std::span<const std::byte> encodeVertices(const void* data, std::size_t count,
                                            std::size_t stride) {
    const std::span<std::byte> room = encodeRoom(vertexAttributesBound(count, stride));
    return room.first(encodeVertexAttributes(room, data, count, stride));
  }

  // Writes one view + accessor; returns the accessor index. `stride` is one element's size.
  // Indices (`target` kElementArrayBuffer) come as `wideIndices`, the 32-bit values the index
  // codec reads whatever size they decode to, with `vertices` bounding them; `data` then holds
  // them at `stride` bytes each for the uncompressed layout (unused when compressing).
  Result<std::uint32_t> addAccessor(const void* data, std::size_t bytes, std::size_t count,
                                    int componentType, const char* type, int target,
                                    bool normalized, const nlohmann::json* min,
                                    const nlohmann::json* max, std::size_t stride,
                                    std::span<const std::uint32_t> wideIndices = {},
                                    std::size_t vertices = 0) {
    nlohmann::json view;
    if (options.meshoptCompression) {
      const bool triangles = target == kElementArrayBuffer;
      const std::span<const std::byte> encoded =
          triangles ? encodeIndices(wideIndices.first(count), vertices)
                    : encodeVertices(data, count, stride);
      const std::uint64_t offset = binaryBytes;
      LODFORGE_TRY(appendBinary(encoded.data(), encoded.size()));
      view = {{"buffer", 1},
              {"byteOffset", fallbackBytes},
              {"byteLength", bytes},
              {"target", target},
              {"extensions",
               {{"EXT_meshopt_compression",
                 {{"buffer", 0},
                  {"byteOffset", offset},
                  {"byteLength", encoded.size()},
                  {"byteStride", stride},
                  {"mode", triangles ? "TRIANGLES" : "ATTRIBUTES"},
                  {"count", count}}}}}};
      if (!triangles) view["byteStride"] = stride;
      fallbackBytes += (bytes + 3) / 4 * 4;
    } else {
      const std::uint64_t offset = binaryBytes;
      LODFORGE_TRY(appendBinary(data, bytes));
      view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}};
      // Padded elements (a quantised vec3 in 4 or 8 bytes) need their stride spelled out.
      if (target == kArrayBuffer && stride != elementBytes(componentType, type))
        view["byteStride"] = stride;
    }
    bufferViews.push_back(std::move(view));
    nlohmann::json accessor = {{"bufferView", bufferViews.size() - 1},
                               {"componentType", componentType},
                               {"count", count},
                               {"type", type}};
    if (normalized) accessor["normalized"] = true;
    if (min) accessor["min"] = *min;
    if (max) accessor["max"] = *max;
    accessors.push_back(std::move(accessor));
    return static_cast<std::uint32_t>(accessors.size() - 1);
  }
};

GlbWriter::GlbWriter(std::unique_ptr<State> state) : state_(std::move(state)) {}
GlbWriter::GlbWriter(GlbWriter&&) noexcept = default;
GlbWriter& GlbWriter::operator=(GlbWriter&&) noexcept = default;
GlbWriter::~GlbWriter() = default;

Result<GlbWriter> GlbWriter::create(const std::string& path, const GlbWriteOptions& options) {
  auto state = std::make_unique<State>();
  state->path = path;
  state->options = options;
  return GlbWriter(std::move(state));
}

std::uint32_t GlbWriter::addMaterial(const std::array<float, 4>& baseColor, std::string_view name) {
  // Dielectric and fairly rough: the default glTF material (metallic 1) renders black without
  // an environment map, which is what most viewers have for CAD data.
  nlohmann::json material = {
      {"pbrMetallicRoughness",
       {{"baseColorFactor", {baseColor[0], baseColor[1], baseColor[2], baseColor[3]}},
        {"metallicFactor", 0.0},
        {"roughnessFactor", 0.7}}}};
  if (state_->options.doubleSided) material["doubleSided"] = true;
  if (baseColor[3] < 1.0f) material["alphaMode"] = "BLEND";
  if (!name.empty()) material["name"] = std::string(name);
  state_->materials.push_back(std::move(material));
  return static_cast<std::uint32_t>(state_->materials.size() - 1);
}

std::uint32_t GlbWriter::addMaterial(const Material& m, std::optional<std::uint32_t> texture) {
  nlohmann::json material = {{"pbrMetallicRoughness",
                              {{"baseColorFactor", m.baseColor},
                               {"metallicFactor", m.metallic},
                               {"roughnessFactor", m.roughness}}}};
  if (texture) material["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", *texture}};
  if (m.doubleSided) material["doubleSided"] = true;
  if (m.alphaMode != AlphaMode::kOpaque) material["alphaMode"] = alphaModeName(m.alphaMode);
  if (m.alphaMode == AlphaMode::kMask) material["alphaCutoff"] = m.alphaCutoff;
  if (m.emissive != std::array<float, 3>{0, 0, 0}) material["emissiveFactor"] = m.emissive;
  if (!m.name.empty()) material["name"] = m.name;
  state_->materials.push_back(std::move(material));
  return static_cast<std::uint32_t>(state_->materials.size() - 1);
}

std::array<std::int8_t, 4> glbPackNormal(Vec3f normal) {
  const Vec3f n = normalizeOr(normal, Vec3f{0, 0, 1});
  const float axes[3] = {n.x, n.y, n.z};
  std::array<std::int8_t, 4> packed{};
  for (std::size_t a = 0; a < 3; ++a)
    packed[a] = static_cast<std::int8_t>(roundToLong(axes[a] * 127.0f));
  return packed;
}

Status GlbWriter::State::addQuantizedAttributes(const GlbMeshData& mesh, const Aabb& bounds,
                                                nlohmann::json& attributes) {
  const std::size_t vertexCount = mesh.positions.size();
  // KHR_mesh_quantization: integer positions on a uniform grid (a uniform scale leaves the
  // normals' directions alone), padded to 8 bytes; normals as normalised bytes, padded to 4.
  const Aabbd box{toDouble(bounds.min), toDouble(bounds.max)};
  const double step = glbQuantizationStep(box);
  std::vector<std::uint16_t> grid(vertexCount * 4, 0);
  std::array<std::uint16_t, 3> lo{65535, 65535, 65535}, hi{0, 0, 0};
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const Vec3d p = (toDouble(mesh.positions[v]) - box.min) * (1.0 / step);
    const double axes[3] = {p.x, p.y, p.z};
    for (std::size_t a = 0; a < 3; ++a) {
      const auto q = static_cast<std::uint16_t>(std::clamp(roundHalfAway(axes[a]), 0L, 65535L));
      grid[4 * v + a] = q;
      lo[a] = std::min(lo[a], q);
      hi[a] = std::max(hi[a], q);
    }
  }
  const nlohmann::json min = lo, max = hi;
  Result<std::uint32_t> position =
      addAccessor(grid.data(), grid.size() * 2, vertexCount, kUnsignedShort, "VEC3", kArrayBuffer,
                  false, &min, &max, 8);
  if (!position) return position.status();
  attributes["POSITION"] = *position;
  dequantize.emplace_back(std::pair{box.min, step});
  if (!mesh.normals.empty() || !mesh.packedNormals.empty()) {
    std::vector<std::array<std::int8_t, 4>> packing;
    if (mesh.packedNormals.empty()) {
      packing.resize(vertexCount);
      for (std::size_t v = 0; v < vertexCount; ++v) packing[v] = glbPackNormal(mesh.normals[v]);
    }
    const std::span<const std::array<std::int8_t, 4>> packed =
        mesh.packedNormals.empty() ? packing : mesh.packedNormals;
    Result<std::uint32_t> normal =
        addAccessor(packed.data(), packed.size_bytes(), vertexCount, kByte, "VEC3", kArrayBuffer,
                    true, nullptr, nullptr, 4);
    if (!normal) return normal.status();
    attributes["NORMAL"] = *normal;
  }
  return {};
}

Status GlbWriter::State::addFloatAttributes(const GlbMeshData& mesh, const Aabb& bounds,
                                            nlohmann::json& attributes) {
  const std::size_t vertexCount = mesh.positions.size();
  const nlohmann::json min = {bounds.min.x, bounds.min.y, bounds.min.z};
  const nlohmann::json max = {bounds.max.x, bounds.max.y, bounds.max.z};
  Result<std::uint32_t> position =
      addAccessor(mesh.positions.data(), mesh.positions.size_bytes(), vertexCount, kFloat, "VEC3",
                  kArrayBuffer, false, &min, &max, sizeof(Vec3f));
  if (!position) return position.status();
  attributes["POSITION"] = *position;
  dequantize.emplace_back(std::nullopt);
  if (!mesh.normals.empty()) {
    // The validator requires unit normals; fix up zero or unnormalised ones here.
    std::vector<Vec3f> unit(mesh.normals.begin(), mesh.normals.end());
    for (Vec3f& n : unit) n = normalizeOr(n, Vec3f{0, 0, 1});
    Result<std::uint32_t> normal =
        addAccessor(unit.data(), unit.size() * sizeof(Vec3f), vertexCount, kFloat, "VEC3",
                    kArrayBuffer, false, nullptr, nullptr, sizeof(Vec3f));
    if (!normal) return normal.status();
    attributes["NORMAL"] = *normal;
  }
  return {};
}

Status GlbWriter::State::addColors(const GlbMeshData& mesh, nlohmann::json& attributes) {
  const std::size_t vertexCount = mesh.positions.size();
  if (!mesh.colors.empty()) {
    Result<std::uint32_t> color =
        addAccessor(mesh.colors.data(), mesh.colors.size_bytes(), vertexCount, kUnsignedByte,
                    "VEC4", kArrayBuffer, true, nullptr, nullptr, sizeof(Rgba8));
    if (!color) return color.status();
    attributes["COLOR_0"] = *color;
  }
  return {};
}

Status GlbWriter::State::addUvs(const GlbMeshData& mesh, nlohmann::json& attributes) {
  if (mesh.uvs.empty()) return {};
  Result<std::uint32_t> uv =
      addAccessor(mesh.uvs.data(), mesh.uvs.size_bytes(), mesh.uvs.size(), kFloat, "VEC2",
                  kArrayBuffer, false, nullptr, nullptr, sizeof(Vec2f));
  if (!uv) return uv.status();
  attributes["TEXCOORD_0"] = *uv;
  return {};
}

Result<std::uint32_t> GlbWriter::addTexture(std::span<const std::byte> encoded, ImageFormat format,
                                            TextureWrap wrapS, TextureWrap wrapT) {
  assert(format != ImageFormat::kUnknown && !encoded.empty());
  State& s = *state_;
  Result<std::uint32_t> view = addBufferView(encoded);
  if (!view) return view.status();
  s.images.push_back({{"bufferView", *view}, {"mimeType", std::string(mimeTypeOf(format))}});
  const nlohmann::json sampler = {{"magFilter", 9729},  // LINEAR
                                  {"minFilter", 9987},  // LINEAR_MIPMAP_LINEAR
                                  {"wrapS", wrapModeCode(wrapS)},
                                  {"wrapT", wrapModeCode(wrapT)}};
  auto found = std::find(s.samplers.begin(), s.samplers.end(), sampler);
  if (found == s.samplers.end()) {
    s.samplers.push_back(sampler);
    found = s.samplers.end() - 1;
  }
  nlohmann::json texture = {{"sampler", found - s.samplers.begin()}};
  if (format == ImageFormat::kWebp) {
    texture["extensions"]["EXT_texture_webp"] = {{"source", s.images.size() - 1}};
    s.webp = true;
  } else {
    texture["source"] = s.images.size() - 1;
  }
  s.textures.push_back(std::move(texture));
  return static_cast<std::uint32_t>(s.textures.size() - 1);
}

Status GlbWriter::State::addExtraAttributes(const GlbMeshData& mesh, nlohmann::json& attributes) {
  const std::size_t vertexCount = mesh.positions.size();
  for (const GlbVertexAttribute& extra : mesh.extraAttributes) {
    assert(extra.data.size() == 4 * vertexCount && extra.semantic.starts_with('_'));
    Result<std::uint32_t> index =
        addAccessor(extra.data.data(), extra.data.size(), vertexCount, extra.componentType,
                    "SCALAR", kArrayBuffer, false, nullptr, nullptr, 4);
    if (!index) return index.status();
    attributes[extra.semantic] = *index;
  }
  return {};
}

// 16-bit indices when they fit; 65535 itself is the primitive-restart value glTF forbids.
Result<std::uint32_t> GlbWriter::State::addIndices(const GlbMeshData& mesh) {
  const std::size_t vertexCount = mesh.positions.size();
  if (mesh.points) return 0u;  // unused
  if (vertexCount < 65535) {
    // Narrowed only for the uncompressed layout (the meshopt codec takes the 32-bit ones).
    scratch.resize(options.meshoptCompression ? 0 : mesh.indices.size() * 2);
    for (std::size_t i = 0; i < scratch.size() / 2; ++i) {
      const auto v = static_cast<std::uint16_t>(mesh.indices[i]);
      std::memcpy(scratch.data() + 2 * i, &v, 2);
    }
    return addAccessor(scratch.data(), mesh.indices.size() * 2, mesh.indices.size(), kUnsignedShort,
                       "SCALAR", kElementArrayBuffer, false, nullptr, nullptr, 2, mesh.indices,
                       vertexCount);
  }
  return addAccessor(mesh.indices.data(), mesh.indices.size_bytes(), mesh.indices.size(),
                     kUnsignedInt, "SCALAR", kElementArrayBuffer, false, nullptr, nullptr, 4,
                     mesh.indices, vertexCount);
}

Result<std::uint32_t> GlbWriter::addBufferView(std::span<const std::byte> bytes) {
  State& s = *state_;
  if (s.binaryBytes % 8 != 0) {  // appendBinary keeps 4-byte alignment
    const std::uint32_t pad = 0;
    LODFORGE_TRY(s.appendBinary(&pad, sizeof pad));
  }
  const std::uint64_t offset = s.binaryBytes;
  LODFORGE_TRY(s.appendBinary(bytes.data(), bytes.size()));
  s.bufferViews.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes.size()}});
  return static_cast<std::uint32_t>(s.bufferViews.size() - 1);
}

void GlbWriter::setStructuralMetadata(std::string json) {
  state_->structuralMetadata = std::move(json);
}

Result<std::uint32_t> GlbWriter::addMesh(const GlbMeshData& mesh, std::string_view name,
                                         std::optional<std::uint32_t> material) {
  State& s = *state_;
  assert(!mesh.positions.empty());
  assert(mesh.points ? mesh.indices.empty()
                     : (!mesh.indices.empty() && mesh.indices.size() % 3 == 0));
  assert(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size());
  assert(mesh.packedNormals.empty() || (mesh.quantized && mesh.normals.empty() &&
                                        mesh.packedNormals.size() == mesh.positions.size()));
  assert(mesh.colors.empty() || mesh.colors.size() == mesh.positions.size());
  assert(mesh.uvs.empty() || mesh.uvs.size() == mesh.positions.size());
  Aabb bounds;
  for (const Vec3f& p : mesh.positions) bounds.add(p);
  s.reserveFor(mesh);
  nlohmann::json attributes;
  if (mesh.quantized) {
    LODFORGE_TRY(s.addQuantizedAttributes(mesh, bounds, attributes));
  } else {
    LODFORGE_TRY(s.addFloatAttributes(mesh, bounds, attributes));
  }
  LODFORGE_TRY(s.addColors(mesh, attributes));
  LODFORGE_TRY(s.addUvs(mesh, attributes));
  LODFORGE_TRY(s.addExtraAttributes(mesh, attributes));
  // One primitive, or one per group of indices (each with its material) over the same vertices.
  const GlbPrimitive whole{static_cast<std::uint32_t>(mesh.indices.size()), material};
  const std::span<const GlbPrimitive> groups =
      mesh.primitives.empty() ? std::span<const GlbPrimitive>(&whole, 1) : mesh.primitives;
  nlohmann::json primitives = nlohmann::json::array();
  std::size_t first = 0;
  for (const GlbPrimitive& group : groups) {
    GlbMeshData part = mesh;
    part.indices = mesh.indices.subspan(first, mesh.points ? 0 : group.indexCount);
    first += group.indexCount;
    Result<nlohmann::json> primitive = s.primitive(part, attributes, group.material, *this);
    if (!primitive) return primitive.status();
    primitives.push_back(std::move(*primitive));
  }
  assert(mesh.points || first == mesh.indices.size());
  nlohmann::json entry = {{"primitives", std::move(primitives)}};
  if (!name.empty()) entry["name"] = std::string(name);
  s.meshes.push_back(std::move(entry));
  return static_cast<std::uint32_t>(s.meshes.size() - 1);
}

Result<nlohmann::json> GlbWriter::State::primitive(const GlbMeshData& mesh,
                                                   const nlohmann::json& attributes,
                                                   std::optional<std::uint32_t> material,
                                                   GlbWriter& writer) {
  State& s = *this;
  Result<std::uint32_t> indices = s.addIndices(mesh);
  if (!indices) return indices.status();
  if (!material) {
    if (!s.defaultMaterial) s.defaultMaterial = writer.addMaterial({1, 1, 1, 1}, "default");
    material = s.defaultMaterial;
  }
  nlohmann::json primitive = {{"attributes", attributes}, {"mode", 4}, {"material", *material}};
  if (mesh.propertyAttribute)
    primitive["extensions"]["EXT_structural_metadata"]["propertyAttributes"] = {
        *mesh.propertyAttribute};
  if (mesh.featureIds) {
    assert(std::any_of(mesh.extraAttributes.begin(), mesh.extraAttributes.end(),
                       [](const GlbVertexAttribute& a) { return a.semantic == "_FEATURE_ID_0"; }));
    primitive["extensions"]["EXT_mesh_features"]["featureIds"] = {
        {{"featureCount", mesh.featureIds->featureCount},
         {"attribute", 0},
         {"propertyTable", mesh.featureIds->propertyTable}}};
    s.meshFeatures = true;
  }
  if (mesh.points) {
    primitive["mode"] = 0;
  } else {
    primitive["indices"] = *indices;
  }
  return primitive;
}

namespace {
bool isTranslation(const Mat4d& m) {
  for (int i = 0; i < 12; ++i)
    if (m.m[static_cast<std::size_t>(i)] != (i % 5 == 0 ? 1.0 : 0.0)) return false;
  return m.m[15] == 1.0;
}
}  // namespace

std::uint32_t GlbWriter::addNode(std::string_view name, std::optional<std::uint32_t> mesh,
                                 const Mat4d* transform, std::optional<std::uint32_t> parent,
                                 std::string_view layer) {
  nlohmann::json node = nlohmann::json::object();
  if (!name.empty()) node["name"] = std::string(name);
  if (!layer.empty()) node["extras"] = {{"layer", std::string(layer)}};
  if (mesh) node["mesh"] = *mesh;
  const auto& grid = mesh ? state_->dequantize[*mesh] : std::nullopt;
  if (state_->options.flatScene && transform && isTranslation(*transform)) {
    const Vec3d t{transform->m[12], transform->m[13], transform->m[14]};
    const Vec3d at = grid ? t + grid->first : t;
    node["translation"] = {at.x, at.y, at.z};
    if (grid) node["scale"] = {grid->second, grid->second, grid->second};
  } else if (grid && !transform) {
    // Integer grid coordinates back to the mesh's own units.
    node["translation"] = {grid->first.x, grid->first.y, grid->first.z};
    node["scale"] = {grid->second, grid->second, grid->second};
  } else if (grid) {
    node["matrix"] = (*transform * Mat4d::translation(grid->first) *
                      Mat4d::scale({grid->second, grid->second, grid->second}))
                         .m;
  } else if (transform && transform->m != Mat4d{}.m) {
    node["matrix"] = transform->m;
  }
  const auto index = static_cast<std::uint32_t>(state_->nodes.size());
  state_->nodes.push_back(std::move(node));
  state_->children.emplace_back();
  assert(!parent || *parent < index);
  (parent ? state_->children[*parent] : state_->rootChildren).push_back(index);
  return index;
}

void GlbWriter::setRootName(std::string_view name) {
  state_->rootName = name;
}

void GlbWriter::setRootTranslation(Vec3d translation) {
  state_->rootTranslation = translation;
}

std::uint64_t GlbWriter::binaryBytes() const {
  return state_->binaryBytes;
}

// The node tree with the root node (or, flat, without it) and the scene over it.
nlohmann::json GlbWriter::State::sceneDocument() {
  assert(!options.flatScene || !rootTranslation);
  for (std::size_t n = 0; n < children.size(); ++n)
    if (!children[n].empty()) nodes[n]["children"] = children[n];
  // The root node holds every object node, and the origin offset if there is one.
  nlohmann::json root = {{"name", rootName}};
  if (!rootChildren.empty()) root["children"] = rootChildren;
  if (rootTranslation && *rootTranslation != Vec3d{})
    root["translation"] = {rootTranslation->x, rootTranslation->y, rootTranslation->z};
  nlohmann::json sceneNodes = rootChildren;
  if (!options.flatScene) {
    nodes.push_back(std::move(root));
    sceneNodes = {nodes.size() - 1};
  }
  return {{"asset", {{"version", "2.0"}, {"generator", kGenerator}}},
          {"scene", 0},
          {"scenes", {{{"nodes", sceneNodes}}}},
          {"nodes", std::move(nodes)}};
}

void GlbWriter::State::addGeometry(nlohmann::json& document) {
  if (meshes.empty()) return;
  document["meshes"] = std::move(meshes);
  document["accessors"] = std::move(accessors);
  document["bufferViews"] = std::move(bufferViews);
  document["buffers"] = {{{"byteLength", binaryBytes}}};
  if (options.meshoptCompression) {
    // The views describe an uncompressed buffer that exists only once decoded.
    document["buffers"].push_back(
        {{"byteLength", fallbackBytes},
         {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    document["extensionsUsed"].push_back("EXT_meshopt_compression");
    document["extensionsRequired"].push_back("EXT_meshopt_compression");
  }
  const bool quantized = std::any_of(dequantize.begin(), dequantize.end(),
                                     [](const auto& grid) { return grid.has_value(); });
  if (quantized) {
    document["extensionsUsed"].push_back("KHR_mesh_quantization");
    document["extensionsRequired"].push_back("KHR_mesh_quantization");
  }
}

void GlbWriter::State::addAppearance(nlohmann::json& document) {
  if (!materials.empty()) document["materials"] = std::move(materials);
  if (!textures.empty()) {
    document["images"] = std::move(images);
    document["samplers"] = std::move(samplers);
    document["textures"] = std::move(textures);
    // Every texture is WebP (no fallback image): a viewer without the extension draws nothing.
    if (webp) {
      document["extensionsUsed"].push_back("EXT_texture_webp");
      document["extensionsRequired"].push_back("EXT_texture_webp");
    }
  }
  if (!structuralMetadata.empty()) {
    document["extensions"]["EXT_structural_metadata"] = nlohmann::json::parse(structuralMetadata);
    document["extensionsUsed"].push_back("EXT_structural_metadata");
  }
  if (meshFeatures) document["extensionsUsed"].push_back("EXT_mesh_features");
}

// Header, JSON chunk and binary chunk (the spilled part copied in first), under a temporary name.
Status GlbWriter::State::writeFile(const std::string& json) {
  const bool hasBinary = binaryBytes > 0;
  const std::uint64_t total = 12 + 8 + json.size() + (hasBinary ? 8 + binaryBytes : 0);
  if (total > 0xFFFFFFFFull) {
    return Error{
        ErrorKind::kLimit,
        fmt::format("{}: GLB would be {} bytes; the format's limit is 4 GiB", path, total)};
  }
  // A small buffer for the header and the JSON: the binary chunk is written from memory as it
  // is (a 4 MB buffer zeroed for every tile was 4 % of the point tiles' contents).
  Result<OutputFile> out = OutputFile::create(path, std::size_t{64} << 10);
  if (!out) return out.status();
  const std::array<std::uint32_t, 5> head = glbHead(json.size(), hasBinary ? 8 + binaryBytes : 0);
  LODFORGE_TRY(out->write(head.data(), sizeof head));
  LODFORGE_TRY(out->write(json.data(), json.size()));
  if (hasBinary) {
    const std::array<std::uint32_t, 2> binChunk = binChunkHead(binaryBytes);
    LODFORGE_TRY(out->write(binChunk.data(), sizeof binChunk));
    if (spill) {
      // The spilled part is committed to a side file, copied in, then removed.
      const std::uint64_t spilled = spill->bytesWritten();
      LODFORGE_TRY(spill->commit());
      spill.reset();
      Status copied = out->appendFileContents(spillPath, spilled);
      ::remove(spillPath.c_str());
      LODFORGE_TRY(copied);
    }
    LODFORGE_TRY(out->write(binary.data(), binary.size()));
  }
  return out->commit();
}

Status GlbWriter::finish() {
  State& s = *state_;
  nlohmann::json document = s.sceneDocument();
  s.addGeometry(document);
  s.addAppearance(document);
  // (Names come from inputs and may not be UTF-8: replaced rather than thrown on.)
  std::string json = document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  padGlbJson(json);
  return s.writeFile(json);
}

namespace {

// The nodes above objects with assembly paths: one per distinct prefix, made on first use, so
// "motor/rotor/shaft" and "motor/rotor/key" share "motor" and "rotor".
class AssemblyNodes {
 public:
  // `shared`: the first component every path starts with ("" if none), which the root node
  // stands for.
  AssemblyNodes(GlbWriter& writer, std::string_view shared) : writer_(writer), shared_(shared) {
    if (!shared_.empty()) writer_.setRootName(shared_);
  }

  // The node an object with this path hangs under (none: the root).
  std::optional<std::uint32_t> parentOf(std::string_view path) {
    if (!shared_.empty()) path.remove_prefix(shared_.size() + 1);
    const auto slash = path.rfind('/');
    if (slash == std::string_view::npos) return std::nullopt;
    return nodeFor(path.substr(0, slash));
  }

 private:
  std::uint32_t nodeFor(std::string_view prefix) {
    if (const auto found = nodes_.find(std::string(prefix)); found != nodes_.end())
      return found->second;
    const auto slash = prefix.rfind('/');
    const std::optional<std::uint32_t> parent =
        slash == std::string_view::npos ? std::nullopt
                                        : std::optional(nodeFor(prefix.substr(0, slash)));
    const std::string_view name =
        slash == std::string_view::npos ? prefix : prefix.substr(slash + 1);
    const std::uint32_t node = writer_.addNode(name, std::nullopt, nullptr, parent);
    nodes_.emplace(std::string(prefix), node);
    return node;
  }

  GlbWriter& writer_;
  std::string shared_;
  std::unordered_map<std::string, std::uint32_t> nodes_;
};

// The model's images as the GLB's textures: each written once, embedded (a file's bytes read
// when first used), one texture per image and wrap modes.
class ModelTextures {
 public:
  ModelTextures(const Model& model, GlbWriter& writer) : model_(model), writer_(writer) {}

  bool textured(std::uint32_t material) const {
    return material < model_.materials.size() &&
           model_.materials[material].baseColorImage != kNoImage;
  }

  Result<std::optional<std::uint32_t>> of(const Material& material) {
    if (material.baseColorImage == kNoImage) return std::optional<std::uint32_t>();
    const auto key = std::tuple(material.baseColorImage, material.wrapS, material.wrapT);
    if (const auto found = textures_.find(key); found != textures_.end())
      return std::optional(found->second);
    const ImageSource& image = model_.images[material.baseColorImage];
    Result<std::vector<std::byte>> bytes = imageBytes(image);
    if (!bytes) return bytes.status();
    ImageFormat format = imageFormatOf(*bytes);
    if (format == ImageFormat::kUnknown) format = image.format;  // a TGA, known by its name
    if (format == ImageFormat::kUnknown)
      return badInput(image.embedded() ? image.name : image.path,
                      "texture image: not a JPEG, PNG, WebP, BMP or TGA image");
    if (!gltfImageFormat(format)) {
      // glTF holds JPEG, PNG and WebP: a BMP or TGA goes in as a PNG (lossless, alpha kept).
      Result<Image> texels = decodeImage(image);
      if (!texels) return texels.status();
      Result<std::vector<std::byte>> png = encodeImage(*texels, {.format = ImageFormat::kPng});
      if (!png) return png.status();
      bytes = std::move(*png);
      format = ImageFormat::kPng;
    }
    Result<std::uint32_t> texture =
        writer_.addTexture(*bytes, format, material.wrapS, material.wrapT);
    if (!texture) return texture.status();
    textures_.emplace(key, *texture);
    return std::optional(*texture);
  }

 private:
  const Model& model_;
  GlbWriter& writer_;
  std::map<std::tuple<std::uint32_t, TextureWrap, TextureWrap>, std::uint32_t> textures_;
};

// The first path component every object's path starts with, followed by more ("" if none).
std::string_view sharedFirstComponent(const Model& model) {
  std::string_view shared;
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const std::string_view path = model.objectPath(o);
    const auto slash = path.find('/');
    if (slash == std::string_view::npos || slash == 0) return {};
    if (o == 0) shared = path.substr(0, slash);
    if (path.substr(0, slash) != shared) return {};
  }
  return shared;
}

}  // namespace

Status writeGlb(const Model& model, const std::string& path, const GlbWriteOptions& options) {
  Result<GlbWriter> writer = GlbWriter::create(path, options);
  if (!writer) return writer.status();
  Progress progress("writing " + path, model.triangleCount());
  // The model's materials, written when used; their base colour is in the vertex colours when
  // there are any (readers bake it in), so it is white there.
  std::vector<std::optional<std::uint32_t>> materials(model.materials.size());
  ModelTextures textures(model, *writer);
  Status textureStatus;
  const auto materialOf = [&](std::uint32_t m) -> std::optional<std::uint32_t> {
    if (m >= materials.size()) return std::nullopt;
    if (!materials[m]) {
      Material material = model.materials[m];
      if (model.hasColors()) material.baseColor = {1, 1, 1, 1};
      Result<std::optional<std::uint32_t>> texture = textures.of(material);
      if (!texture) textureStatus = texture.status();
      materials[m] = writer->addMaterial(material, texture ? *texture : std::nullopt);
    }
    return materials[m];
  };
  AssemblyNodes assembly(*writer, sharedFirstComponent(model));
  const std::vector<Placement> placements =
      options.shareMeshes ? findPlacements(model) : std::vector<Placement>{};
  std::vector<std::optional<std::uint32_t>> meshes(model.objectCount());
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    if (o % 1024 == 0) LODFORGE_TRY(checkCancelled());
    const ObjectRecord& record = model.objects[o];
    const Placement* placed =
        o < placements.size() && placements[o].source != o ? &placements[o] : nullptr;
    std::optional<std::uint32_t>& mesh = meshes[o];
    if (placed) {
      mesh = meshes[placed->source];
    } else if (record.triangleCount > 0) {
      GlbMeshData data;
      data.positions = model.objectPositions(o);
      if (model.hasNormals())
        data.normals = std::span(model.normals).subspan(record.vertexOffset, record.vertexCount);
      if (model.hasColors())
        data.colors = std::span(model.colors).subspan(record.vertexOffset, record.vertexCount);
      const std::optional<std::uint32_t> material = materialOf(record.material);
      LODFORGE_TRY(textureStatus);
      // Texture coordinates go with a texture; an object without one draws no image.
      if (model.hasUvs() && textures.textured(record.material))
        data.uvs = std::span(model.uvs).subspan(record.vertexOffset, record.vertexCount);
      data.indices = model.objectIndices(o);
      Result<std::uint32_t> added = writer->addMesh(data, model.objectName(o), material);
      if (!added) return added.status();
      mesh = *added;
    }
    writer->addNode(model.objectName(o), mesh, placed ? &placed->transform : nullptr,
                    assembly.parentOf(model.objectPath(o)), model.objectLayer(o));
    progress.advance(record.triangleCount);
  }
  progress.finish();
  writer->setRootTranslation(model.origin);
  return writer->finish();
}

}  // namespace lodforge
