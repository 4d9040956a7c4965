#include "lodforge/core/model.h"

#include <cassert>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/mesh.h"

namespace lodforge {

Aabb Model::bounds() const {
  Aabb box;
  for (const ObjectRecord& o : objects) box.add(o.bounds);
  return box;
}

std::uint64_t modelMemoryBytes(std::uint64_t vertexCount, std::uint64_t triangleCount,
                               std::uint64_t objectCount, bool normals, bool colors,
                               std::uint64_t nameBytes) {
  const std::uint64_t perVertex =
      sizeof(Vec3f) + (normals ? sizeof(Vec3f) : 0) + (colors ? sizeof(Rgba8) : 0);
  return vertexCount * perVertex + triangleCount * 3 * sizeof(std::uint32_t) +
         objectCount * sizeof(ObjectRecord) + nameBytes;
}

std::uint64_t Model::memoryBytes() const {
  std::uint64_t imageBytes = 0;
  for (const ImageSource& image : images) imageBytes += image.bytes.size();
  return modelMemoryBytes(vertexCount(), triangleCount(), objectCount(), hasNormals(), hasColors(),
                          names.size() + paths.size()) +
         uvs.size() * sizeof(Vec2f) + imageBytes;
}

void ModelBuilder::beginObject(std::string_view name, std::string_view path) {
  endObject();
  ObjectRecord record;
  record.vertexOffset = model_.positions.size();
  record.triangleOffset = model_.indices.size() / 3;
  record.nameOffset = model_.names.size();
  record.nameLength = static_cast<std::uint32_t>(name.size());
  model_.names.append(name);
  record.pathOffset = model_.paths.size();
  record.pathLength = static_cast<std::uint32_t>(path.size());
  model_.paths.append(path);
  model_.objects.push_back(record);
  open_ = true;
}

std::uint32_t ModelBuilder::addVertex(Vec3f position) {
  assert(open_);
  const auto local = model_.positions.size() - model_.objects.back().vertexOffset;
  model_.positions.push_back(position);
  return static_cast<std::uint32_t>(local);
}

void ModelBuilder::addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  assert(open_);
  model_.indices.insert(model_.indices.end(), {a, b, c});
}

std::uint32_t LayerTable::index(const std::string& name) {
  if (name.empty()) return kNoLayer;
  const auto [at, added] = index_.try_emplace(name, static_cast<std::uint32_t>(layers_.size()));
  if (added) layers_.push_back(name);
  return at->second;
}

void ModelBuilder::endObject() {
  if (!open_) return;
  open_ = false;
  ObjectRecord& record = model_.objects.back();
  const std::uint64_t vertices = model_.positions.size() - record.vertexOffset;
  const std::uint64_t triangles = model_.indices.size() / 3 - record.triangleOffset;
  // Local uint32 indices bound an object to 4G vertices; readers split bigger inputs.
  assert(vertices <= std::numeric_limits<std::uint32_t>::max());
  assert(triangles <= std::numeric_limits<std::uint32_t>::max());
  record.vertexCount = static_cast<std::uint32_t>(vertices);
  record.triangleCount = static_cast<std::uint32_t>(triangles);
  record.bounds = computeBounds(model_.objectPositions(model_.objects.size() - 1));
}

Vec3d chooseOrigin(const Aabbd& worldBounds) {
  if (worldBounds.empty()) return {};
  const Vec3d c = worldBounds.center();
  const double far = std::max({std::abs(worldBounds.min.x), std::abs(worldBounds.min.y),
                               std::abs(worldBounds.min.z), std::abs(worldBounds.max.x),
                               std::abs(worldBounds.max.y), std::abs(worldBounds.max.z)});
  // Below 2^16 a float still resolves ~4 µm; beyond, keep coordinates near zero.
  if (far < 65536.0) return {};
  return {std::round(c.x), std::round(c.y), std::round(c.z)};
}

void placeAtOrigin(Model& model, std::span<const Vec3d> world) {
  assert(world.size() == model.positions.size());
  Aabbd bounds;
  for (const Vec3d& p : world) bounds.add(p);
  model.origin = chooseOrigin(bounds);
  for (std::size_t v = 0; v < world.size(); ++v)
    model.positions[v] = toFloat(world[v] - model.origin);
  for (ObjectRecord& o : model.objects) {
    Aabb box;
    for (std::uint64_t v = o.vertexOffset; v < o.vertexOffset + o.vertexCount; ++v)
      box.add(model.positions[v]);
    o.bounds = box;
  }
}

