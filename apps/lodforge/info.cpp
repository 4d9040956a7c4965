// `lodforge info FILE`: format, counts, bounds and what loading the file would cost. PLY files
// are streamed (constant memory, any size); other formats are loaded.
#include <chrono>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cad_options.h"
#include "cli.h"
#include "info_attributes.h"
#include "info_textures.h"
#include "lodforge/core/file.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/format_advice.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_textures.h"
#include "lodforge/io/model_io.h"
#include "lodforge/io/points/las_reader.h"
#include "lodforge/io/points/point_reader.h"
#include "lodforge/points/cloud_file.h"
#include "lodforge/simplify/package.h"

namespace lodforge::cli {

namespace {

struct Summary {
  std::string format;
  std::string encoding;  // e.g. PLY's binary_little_endian
  std::uint64_t fileBytes = 0;
  std::uint64_t vertices = 0, triangles = 0, objects = 0;
  bool normals = false, colors = false, uvs = false;
  Aabbd bounds;  // world coordinates
  std::uint64_t memoryBytes = 0;
  nlohmann::json extras;    // a PLY's other vertex properties (ExtraRanges::json)
  nlohmann::json cad;       // a CAD file's part tree: shapes, instances, depth, names
  nlohmann::json textures;  // materials and images (info_textures.h)
};

Result<Summary> summarizePly(const std::string& path, bool salvage) {
  PlyReadOptions options;
  options.salvageTruncated = salvage;
  options.readExtras = true;
  Result<PlyReader> reader = PlyReader::open(path, options);
  if (!reader) return reader.status();
  const PlyHeader& header = reader->header();
  ExtraRanges extras(header.extras);
  Summary s;
  s.format = "PLY";
  s.encoding = std::string(plyFormatName(header.format));
  s.normals = header.hasNormals;
  s.colors = header.hasColors;
  s.uvs = header.hasUvs || header.hasFaceUvs;
  if (plyTextured(header)) {
    std::vector<std::string> warnings;
    PlyTextures textures = readPlyTextures(header, path, &warnings);
    for (const std::string& w : warnings) fmt::print(stderr, "lodforge: warning: {}\n", w);
    Model table;
    table.materials = std::move(textures.materials);
    table.images = std::move(textures.images);
    s.textures = textureSummary(table);
  }
  std::unordered_set<std::uint32_t> ids;
  PlyBatch batch;
  Progress progress("reading", header.vertexCount + header.faceCount);
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    for (const Vec3d& p : batch.positions) s.bounds.add(p);
    s.vertices += batch.positions.size();
    s.triangles += batch.triangles.size() / 3;
    ids.insert(batch.triangleObjects.begin(), batch.triangleObjects.end());
    extras.add(batch.extras);
    progress.advance(batch.count);
  }
  if (reader->truncation()) {
    fmt::print(stderr, "lodforge: warning: {}; counted what came before\n", *reader->truncation());
  }
  s.objects = header.hasObjectIds ? ids.size() : 1;
  s.extras = extras.json();
  s.memoryBytes = modelMemoryBytes(s.vertices, s.triangles, s.objects, s.normals, s.colors);
  return s;
}

// The distinct part names in the order the tree lists them, with how often each is placed.
nlohmann::json partNames(const Model& model) {
  std::vector<std::string> order;
  std::unordered_map<std::string, std::uint64_t> count;
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const std::string name(model.objectName(o));
    if (count[name]++ == 0) order.push_back(name);
  }
  nlohmann::json names = nlohmann::json::array();
  for (const std::string& name : order) names.push_back({{"name", name}, {"count", count[name]}});
  return names;
}

// The CAD layers and how many parts each holds, in the model's order.
nlohmann::json layerCounts(const Model& model) {
  std::vector<std::uint64_t> count(model.layers.size());
  for (const ObjectRecord& o : model.objects)
    if (o.layer < count.size()) ++count[o.layer];
  nlohmann::json layers = nlohmann::json::array();
  for (std::size_t l = 0; l < count.size(); ++l)
    layers.push_back({{"name", model.layers[l]}, {"count", count[l]}});
  return layers;
}

