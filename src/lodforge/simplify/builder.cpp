#include "lodforge/simplify/builder.h"

#include <chrono>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>

#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/mesh/object_stream.h"
#include "lodforge/simplify/package.h"
#include "lodforge/simplify/prepare.h"
#include "lodforge/simplify/shape_cache.h"

namespace lodforge {

namespace {

constexpr std::size_t kMaxWaveObjects = 4096;
// What the build holds besides the objects in flight: the program, TBB, the readers' batches,
// the package writer's section buffers. Part of any --memory-limit.
constexpr std::uint64_t kFixedBytes = std::uint64_t{48} << 20;

struct Built {
  ProgressiveMesh mesh;
  std::string name, path;
  std::uint32_t material = kNoMaterial;
  std::uint32_t layer = kNoLayer;
  Rgba8 color;
  std::uint64_t inputTriangles = 0;
};

// Memory one object needs while it is built: the source, the prepared copy, the simplifier;
// a textured one also a texture quadric, cost and target per wedge (at most one per vertex)
// and a wedge per triangle corner.
std::uint64_t footprint(const SourceObject& object) {
  const std::uint64_t vertices = object.positions.size(), triangles = object.indices.size() / 3;
  const std::uint64_t wedges = object.uvs.empty() ? 0 : vertices * 192 + triangles * 24;
  return 2 * object.memoryBytes() + progressiveBuildBytes(vertices, triangles) + wedges;
}

// What the package says of an object besides its mesh; the object keeps its arrays.
Built describe(SourceObject& source) {
  Built built;
  built.name = std::move(source.name);
  built.path = std::move(source.path);
  built.material = source.material;
  built.layer = source.layer;
  built.inputTriangles = source.indices.size() / 3;
  // The base colour: the first vertex's (CAD parts are usually one colour).
  built.color = source.colors.empty() ? Rgba8{} : source.colors.front();
  return built;
}

// A textured object is built over its wedges (prepareTexturedObject): seams slide along
// themselves and every level's triangles keep one chart each.
ProgressiveMesh buildTextured(SourceObject& source, ProgressiveOptions options) {
  PreparedTexturedObject prepared = prepareTexturedObject(
      source.positions, source.normals, source.colors, source.uvs, source.indices);
  source = SourceObject{};
  options.wedges = prepared.wedges;
  options.wedgeUvs = prepared.uvs;
  return buildProgressive(prepared.points, prepared.indices, prepared.normals, prepared.colors,
                          options);
}

Built buildOne(SourceObject& source, const ProgressiveOptions& options) {
  Built built = describe(source);
  if (!source.uvs.empty()) {
    built.mesh = buildTextured(source, options);
    return built;
  }
  PreparedObject prepared =
      prepareObject(source.positions, source.normals, source.colors, source.indices);
  source = SourceObject{};  // release the input before the simplifier allocates
  built.mesh = buildProgressive(prepared.positions, prepared.indices, prepared.normals,
                                prepared.colors, options);
  return built;
}

// One object of a wave, in stream order: built here, or a placement of a shape built before it.
struct WaveObject {
  SourceObject source;  // emptied for a placement
  ShapeLookup shape;
  Built built;  // a placement's description until its mesh is placed
};

// A wave: as many objects as fit the budget (at least one); `carried` is the object that did not
// fit the last one. Placements of remembered shapes cost no build and little memory.
Status readWave(ObjectStream& stream, ShapeCache& shapes, std::uint64_t budget,
                std::optional<WaveObject>& carried, std::vector<WaveObject>& wave) {
  wave.clear();
  std::uint64_t bytes = 0;
  while (wave.size() < kMaxWaveObjects) {
    WaveObject object;
    if (carried) {
      object = std::move(*carried);
      carried.reset();
    } else {
      Result<bool> more = stream.next(object.source);
      if (!more) return more.status();
      if (!*more) break;
      // A textured shape placed again would need the same coordinates too: built anew.
      if (object.source.uvs.empty()) object.shape = shapes.lookup(object.source);
      if (object.shape.placed) {
        object.built = describe(object.source);
        object.source = SourceObject{};
      }
    }
    const std::uint64_t need = object.shape.placed ? 0 : footprint(object.source);
    if (need > budget) {
      return Error{ErrorKind::kLimit,
                   fmt::format("object '{}' ({} triangles) needs about {} to build, more than the "
                               "{} memory limit",
                               object.source.name, formatCount(object.source.indices.size() / 3),
                               formatBytes(need), formatBytes(budget))};
    }
    if (!wave.empty() && bytes + need > budget) {
      carried = std::move(object);
      break;
    }
    bytes += need;
    wave.push_back(std::move(object));
  }
  return {};
}

void count(const Built& b, BuildStats& stats) {
  stats.objects += 1;
  stats.inputTriangles += b.inputTriangles;
  stats.vertices += b.mesh.vertexCount();
  stats.triangles += b.mesh.triangleCount();
  stats.minVertices += b.mesh.q;
  stats.minTriangles += b.mesh.map.empty() ? 0 : b.mesh.map.front();
}

Result<BuildStats> build(const std::string& input, ObjectStream& stream, const std::string& output,
                         const BuildOptions& options) {
  if (options.memoryLimit && options.memoryLimit < kFixedBytes + (std::uint64_t{4} << 20)) {
    return Error{
        ErrorKind::kLimit,
        fmt::format("--memory-limit {} is too small to build anything: at least {} ({} "
                    "for the program plus the objects in flight)",
                    formatBytes(options.memoryLimit),
                    formatBytes(kFixedBytes + (std::uint64_t{4} << 20)), formatBytes(kFixedBytes))};
  }
  // The objects in flight get what the limit leaves (a quarter of the machine by default), less
  // an eighth for the shapes kept to place again (none without placements).
  const std::uint64_t limit = options.memoryLimit
                                  ? options.memoryLimit - kFixedBytes
                                  : std::max<std::uint64_t>(physicalMemoryBytes() / 4, 256 << 20);
  const std::uint64_t cacheBytes = options.placeRepeatedShapes ? limit / 8 : 0;
  ShapeCache shapes(cacheBytes);
  const std::uint64_t budget = limit - cacheBytes;
  Result<PackageWriter> writer = PackageWriter::create(
      output, stream.origin(), true, stream.hasColors(), !stream.images().empty());
  if (!writer) return writer.status();
  BuildStats stats;
  stats.streamed = stream.streaming();
  Progress progress("building", stream.triangleCountHint());
  std::optional<WaveObject> carried;
  std::vector<WaveObject> wave;
  while (true) {
    LODFORGE_TRY(readWave(stream, shapes, budget, carried, wave));
    if (wave.empty()) break;
    ++stats.waves;
    tbb::parallel_for(
        std::size_t{0}, wave.size(),
        [&](std::size_t i) {
          if (!wave[i].shape.placed) wave[i].built = buildOne(wave[i].source, options.progressive);
        },
        tbb::simple_partitioner());
    // In stream order, so a shape's mesh is kept before any placement of it is written.
    for (WaveObject& object : wave) {
      Built& b = object.built;
      if (const auto& placed = object.shape.placed) {
        b.mesh = placedMesh(shapes.mesh(placed->shape), placed->motion);
        stats.placements += 1;
      } else if (object.shape.remembered) {
        shapes.setMesh(*object.shape.remembered, b.mesh);
      }
      LODFORGE_TRY(writer->add(b.mesh, {b.name, b.color, b.path, b.material, b.layer}));
      count(b, stats);
      progress.advance(b.inputTriangles);
      object = WaveObject{};
    }
    LODFORGE_TRY(checkCancelled());
  }
  if (stats.inputTriangles == 0)
    return badInput(input,
                    "no triangles: a package is built from a mesh (for a point cloud use "
                    "`lodforge points` or `lodforge tiles`)");
  LODFORGE_TRY(writer->finish(stream.materials(), stream.layers(), stream.images()));
  progress.finish();
  Result<std::uint64_t> size = fileSize(output);
  if (!size) return size.status();
  stats.packageBytes = *size;
  stats.shapeCacheBytes = shapes.bytes();
  return stats;
}

}  // namespace

Result<BuildStats> buildPackage(const std::string& input, const std::string& output,
                                const BuildOptions& options) {
  // The time of the whole build: a CAD file is read and tessellated when its stream opens.
  const auto start = std::chrono::steady_clock::now();
  const auto timed = [&](Result<BuildStats> stats) {
    if (stats)
      stats->seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  };
  ObjectStreamOptions streamOptions{options.read, false};
  std::vector<std::string>* warnings = options.read.warnings;
  const std::size_t warned = warnings != nullptr ? warnings->size() : 0;
  Result<std::unique_ptr<ObjectStream>> stream = openObjectStream(input, streamOptions);
  if (!stream) return stream.status();
  Result<BuildStats> stats = build(input, **stream, output, options);
  if (stats.ok() || stats.error().kind != ErrorKind::kUnsupported) return timed(std::move(stats));
  // The PLY's objects are not grouped: load it whole instead of streaming (objects get grouped
  // by the reader), as long as it fits. The whole read warns again about what it sees.
  if (warnings != nullptr) warnings->resize(warned);
  streamOptions.load = true;
  stream = openObjectStream(input, streamOptions);
  if (!stream) return stream.status();
  return timed(build(input, **stream, output, options));
}

}  // namespace lodforge
