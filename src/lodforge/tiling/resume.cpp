#include "lodforge/tiling/resume.h"

#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/tiling/texture_state.h"

namespace lodforge {

std::string workStatePath(const std::string& workDirectory) {
  return workDirectory + "/state.json";
}

nlohmann::json boundsToJson(const Aabbd& bounds) {
  return {bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z};
}

Aabbd boundsFromJson(const nlohmann::json& json) {
  Aabbd bounds;
  bounds.min = {json.at(0).get<double>(), json.at(1).get<double>(), json.at(2).get<double>()};
  bounds.max = {json.at(3).get<double>(), json.at(4).get<double>(), json.at(5).get<double>()};
  return bounds;
}

namespace {
nlohmann::json boundsList(const std::vector<Aabbd>& boxes) {
  nlohmann::json list = nlohmann::json::array();
  for (const Aabbd& box : boxes) list.push_back(boundsToJson(box));
  return list;
}

// Each side file with its size and modification time.
nlohmann::json sideFilesToJson(const std::vector<std::string>& files) {
  nlohmann::json list = nlohmann::json::array();
  for (const std::string& file : files) {
    const Result<std::uint64_t> size = fileSize(file);
    list.push_back({file, size ? *size : 0, modifiedTicks(file)});
  }
  return list;
}

// The side files, when every one is still the file it was; nothing otherwise.
std::optional<std::vector<std::string>> unchangedSideFiles(const nlohmann::json& list) {
  std::vector<std::string> files;
  for (const auto& entry : list) {
    const std::string file = entry.at(0).get<std::string>();
    const Result<std::uint64_t> size = fileSize(file);
    if ((size ? *size : 0) != entry.at(1).get<std::uint64_t>() ||
        modifiedTicks(file) != entry.at(2).get<std::int64_t>())
      return std::nullopt;
    files.push_back(file);
  }
  return files;
}

}  // namespace

Status saveChunkState(const std::string& path, const nlohmann::json& identity,
                      const ChunkInput& input) {
  const ChunkGrid& grid = input.chunks->grid();
  nlohmann::json counts = nlohmann::json::array();
  for (const auto& [index, count] : input.chunks->triangleCounts())
    counts.push_back({index, count});
  Result<nlohmann::json> textures =
      saveTextureTable(input.textures, std::filesystem::path(path).parent_path().string());
  if (!textures) return textures.status();
  const nlohmann::json state = {
      {"identity", identity},
      {"textures", *textures},
      {"sideFiles", sideFilesToJson(input.sideFiles)},
      {"grid",
       {{"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
        {"size", grid.size},
        {"dims", grid.dims}}},
      {"bounds", boundsToJson(input.bounds)},
      {"inputTriangles", input.inputTriangles},
      {"colors", input.colors},
      {"streamed", input.streamed},
      {"frame", input.frame ? nlohmann::json(input.frame->m) : nlohmann::json()},
      {"counts", counts},
      {"pieces", input.chunks->pieces()},
      {"parts",
       {{"source", input.parts.source},
        {"names", input.parts.names},
        {"paths", input.parts.paths},
        {"bounds", boundsList(input.parts.bounds)},
        {"materials", input.parts.materials},
        {"materialTable", materialsToJson(input.parts.materialTable)},
        {"layers", input.parts.layers},
        {"layerTable", input.parts.layerTable}}}};
  // (Part names come from the input and may not be UTF-8: replaced rather than thrown on.)
  return OutputFile::writeWhole(
      path, state.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

std::optional<ChunkInput> resumeChunks(const std::string& path, const nlohmann::json& identity,
                                       const std::string& chunkDirectory) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json state = nlohmann::json::parse(in);
    if (state.at("identity") != identity) return std::nullopt;  // other input or options
    ChunkGrid grid;
    const auto& g = state.at("grid");
    grid.origin = {g.at("origin").at(0).get<double>(), g.at("origin").at(1).get<double>(),
                   g.at("origin").at(2).get<double>()};
    grid.size = g.at("size").get<double>();
    grid.dims = g.at("dims").get<ChunkCell>();
    std::map<std::uint64_t, std::uint64_t> counts;
    for (const auto& entry : state.at("counts"))
      counts[entry.at(0).get<std::uint64_t>()] = entry.at(1).get<std::uint64_t>();
    ChunkInput input;
    input.bounds = boundsFromJson(state.at("bounds"));
    input.inputTriangles = state.at("inputTriangles").get<std::uint64_t>();
    input.colors = state.at("colors").get<bool>();
    input.streamed = state.at("streamed").get<bool>();
    if (!state.at("frame").is_null())
      input.frame = Mat4d{state.at("frame").get<std::array<double, 16>>()};
    const auto& parts = state.at("parts");
    input.parts.source = parts.at("source").get<std::string>();
    input.parts.names = parts.at("names").get<std::vector<std::string>>();
    input.parts.paths = parts.at("paths").get<std::vector<std::string>>();
    for (const auto& box : parts.at("bounds")) input.parts.bounds.push_back(boundsFromJson(box));
    input.parts.materials = parts.at("materials").get<std::vector<std::uint32_t>>();
    std::optional<std::vector<Material>> table = materialsFromJson(parts.at("materialTable"));
    if (!table) return std::nullopt;
    input.parts.materialTable = std::move(*table);
    input.parts.layers = parts.at("layers").get<std::vector<std::uint32_t>>();
    input.parts.layerTable = parts.at("layerTable").get<std::vector<std::string>>();
    if (input.parts.paths.size() != input.parts.names.size() ||
        input.parts.bounds.size() != input.parts.names.size() ||
        input.parts.materials.size() != input.parts.names.size() ||
        input.parts.layers.size() != input.parts.names.size())
      return std::nullopt;
    for (std::uint32_t m : input.parts.materials)
      if (m != kNoMaterial && m >= input.parts.materialTable.size()) return std::nullopt;
    for (std::uint32_t l : input.parts.layers)
      if (l != kNoLayer && l >= input.parts.layerTable.size()) return std::nullopt;
    std::optional<TextureTable> textures =
        loadTextureTable(state.at("textures"), std::filesystem::path(path).parent_path().string());
    if (!textures) return std::nullopt;
    input.textures = std::move(*textures);
    std::optional<std::vector<std::string>> sideFiles = unchangedSideFiles(state.at("sideFiles"));
    if (!sideFiles) return std::nullopt;  // a material library changed: chunk again
    input.sideFiles = std::move(*sideFiles);
    input.chunks = std::make_unique<ChunkWriter>(ChunkWriter::reopen(
        grid, chunkDirectory, std::move(counts), state.at("pieces").get<int>()));
    return input;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // damaged: chunk again
  }
}

std::string nodeSummaryPath(const std::string& meshPath) {
  return meshPath + ".json";
}

Status writeNodeSummary(const OctreeNode& node) {
  const nlohmann::json summary = {{"bounds", boundsToJson(node.bounds)},
                                  {"geometricError", node.geometricError},
                                  {"triangles", node.triangles},
                                  {"vertices", node.vertices},
                                  {"lockedVertices", node.lockedVertices},
                                  {"droppedSegments", node.droppedSegments},
                                  {"features", node.features}};
  LODFORGE_TRY(OutputFile::writeWhole(nodeSummaryPath(node.meshPath), summary.dump()));
  checkpointReached("node");
  return {};
}

bool readNodeSummary(const std::string& path, OctreeNode& node) {
  std::ifstream in(path);
  if (!in) return false;
  try {
    const nlohmann::json summary = nlohmann::json::parse(in);
    node.bounds = boundsFromJson(summary.at("bounds"));
    node.geometricError = summary.at("geometricError").get<double>();
    node.triangles = summary.at("triangles").get<std::uint64_t>();
    node.vertices = summary.at("vertices").get<std::uint64_t>();
    node.lockedVertices = summary.at("lockedVertices").get<std::uint64_t>();
    node.droppedSegments = summary.at("droppedSegments").get<std::uint64_t>();
    node.features = summary.at("features").get<std::vector<std::uint32_t>>();
  } catch (const nlohmann::json::exception&) {
    return false;  // a damaged summary: build the node again
  }
  return true;
}

}  // namespace lodforge