Result<Summary> summarizeLoaded(const std::string& path, FileFormat format,
                                CadReadOptions cadOptions, bool salvage) {
  std::vector<std::string> warnings;
  CadReadStats cad;
  cadOptions.salvageTruncated = salvage;
  Result<Model> model =
      format == FileFormat::kCad
          ? readCad(path, cadOptions, &warnings, &cad)
          : readModel(path, {.salvageTruncated = salvage, .warnings = &warnings, .cad = {}});
  for (const std::string& w : warnings) fmt::print(stderr, "lodforge: warning: {}\n", w);
  if (!model) return model.status();
  Summary s;
  if (format == FileFormat::kCad)
    s.cad = {{"shapes", cad.shapes}, {"instances", cad.instances}, {"depth", cad.depth},
             {"hidden", cad.hidden}, {"parts", partNames(*model)}, {"layers", layerCounts(*model)}};
  s.format = std::string(formatName(format));
  s.vertices = model->vertexCount();
  s.triangles = model->triangleCount();
  s.objects = model->objectCount();
  s.normals = model->hasNormals();
  s.colors = model->hasColors();
  s.uvs = model->hasUvs();
  s.textures = textureSummary(*model);
  const Aabb local = model->bounds();
  if (!local.empty()) {
    s.bounds.add(model->origin + toDouble(local.min));
    s.bounds.add(model->origin + toDouble(local.max));
  }
  s.memoryBytes = model->memoryBytes();
  return s;
}

nlohmann::json toJson(const std::string& path, const Summary& s) {
  nlohmann::json j = {{"file", path},
                      {"format", s.format},
                      {"fileBytes", s.fileBytes},
                      {"vertices", s.vertices},
                      {"triangles", s.triangles},
                      {"objects", s.objects},
                      {"normals", s.normals},
                      {"colors", s.colors},
                      {"memoryBytes", s.memoryBytes},
                      {"uvs", s.uvs}};
  if (!s.textures.empty()) j["textures"] = s.textures;
  if (!s.encoding.empty()) j["encoding"] = s.encoding;
  if (!s.extras.empty()) j["attributes"] = {{"extras", s.extras}};
  if (!s.cad.empty()) j["cad"] = s.cad;
  if (!s.bounds.empty()) {
    j["bounds"] = {{"min", {s.bounds.min.x, s.bounds.min.y, s.bounds.min.z}},
                   {"max", {s.bounds.max.x, s.bounds.max.y, s.bounds.max.z}}};
  }
  return j;
}

void print(const std::string& path, const Summary& s) {
  fmt::print("file       {}\n", path);
  fmt::print("format     {}{} ({})\n", s.format, s.encoding.empty() ? "" : " " + s.encoding,
             formatBytes(s.fileBytes));
  std::string attributes;
  if (s.normals) attributes += "normals";
  if (s.colors) attributes += attributes.empty() ? "colors" : ", colors";
  if (s.uvs) attributes += attributes.empty() ? "texture coordinates" : ", texture coordinates";
  fmt::print("vertices   {}{}\n", formatCount(s.vertices),
             attributes.empty() ? "" : " (" + attributes + ")");
  fmt::print("triangles  {}\n", formatCount(s.triangles));
  fmt::print("objects    {}\n", formatCount(s.objects));
  if (!s.bounds.empty()) {
    const Vec3d size = s.bounds.size();
    fmt::print("bounds     min ({:.6g}, {:.6g}, {:.6g})  max ({:.6g}, {:.6g}, {:.6g})\n",
               s.bounds.min.x, s.bounds.min.y, s.bounds.min.z, s.bounds.max.x, s.bounds.max.y,
               s.bounds.max.z);
    fmt::print("size       {:.6g} x {:.6g} x {:.6g}\n", size.x, size.y, size.z);
  } else {
    fmt::print("bounds     empty\n");
  }
  fmt::print("memory     {} to load\n", formatBytes(s.memoryBytes));
  if (!s.extras.empty()) printPointAttributes({{"extras", s.extras}});
  printTextures(s.textures);
  if (s.cad.empty()) return;
  const auto hidden = s.cad["hidden"].get<std::uint64_t>();
  fmt::print("parts      {} shapes placed {} times, assembly depth {}{}\n",
             formatCount(s.cad["shapes"].get<std::uint64_t>()),
             formatCount(s.cad["instances"].get<std::uint64_t>()),
             s.cad["depth"].get<std::uint32_t>(),
             hidden > 0 ? fmt::format("; {} hidden, left out", formatCount(hidden)) : "");
  const nlohmann::json& parts = s.cad["parts"];
  constexpr std::size_t kShown = 12;
  for (std::size_t i = 0; i < std::min(parts.size(), kShown); ++i)
    fmt::print("  {} x{}\n", parts[i]["name"].get<std::string>(),
               parts[i]["count"].get<std::uint64_t>());
  if (parts.size() > kShown)
    fmt::print("  ... and {} more names (--json lists them all)\n", parts.size() - kShown);
  const nlohmann::json& layers = s.cad["layers"];
  if (layers.empty()) return;
  fmt::print("layers     {}\n", formatCount(layers.size()));
  for (std::size_t i = 0; i < std::min(layers.size(), kShown); ++i)
    fmt::print("  {} ({} parts)\n", layers[i]["name"].get<std::string>(),
               formatCount(layers[i]["count"].get<std::uint64_t>()));
  if (layers.size() > kShown)
    fmt::print("  ... and {} more layers (--json lists them all)\n", layers.size() - kShown);
}