void weldModel(Model& model, const WeldOptions& options) {
  Model out;
  out.origin = model.origin;
  out.names = std::move(model.names);
  out.paths = std::move(model.paths);
  out.materials = std::move(model.materials);
  out.layers = std::move(model.layers);
  out.images = std::move(model.images);
  out.objects.reserve(model.objects.size());
  std::vector<std::uint32_t> remap;
  for (std::size_t o = 0; o < model.objects.size(); ++o) {
    const ObjectRecord& in = model.objects[o];
    const auto positions = model.objectPositions(o);
    const auto normals =
        model.hasNormals()
            ? std::span<const Vec3f>(model.normals).subspan(in.vertexOffset, in.vertexCount)
            : std::span<const Vec3f>();
    const auto colors =
        model.hasColors()
            ? std::span<const Rgba8>(model.colors).subspan(in.vertexOffset, in.vertexCount)
            : std::span<const Rgba8>();
    const auto uvs =
        model.hasUvs() ? std::span<const Vec2f>(model.uvs).subspan(in.vertexOffset, in.vertexCount)
                       : std::span<const Vec2f>();
    remap.resize(in.vertexCount);
    WeldOptions objectOptions = options;
    objectOptions.keepNormalSplits = options.keepNormalSplits && !normals.empty();
    objectOptions.keepColorSplits = options.keepColorSplits && !colors.empty();
    const std::uint32_t unique =
        weldVertices(positions, normals, colors, objectOptions, remap, uvs);

    ObjectRecord record = in;
    record.vertexOffset = out.positions.size();
    record.triangleOffset = out.indices.size() / 3;
    record.vertexCount = unique;
    out.positions.resize(out.positions.size() + unique);
    remapVertexAttribute(positions, remap, std::span(out.positions).subspan(record.vertexOffset));
    if (!normals.empty()) {
      out.normals.resize(out.positions.size());
      remapVertexAttribute(normals, remap, std::span(out.normals).subspan(record.vertexOffset));
    }
    if (!colors.empty()) {
      out.colors.resize(out.positions.size());
      remapVertexAttribute(colors, remap, std::span(out.colors).subspan(record.vertexOffset));
    }
    if (!uvs.empty()) {
      out.uvs.resize(out.positions.size());
      remapVertexAttribute(uvs, remap, std::span(out.uvs).subspan(record.vertexOffset));
    }
    const auto indices = model.objectIndices(o);
    const std::size_t first = out.indices.size();
    out.indices.insert(out.indices.end(), indices.begin(), indices.end());
    const auto mine = std::span(out.indices).subspan(first);
    remapIndices(mine, remap);
    const std::size_t kept =
        removeDegenerateTriangles(std::span(out.positions).subspan(record.vertexOffset), mine,
                                  DegenerateOptions{.zeroArea = false});
    out.indices.resize(first + 3 * kept);
    record.triangleCount = static_cast<std::uint32_t>(kept);
    out.objects.push_back(record);
  }
  model = std::move(out);
}

void dropUnusedMaterials(Model& model) {
  std::vector<std::uint32_t> materialIndex(model.materials.size(), kNoMaterial);
  for (const ObjectRecord& o : model.objects) {
    if (o.material != kNoMaterial) materialIndex[o.material] = 0;
  }
  std::vector<Material> materials;
  std::vector<std::uint32_t> imageIndex(model.images.size(), kNoImage);
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    if (materialIndex[m] == kNoMaterial) continue;
    materialIndex[m] = static_cast<std::uint32_t>(materials.size());
    materials.push_back(std::move(model.materials[m]));
    if (materials.back().baseColorImage != kNoImage)
      imageIndex[materials.back().baseColorImage] = 0;
  }
  std::vector<ImageSource> images;
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    if (imageIndex[i] == kNoImage) continue;
    imageIndex[i] = static_cast<std::uint32_t>(images.size());
    images.push_back(std::move(model.images[i]));
  }
  for (Material& material : materials) {
    if (material.baseColorImage != kNoImage)
      material.baseColorImage = imageIndex[material.baseColorImage];
  }
  for (ObjectRecord& o : model.objects) {
    if (o.material != kNoMaterial) o.material = materialIndex[o.material];
  }
  model.materials = std::move(materials);
  model.images = std::move(images);
}

bool isConsistent(const Model& model, std::string* why) {
  auto fail = [&](std::string message) {
    if (why) *why = std::move(message);
    return false;
  };
  if (model.indices.size() % 3 != 0) return fail("index count is not a multiple of 3");
  if (!model.normals.empty() && model.normals.size() != model.positions.size())
    return fail("normals and positions differ in count");
  if (!model.colors.empty() && model.colors.size() != model.positions.size())
    return fail("colors and positions differ in count");
  if (!model.uvs.empty() && model.uvs.size() != model.positions.size())
    return fail("texture coordinates and positions differ in count");
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const std::uint32_t image = model.materials[m].baseColorImage;
    if (image != kNoImage && image >= model.images.size())
      return fail(fmt::format("material {} image out of range", m));
  }
  std::uint64_t nextVertex = 0, nextTriangle = 0;
  for (std::size_t i = 0; i < model.objects.size(); ++i) {
    const ObjectRecord& o = model.objects[i];
    if (o.vertexOffset != nextVertex || o.triangleOffset != nextTriangle)
      return fail(fmt::format("object {} does not follow its predecessor", i));
    if (o.nameOffset + o.nameLength > model.names.size())
      return fail(fmt::format("object {} name out of range", i));
    if (o.pathOffset + o.pathLength > model.paths.size())
      return fail(fmt::format("object {} path out of range", i));
    if (o.material != kNoMaterial && o.material >= model.materials.size())
      return fail(fmt::format("object {} material out of range", i));
    if (o.layer != kNoLayer && o.layer >= model.layers.size())
      return fail(fmt::format("object {} layer out of range", i));
    nextVertex += o.vertexCount;
    nextTriangle += o.triangleCount;
    if (nextVertex > model.positions.size() || nextTriangle > model.triangleCount())
      return fail(fmt::format("object {} extends past the arrays", i));
    for (std::uint32_t index : model.objectIndices(i)) {
      if (index >= o.vertexCount)
        return fail(fmt::format("object {} index {} out of range", i, index));
    }
  }
  if (nextVertex != model.positions.size() || nextTriangle != model.triangleCount())
    return fail("objects do not cover the arrays");
  return true;
}

}  // namespace lodforge
