#include "lodforge/tiling/chunk_input.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <span>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/extract.h"
#include "lodforge/simplify/package.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/chunk_obj.h"
#include "lodforge/tiling/chunk_ply.h"
#include "lodforge/tiling/chunk_sizing.h"

namespace lodforge {
namespace {

// A model file, or a progressive package (.lfp) at full detail: every object's mesh as it was
// before simplification.
Result<Model> readInputModel(const std::string& path, const CadReadOptions& cad, bool salvage,
                             std::vector<std::string>& warnings) {
  if (fileExtension(path) != "lfp")
    return readModel(path, {.salvageTruncated = salvage, .warnings = &warnings, .cad = cad});
  Result<Package> package = Package::open(path);
  if (!package) return package.status();
  return extractModel(*package, vertexCountsForRatio(*package, 1.0));
}

// The text as valid UTF-8 (EXT_structural_metadata's strings must be): bytes that are not
// become U+FFFD, as the JSON files beside the tiles would write them anyway.
std::string validUtf8(std::string_view text) {
  const std::string quoted = nlohmann::json(std::string(text))
                                 .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return nlohmann::json::parse(quoted).get<std::string>();
}

// The model's objects as the parts of the tileset.
PartTable partTable(const std::string& path, const Model& model, std::span<const Vec3d> world) {
  PartTable parts;
  parts.source = std::filesystem::path(path).filename().string();
  parts.names.reserve(model.objectCount());
  parts.paths.reserve(model.objectCount());
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    parts.names.push_back(validUtf8(model.objectName(o)));
    parts.paths.push_back(validUtf8(model.objectPath(o)));
    parts.materials.push_back(model.objects[o].material);
    parts.layers.push_back(model.objects[o].layer);
    Aabbd& box = parts.bounds.emplace_back();
    for (std::uint32_t v = 0; v < model.objects[o].vertexCount; ++v)
      box.add(world[model.objects[o].vertexOffset + v]);
  }
  // Equal materials once (files repeat them), so a tile draws one primitive per material.
  std::vector<std::uint32_t> first(model.materials.size());
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const auto same =
        std::find(parts.materialTable.begin(), parts.materialTable.end(), model.materials[m]);
    first[m] = static_cast<std::uint32_t>(same - parts.materialTable.begin());
    if (same == parts.materialTable.end()) parts.materialTable.push_back(model.materials[m]);
  }
  for (std::uint32_t& m : parts.materials)
    if (m != kNoMaterial) m = m < first.size() ? first[m] : kNoMaterial;
  for (Material& m : parts.materialTable) m.name = validUtf8(m.name);
  for (const std::string& layer : model.layers) parts.layerTable.push_back(validUtf8(layer));
  return parts;
}

// A model read whole, in the tileset's frame: what chunkModel cuts.
struct PlacedModel {
  Model model;
  std::vector<Vec3d> world;    // its positions, through the transform if any
  std::vector<Vec3f> normals;  // one per vertex, turned with the positions
  bool features = false;       // its objects become parts (CutCorner::feature)
};

// Parts are named per vertex only when there is more than one. Scenes of nodes are assemblies
// (CAD, glTF, assimp's formats, packages); scans are not.
bool namesParts(const std::string& path, const Model& model, PartsMode parts) {
  const FileFormat format = formatFromPath(path);
  const bool assembly = format == FileFormat::kCad || format == FileFormat::kGlb ||
                        format == FileFormat::kGltf || format == FileFormat::kAssimp ||
                        fileExtension(path) == "lfp";
  return model.objectCount() > 1 &&
         (parts == PartsMode::kOn || (parts == PartsMode::kAuto && assembly));
}