// A progressive package: counts, levels, and what the LOD bookkeeping costs.
// A textured package's materials and images, as info_textures says them of a model.
nlohmann::json packageTextures(const Package& package) {
  if (!package.header().hasUvs()) return {};
  Model model;
  for (std::size_t m = 0; m < package.materialCount(); ++m)
    model.materials.push_back(package.material(m));
  for (std::size_t k = 0; k < package.imageCount(); ++k) model.images.push_back(package.image(k));
  return textureSummary(model);
}

Status describePackage(const std::string& path, bool json) {
  Result<Package> package = Package::open(path);
  if (!package) return package.status();
  const PackageHeader& h = package->header();
  std::uint64_t minVertices = 0, minTriangles = 0;
  double maxError = 0;
  for (std::size_t i = 0; i < package->objectCount(); ++i) {
    minVertices += package->object(i).minVertexCount;
    minTriangles += package->object(i).minTriangleCount;
    if (!package->error(i).empty())
      maxError = std::max(maxError, static_cast<double>(package->error(i).front()));
  }
  // The assembly: how many objects sit in a tree, how deep it goes, how many materials and layers.
  std::uint64_t placed = 0, depth = 0;
  for (std::size_t i = 0; i < package->objectCount(); ++i) {
    const std::string_view tree = package->objectPath(i);
    if (tree.empty()) continue;
    ++placed;
    depth =
        std::max(depth, 1 + static_cast<std::uint64_t>(std::count(tree.begin(), tree.end(), '/')));
  }
  const std::uint64_t lodBytes = package->sectionBytes(PackageSection::kEcol) +
                                 package->sectionBytes(PackageSection::kMap) +
                                 package->sectionBytes(PackageSection::kError);
  const double lodShare = static_cast<double>(lodBytes) /
                          static_cast<double>(std::max<std::uint64_t>(1, package->fileBytes()));
  if (json) {
    nlohmann::json j = {{"file", path},
                        {"format", "lodforge package"},
                        {"version", h.version},
                        {"fileBytes", package->fileBytes()},
                        {"objects", h.objectCount},
                        {"vertices", h.vertexCount},
                        {"triangles", h.triangleCount},
                        {"minVertices", minVertices},
                        {"minTriangles", minTriangles},
                        {"levels", h.levelCount},
                        {"normals", h.hasNormals()},
                        {"colors", h.hasColors()},
                        {"lodBytes", lodBytes},
                        {"maxError", maxError},
                        {"objectsInAssembly", placed},
                        {"assemblyDepth", depth},
                        {"materials", package->materialCount()},
                        {"layers", package->layerCount()},
                        {"origin", {h.origin[0], h.origin[1], h.origin[2]}}};
    if (const nlohmann::json textures = packageTextures(*package); !textures.empty())
      j["textures"] = textures;
    for (std::uint32_t s = 0; s < kPackageSections; ++s)
      j["sections"][std::string(packageSectionName(static_cast<PackageSection>(s)))] =
          h.sections[s].bytes;
    fmt::print("{}\n", j.dump(2));
    return {};
  }
  fmt::print("file       {}\n", path);
  fmt::print("format     lodforge package v{} ({})\n", h.version,
             formatBytes(package->fileBytes()));
  fmt::print("objects    {}\n", formatCount(h.objectCount));
  fmt::print("vertices   {} full, {} at the simplest level (normals{}{})\n",
             formatCount(h.vertexCount), formatCount(minVertices), h.hasColors() ? ", colors" : "",
             h.hasUvs() ? ", texture coordinates" : "");
  fmt::print("triangles  {} full, {} at the simplest level\n", formatCount(h.triangleCount),
             formatCount(minTriangles));
  fmt::print("assembly   {} of the objects in a tree {} deep, {} materials, {} layers\n",
             formatCount(placed), depth, package->materialCount(), package->layerCount());
  fmt::print("levels     {} (every vertex count of every object)\n", formatCount(h.levelCount));
  fmt::print("error      up to {:.6g} model units at the simplest level\n", maxError);
  fmt::print("bounds     min ({:.6g}, {:.6g}, {:.6g})  max ({:.6g}, {:.6g}, {:.6g})\n",
             h.origin[0] + h.boundsMin[0], h.origin[1] + h.boundsMin[1],
             h.origin[2] + h.boundsMin[2], h.origin[0] + h.boundsMax[0],
             h.origin[1] + h.boundsMax[1], h.origin[2] + h.boundsMax[2]);
  fmt::print("LOD data   ECol + Map + error = {} ({:.1f}% of the package)\n", formatBytes(lodBytes),
             100 * lodShare);
  fmt::print("sections  ");
  for (std::uint32_t s = 0; s < kPackageSections; ++s)
    fmt::print(" {} {}{}", packageSectionName(static_cast<PackageSection>(s)),
               formatBytes(h.sections[s].bytes), s + 1 < kPackageSections ? "," : "\n");
  printTextures(packageTextures(*package));
  return {};
}