// World positions, through the transform if any.
Result<std::vector<Vec3d>> worldPositions(const std::string& path, const Model& model,
                                          const ChunkInputOptions& options) {
  std::vector<Vec3d> world(model.vertexCount());
  for (std::size_t v = 0; v < world.size(); ++v) {
    world[v] = model.origin + toDouble(model.positions[v]);
    if (options.transform && !options.transform(world[v], world[v]))
      return badInput(path, fmt::format("vertex {}: cannot be transformed to the tileset's frame "
                                        "(outside the coordinate system?)",
                                        v));
  }
  return world;
}

// Normals: the model's, or area-weighted over each whole object; turned with the positions.
std::vector<Vec3f> worldNormals(const Model& model, std::span<const Vec3d> world,
                                const ChunkInputOptions& options) {
  std::vector<Vec3f> normals = model.normals;
  if (!model.hasNormals()) {
    normals.resize(model.vertexCount());
    for (std::size_t o = 0; o < model.objectCount(); ++o) {
      const ObjectRecord& object = model.objects[o];
      computeVertexNormals(model.objectPositions(o), model.objectIndices(o),
                           std::span(normals).subspan(object.vertexOffset, object.vertexCount));
    }
  }
  if (options.transform) {
    for (std::size_t v = 0; v < world.size(); ++v)
      normals[v] = transformNormal(options, model.origin + toDouble(model.positions[v]), world[v],
                                   normals[v]);
  }
  return normals;
}

// The leaf chunks' grid over the bounds: --chunk-size, or a size that fits where the triangles'
// centroids are.
Result<ChunkGrid> leafGrid(const PlacedModel& m, const ChunkInput& input,
                           const ChunkInputOptions& options) {
  Result<double> fitted = chunkSizeFor(options, input.bounds, input.inputTriangles);
  if (!fitted) return fitted.status();
  double size = *fitted;
  if (options.chunkSize == 0) {
    // --levels asks for leaves at least that small (chunkSizeFor).
    const double fit =
        fitChunkSize(input.bounds, leafTriangles(options, input.inputTriangles),
                     options.trianglesPerChunk, [&](const auto& add) {
                       for (std::size_t o = 0; o < m.model.objectCount(); ++o) {
                         const std::uint64_t offset = m.model.objects[o].vertexOffset;
                         const auto indices = m.model.objectIndices(o);
                         for (std::size_t t = 0; t < indices.size(); t += 3)
                           add((m.world[offset + indices[t]] + m.world[offset + indices[t + 1]] +
                                m.world[offset + indices[t + 2]]) *
                                   (1.0 / 3.0),
                               1.0);
                       }
                     });
    size = options.levels > 0 ? std::min(size, fit) : fit;
  }
  return ChunkGrid::over(input.bounds, size);
}

// Segments (§3.3) of one object at a time: its connected components, over positions welded
// exactly so that attribute splits (a box's hard edges) do not break a part into faces, and
// their bounds.
class ObjectSegments {
 public:
  void find(const PlacedModel& m, std::size_t o) {
    const ObjectRecord& object = m.model.objects[o];
    const auto indices = m.model.objectIndices(o);
    welded_.resize(object.vertexCount);
    const std::uint32_t weldedCount = weldVertices(m.model.objectPositions(o), {}, {}, {}, welded_);
    weldedIndices_.assign(indices.begin(), indices.end());
    remapIndices(weldedIndices_, welded_);
    component_.resize(indices.size() / 3);
    const std::uint32_t segments = connectedComponents(weldedCount, weldedIndices_, component_);
    bounds_.assign(segments, Aabbd{});
    for (std::size_t t = 0; t < indices.size(); ++t)
      bounds_[component_[t / 3]].add(m.world[object.vertexOffset + indices[t]]);
  }
  // The bounds of the segment of the object's triangle `t`.
  const Aabbd& of(std::size_t t) const { return bounds_[component_[t]]; }

 private:
  std::vector<std::uint32_t> welded_, weldedIndices_, component_;
  std::vector<Aabbd> bounds_;
};