// What `info` says of a point file: the JSON that --json prints (and the text is printed from),
// with the point count and bounds beside it until they are added.
struct PointFileFacts {
  nlohmann::json j;
  std::uint64_t count = 0;
  Aabbd bounds;
};

nlohmann::json lazJson(const LazInfo& laz) {
  nlohmann::json items = nlohmann::json::array();
  for (const LazItem& item : laz.items)
    items.push_back(
        {{"type", lazItemName(item.type)}, {"size", item.size}, {"version", item.version}});
  return {{"compressor", static_cast<int>(laz.compressor)},
          {"chunkSize", laz.chunkSize},
          {"variableChunks", laz.chunkSize == kLazVariableChunks},
          {"items", items},
          {"description", describeLaz(laz)}};
}

// A LAS or LAZ header as it stands, then (unless `headerOnly`) every point read for the lidar
// fields' ranges.
Status readLasFacts(const std::string& path, std::uint64_t bytes, bool headerOnly,
                    PointFileFacts& facts) {
  Result<LasHeader> header = LasReader::readHeader(path);
  if (!header) return header.status();
  const LasHeader& h = *header;
  nlohmann::json& j = facts.j;
  j["format"] = h.copc ? "COPC" : h.compressed ? "LAZ" : "LAS";
  if (h.laz) j["laz"] = lazJson(*h.laz);
  j["version"] = fmt::format("{}.{}", h.versionMajor, h.versionMinor);
  j["pointFormat"] = h.pointFormat;
  j["recordLength"] = h.recordLength;
  j["scale"] = {h.scale.x, h.scale.y, h.scale.z};
  j["offset"] = {h.offset.x, h.offset.y, h.offset.z};
  j["colors"] = h.hasColors;
  if (h.hasColors && !h.compressed) j["colorBits"] = h.eightBitColors ? 8 : 16;
  j["crs"] = h.crs;
  j["software"] = h.generatingSoftware;
  facts.count = h.pointCount;
  facts.bounds = h.bounds;
  if (!h.extrasIgnored.empty()) j["warnings"] = {h.extrasIgnored};
  if (!headerOnly) {
    Result<nlohmann::json> attributes = scanPointAttributes(path, bytes);
    if (!attributes) return attributes.status();
    j["attributes"] = std::move(*attributes);
  }
  return {};
}