// The corners of object `o`'s triangle over `corners` (its 3 indices) as chunk files take them.
std::array<CutCorner, 3> cornersOf(const PlacedModel& m, std::size_t o,
                                   std::span<const std::uint32_t> corners, bool colors) {
  const std::uint64_t offset = m.model.objects[o].vertexOffset;
  const std::uint32_t material = m.model.objects[o].material;
  const bool textured = m.model.hasUvs() && material != kNoMaterial &&
                        m.model.materials[material].baseColorImage != kNoImage;
  std::array<CutCorner, 3> triangle;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::uint32_t v = corners[k];
    triangle[k].position = m.world[offset + v];
    triangle[k].color = colors ? m.model.colors[offset + v] : Rgba8{255, 255, 255, 255};
    triangle[k].normal = m.normals[offset + v];
    triangle[k].source = offset + v;
    triangle[k].feature = m.features ? static_cast<std::uint32_t>(o) : kNoFeature;
    if (textured) {
      triangle[k].uv = m.model.uvs[offset + v];
      triangle[k].material = material;
    }
  }
  return triangle;
}

// Every object's triangles into the chunks, segment by segment (ChunkWriter::addSegmentTriangle).
Status addObjects(const PlacedModel& m, ChunkInput& input) {
  Progress progress("tiles: chunks", input.inputTriangles);
  ObjectSegments segments;
  for (std::size_t o = 0; o < m.model.objectCount(); ++o) {
    segments.find(m, o);
    const auto indices = m.model.objectIndices(o);
    for (std::size_t t = 0; t < indices.size(); t += 3) {
      LODFORGE_TRY(input.chunks->addSegmentTriangle(
          segments.of(t / 3), cornersOf(m, o, indices.subspan(t, 3), input.colors)));
    }
    progress.advance(indices.size() / 3);
    LODFORGE_TRY(checkCancelled());
  }
  LODFORGE_TRY(input.chunks->flush());
  progress.finish();
  return {};
}

// A model read whole: placed in the tileset's frame, its parts named, the leaf grid sized, its
// objects cut into the chunks.
Result<ChunkInput> chunkModel(const std::string& path, const ChunkInputOptions& options) {
  ChunkInput input;
  Result<Model> read = readInputModel(path, options.cad, options.salvageTruncated, input.warnings);
  if (!read) return read.status();
  PlacedModel m;
  m.model = std::move(*read);
  input.inputTriangles = m.model.triangleCount();
  if (input.inputTriangles == 0) return badInput(path, "the model has no triangles");
  input.colors = m.model.hasColors();
  m.features = namesParts(path, m.model, options.parts);
  Result<std::vector<Vec3d>> world = worldPositions(path, m.model, options);
  if (!world) return world.status();
  m.world = std::move(*world);
  for (const Vec3d& p : m.world) input.bounds.add(p);
  if (m.features) input.parts = partTable(path, m.model, m.world);
  m.normals = worldNormals(m.model, m.world, options);
  Result<ChunkGrid> grid = leafGrid(m, input, options);
  if (!grid) return grid.status();
  input.chunks = std::make_unique<ChunkWriter>(*grid, options.workDirectory + "/chunks",
                                               options.chunkBufferBytes, options.keepInMemory);
  if (m.model.hasUvs() && !m.model.images.empty()) {
    input.chunks->setTextured(true);
    input.textures = {m.model.materials, std::move(m.model.images)};
  }
  LODFORGE_TRY(addObjects(m, input));
  return input;
}

}  // namespace

Result<ChunkInput> chunkInput(const std::string& path, const ChunkInputOptions& options) {
  std::error_code error;
  std::filesystem::create_directories(options.workDirectory, error);
  if (error)
    return ioError(options.workDirectory, fmt::format("cannot create: {}", error.message()));
  if (fileExtension(path) == "ply") return chunkPly(path, options);
  // An OBJ streams unless its objects are asked to be parts (read whole, by object).
  if (fileExtension(path) == "obj" && options.parts != PartsMode::kOn)
    return chunkObj(path, options);
  return chunkModel(path, options);
}

}  // namespace lodforge