// Text files are streamed to count their points and find their bounds.
Status streamPointFacts(const std::string& path, std::uint64_t bytes, PointFileFacts& facts) {
  Result<PointReader> reader = PointReader::open(path);
  if (!reader) return reader.status();
  facts.j["format"] = reader->info().format;
  facts.j["normals"] = reader->info().hasNormals;
  facts.j["colors"] = reader->info().hasColors;
  PointBatch batch;
  Progress progress("reading", bytes, Progress::Unit::kBytes);
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    for (const Vec3d& p : batch.positions) facts.bounds.add(p);
    facts.count += batch.size();
  }
  return {};
}

// The format lines of a LAS or LAZ file: version, point format, compression, scale and offset.
void printLasFormat(const nlohmann::json& j, std::uint64_t bytes) {
  const std::string colors = !j["colors"].get<bool>() ? std::string()
                             : j.contains("colorBits")
                                 ? fmt::format(", {}-bit colours", j["colorBits"].get<int>())
                                 : std::string(", colours");
  fmt::print("format     {} {}, point format {} ({}-byte records{}) ({})\n",
             j["format"].get<std::string>(), j["version"].get<std::string>(),
             j["pointFormat"].get<int>(), j["recordLength"].get<int>(), colors, formatBytes(bytes));
  if (j.contains("laz")) fmt::print("compressed {}\n", j["laz"]["description"].get<std::string>());
  fmt::print("scale      {:.6g} {:.6g} {:.6g}, offset {:.10g} {:.10g} {:.10g}\n",
             j["scale"][0].get<double>(), j["scale"][1].get<double>(), j["scale"][2].get<double>(),
             j["offset"][0].get<double>(), j["offset"][1].get<double>(),
             j["offset"][2].get<double>());
}

void printPointFile(const std::string& path, std::uint64_t bytes, const PointFileFacts& facts) {
  const nlohmann::json& j = facts.j;
  const Aabbd& bounds = facts.bounds;
  fmt::print("file       {}\n", path);
  if (j.contains("version"))
    printLasFormat(j, bytes);
  else
    fmt::print("format     {} ({})\n", j["format"].get<std::string>(), formatBytes(bytes));
  fmt::print("points     {}\n", formatCount(facts.count));
  if (!bounds.empty())
    fmt::print("bounds     min ({:.10g}, {:.10g}, {:.10g})  max ({:.10g}, {:.10g}, {:.10g})\n",
               bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z);
  const std::string crs = j.value("crs", std::string());
  if (j.contains("crs"))
    fmt::print("crs        {}\n", crs.empty()        ? std::string("none stated")
                                  : crs.size() > 100 ? crs.substr(0, 97) + "..."
                                                     : crs);
  if (j.contains("attributes")) printPointAttributes(j["attributes"]);
  if (j.contains("warnings"))
    for (const auto& warning : j["warnings"])
      fmt::print("warning    {}\n", warning.get<std::string>());
}

// A point file: a LAS or LAZ header as it stands, then (unless `headerOnly`) every point read
// for the lidar fields' ranges; text files are streamed to count their points and find their
// bounds.
Status describePointFile(const std::string& path, bool json, bool headerOnly) {
  Result<std::uint64_t> bytes = fileSize(path);
  if (!bytes) return bytes.status();
  PointFileFacts facts;
  facts.j = {{"file", path}, {"fileBytes", *bytes}};
  const bool las = fileExtension(path) == "las" || fileExtension(path) == "laz";
  LODFORGE_TRY(las ? readLasFacts(path, *bytes, headerOnly, facts)
                   : streamPointFacts(path, *bytes, facts));
  if (facts.count == 0 && !las) return badInput(path, "holds no points");
  facts.j["points"] = facts.count;
  if (!facts.bounds.empty())
    facts.j["bounds"] = {{"min", {facts.bounds.min.x, facts.bounds.min.y, facts.bounds.min.z}},
                         {"max", {facts.bounds.max.x, facts.bounds.max.y, facts.bounds.max.z}}};
  if (json)
    fmt::print("{}\n", facts.j.dump(2));
  else
    printPointFile(path, *bytes, facts);
  return {};
}

// A point package (.lfc): blocks, LOD parts and the tolerance that cut them.
Status describeCloud(const std::string& path, bool json) {
  Result<CloudFile> cloud = CloudFile::open(path);
  if (!cloud) return cloud.status();
  const CloudHeader& h = cloud->header();
  std::uint64_t smallest = h.pointCount, largest = 0;
  for (const CloudBlock& b : cloud->blocks()) {
    smallest = std::min(smallest, b.pointCount);
    largest = std::max(largest, b.pointCount);
  }
  if (json) {
    nlohmann::json j = {{"file", path},
                        {"format", "lodforge point package"},
                        {"version", h.version},
                        {"points", h.pointCount},
                        {"blocks", h.blockCount},
                        {"blockPoints", {smallest, largest}},
                        {"partI", h.droppedCount},
                        {"partII", h.residentCount},
                        {"partIII", h.segmentCount},
                        {"tolerance", h.tolerance},
                        {"crs", cloud->crs()},
                        {"bounds",
                         {{"min", {h.bounds.min.x, h.bounds.min.y, h.bounds.min.z}},
                          {"max", {h.bounds.max.x, h.bounds.max.y, h.bounds.max.z}}}}};
    fmt::print("{}\n", j.dump(2));
    return {};
  }
  fmt::print("file       {}\n", path);
  fmt::print("format     lodforge point package v{}\n", h.version);
  fmt::print("points     {}\n", formatCount(h.pointCount));
  fmt::print("blocks     {} ({} to {} points)\n", formatCount(h.blockCount), formatCount(smallest),
             formatCount(largest));
  fmt::print(
      "LOD        tolerance {:.6g}: Part II {} nodes in memory, Part III {} in segment "
      "files, Part I {} dropped\n",
      h.tolerance, formatCount(h.residentCount), formatCount(h.segmentCount),
      formatCount(h.droppedCount));
  fmt::print("bounds     min ({:.10g}, {:.10g}, {:.10g})  max ({:.10g}, {:.10g}, {:.10g})\n",
             h.bounds.min.x, h.bounds.min.y, h.bounds.min.z, h.bounds.max.x, h.bounds.max.y,
             h.bounds.max.z);
  return {};
}

}  // namespace

void addInfo(CLI::App& app, const Global& global, Run& run) {
  struct Options {
    std::string path;
    bool json = false;
    bool salvage = false;
    bool headerOnly = false;
    CadCommand cad;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("info", "Print a file's format, counts, bounds and load cost");
  sub->add_option(
         "FILE", options->path,
         "A .ply .obj .stl .gltf .glb model, a .step .iges .brep CAD file, a .las .laz .xyz .txt "
         ".csv .pts point file, or a .lfp or .lfc package")
      ->required();
  sub->add_flag("--json", options->json, "Print JSON instead of text");
  sub->add_flag("--header-only", options->headerOnly,
                "LAS and LAZ: the header alone, without reading the points for the ranges of "
                "their fields");
  sub->add_flag("--salvage", options->salvage,
                "Read a truncated PLY, STEP or IFC up to the cut (with a warning)");
  addCadOptions(*sub, options->cad);
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status {
      LODFORGE_TRY(refuseDirectoryInput(options->path));
      const std::string ext = fileExtension(options->path);
      if (ext != "lfp" && ext != "lfc" && !isPointCloudPath(options->path) &&
          formatFromPath(options->path) == FileFormat::kUnknown)
        return unknownFormatError(options->path, fmt::format("{}, {}, and .lfp .lfc packages",
                                                             kMeshFormats, kPointFormats));
      if (ext == "lfp") return describePackage(options->path, options->json);
      if (ext == "lfc") return describeCloud(options->path, options->json);
      if (isPointCloudPath(options->path))
        return describePointFile(options->path, options->json, options->headerOnly);
      const FileFormat format = formatFromPath(options->path);
      Result<std::uint64_t> bytes = fileSize(options->path);
      if (!bytes) return bytes.status();
      Result<CadReadOptions> cad = cadOptions(options->cad, global);
      if (!cad) return cad.status();
      Result<Summary> summary =
          format == FileFormat::kPly
              ? summarizePly(options->path, options->salvage)
              : summarizeLoaded(options->path, format, *cad, options->salvage);
      if (!summary) return summary.status();
      if (summary->vertices == 0)
        return badInput(options->path, "holds no vertices: neither a mesh nor a point set");
      summary->fileBytes = *bytes;
      if (options->json)
        fmt::print("{}\n", toJson(options->path, *summary).dump(2));
      else if (global.verbosity >= 0)
        print(options->path, *summary);
      return {};
    };
  });
}

}  // namespace lodforge::cli
