#include "lodforge/tiling/chunk_input.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <unordered_map>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/model_io.h"
#include "lodforge/io/ply_reader.h"
#include "lodforge/simplify/extract.h"
#include "lodforge/simplify/package.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {
namespace {

// A vertex in the work file: position (3 doubles), colour, normal (3 floats; a sum of face
// normals while a normals pass accumulates it).
constexpr std::size_t kVertexBytes = 3 * sizeof(double) + sizeof(Rgba8) + 3 * sizeof(float);
constexpr std::size_t kNormalOffset = 3 * sizeof(double) + sizeof(Rgba8);
constexpr std::uint64_t kBlockVertices = 1 << 14;

// Corners of the faces, fetched from the vertex work file through a direct-mapped cache of
// fixed-size blocks: meshes written in scan or grid order touch a few blocks at a time. Blocks
// changed by addNormal are written back when evicted and by flush().
class VertexCache {
 public:
  VertexCache(int fd, std::uint64_t vertices, std::uint64_t bytes) : fd_(fd), vertices_(vertices) {
    const std::uint64_t blockBytes = kBlockVertices * kVertexBytes;
    slots_ = std::max<std::uint64_t>(4, bytes / blockBytes);
    data_.resize(slots_ * blockBytes);
    tags_.assign(slots_, ~std::uint64_t{0});
    dirty_.assign(slots_, 0);
  }

  bool fetch(std::uint64_t vertex, CutCorner& out) {
    const std::byte* at = record(vertex);
    if (at == nullptr) return false;
    double xyz[3];
    float normal[3];
    std::memcpy(xyz, at, sizeof xyz);
    std::memcpy(&out.color, at + sizeof xyz, sizeof(Rgba8));
    std::memcpy(normal, at + kNormalOffset, sizeof normal);
    out.position = {xyz[0], xyz[1], xyz[2]};
    out.normal = normalizeOr(Vec3f{normal[0], normal[1], normal[2]}, Vec3f{0, 0, 1});
    out.source = vertex;
    return true;
  }

  bool addNormal(std::uint64_t vertex, Vec3f add) {
    std::byte* at = record(vertex);
    if (at == nullptr) return false;
    float normal[3];
    std::memcpy(normal, at + kNormalOffset, sizeof normal);
    normal[0] += add.x, normal[1] += add.y, normal[2] += add.z;
    std::memcpy(at + kNormalOffset, normal, sizeof normal);
    dirty_[vertex / kBlockVertices % slots_] = 1;
    return true;
  }

  bool flush() {
    for (std::uint64_t slot = 0; slot < slots_; ++slot)
      if (dirty_[slot] != 0 && !writeBack(slot)) return false;
    return true;
  }

 private:
  std::byte* record(std::uint64_t vertex) {
    if (vertex >= vertices_) return nullptr;
    const std::uint64_t block = vertex / kBlockVertices;
    const std::uint64_t slot = block % slots_;
    std::byte* base = data_.data() + slot * kBlockVertices * kVertexBytes;
    if (tags_[slot] != block) {
      if (dirty_[slot] != 0 && !writeBack(slot)) return nullptr;
      const std::uint64_t first = block * kBlockVertices;
      const auto wanted = static_cast<std::size_t>(blockVertices(block) * kVertexBytes);
      if (::pread(fd_, base, wanted, static_cast<off_t>(first * kVertexBytes)) !=
          static_cast<ssize_t>(wanted))
        return nullptr;
      tags_[slot] = block;
    }
    return base + (vertex % kBlockVertices) * kVertexBytes;
  }

  std::uint64_t blockVertices(std::uint64_t block) const {
    return std::min(kBlockVertices, vertices_ - block * kBlockVertices);
  }

  bool writeBack(std::uint64_t slot) {
    const std::uint64_t block = tags_[slot];
    const auto bytes = static_cast<std::size_t>(blockVertices(block) * kVertexBytes);
    const std::byte* base = data_.data() + slot * kBlockVertices * kVertexBytes;
    if (::pwrite(fd_, base, bytes, static_cast<off_t>(block * kBlockVertices * kVertexBytes)) !=
        static_cast<ssize_t>(bytes))
      return false;
    dirty_[slot] = 0;
    return true;
  }

  int fd_;
  std::uint64_t vertices_, slots_ = 0;
  std::vector<std::byte> data_;
  std::vector<std::uint64_t> tags_;
  std::vector<std::uint8_t> dirty_;
};

// Runs `work` on `threads` threads (0: as many as the process allows).
template <class Work>
void runOn(int threads, const Work& work) {
  if (threads <= 0) return work();
  tbb::task_arena arena(threads);
  arena.execute(work);
}

// A small model still gets a hierarchy to refine through: leaves of at most a sixteenth of it
// (not below kLeastLeafTriangles), so that a viewer shows a 30 K-triangle part from afar with a
// coarse tile instead of loading all of it.
constexpr std::uint64_t kLeastLeafTriangles = 2048;
std::uint64_t leafTriangles(const ChunkInputOptions& options, std::uint64_t triangles) {
  return std::min(options.trianglesPerChunk, std::max(triangles / 16, kLeastLeafTriangles));
}

// With --levels N the leaves are small enough for N levels above them (the grid's longest side
// has 2^N cells), unless that leaves fewer than kLeastLevelTriangles per leaf of a surface.
constexpr std::uint64_t kLeastLevelTriangles = 16;
Result<double> chunkSizeFor(const ChunkInputOptions& options, const Aabbd& bounds,
                            std::uint64_t triangles) {
  if (options.chunkSize > 0) return options.chunkSize;
  double size = ChunkGrid::sizeFor(bounds, triangles, leafTriangles(options, triangles));
  if (options.levels <= 0) return size;
  int most = 0;
  while (most < 30 && (triangles >> (2 * (most + 1))) >= kLeastLevelTriangles) ++most;
  if (options.levels > most)
    return Error{ErrorKind::kUsage,
                 fmt::format("--levels {}: the model's {} triangles make at most {} levels above "
                             "the leaves (each level quarters a surface's leaves, and a leaf "
                             "keeps at least {} triangles)",
                             options.levels, triangles, most, kLeastLevelTriangles)};
  return std::min(size, std::max(bounds.longestSide(), 1e-9) / std::ldexp(1.0, options.levels));
}

// A model file, or a progressive package (.lfp) at full detail: every object's mesh as it was
// before simplification.
Result<Model> readInputModel(const std::string& path) {
  if (fileExtension(path) != "lfp") return readModel(path);
  Result<Package> package = Package::open(path);
  if (!package) return package.status();
  return extractModel(*package, vertexCountsForRatio(*package, 1.0));
}

// The surface estimate of ChunkGrid::sizeFor, halved while the chunk a triangle lands in holds
// on average more than 1.5 x the target (parts clustered in a volume, as in a CAD assembly,
// crowd into far fewer chunks than a surface would). `visit(add)` calls add(point, triangles)
// for where the triangles are: each triangle's centroid, or each object's centre.
template <class Visit>
double fitChunkSize(const Aabbd& bounds, double size, std::uint64_t perChunk, const Visit& visit) {
  const double smallest = bounds.longestSide() / 4096;
  std::unordered_map<std::uint64_t, double> load;
  while (size / 2 >= smallest) {
    const ChunkGrid grid = ChunkGrid::over(bounds, size);
    load.clear();
    visit([&](Vec3d p, double triangles) { load[grid.cellIndex(grid.cellOf(p))] += triangles; });
    double squares = 0, triangles = 0;
    for (const auto& [cell, count] : load) {
      squares += count * count;
      triangles += count;
    }
    if (squares / triangles <= 1.5 * static_cast<double>(perChunk)) break;
    size /= 2;
  }
  return size;
}

// A normal carried through the input transform (a CRS to a local frame): the direction from the
// transformed point to the transformed point one unit along the normal. Without a transform, or
// where that fails, the normal as it was.
Vec3f transformNormal(const ChunkInputOptions& options, Vec3d in, Vec3d out, Vec3f normal) {
  Vec3d ahead;
  if (!options.transform || !options.transform(in + toDouble(normal), ahead)) return normal;
  return normalizeOr(toFloat(ahead - out), normal);
}

Result<ChunkInput> chunkPly(const std::string& path, const ChunkInputOptions& options) {
  ChunkInput input;
  input.streamed = true;
  // Pass 1: vertices to the work file, and the bounds.
  PlyReadOptions read;
  read.readFaces = false;
  read.salvageTruncated = options.salvageTruncated;
  Result<PlyReader> vertices = PlyReader::open(path, read);
  if (!vertices) return vertices.status();
  const PlyHeader header = vertices->header();
  if (header.faceCount == 0) return badInput(path, "no faces: a tileset needs a mesh");
  input.colors = header.hasColors;
  const std::string vertexPath = options.workDirectory + "/vertices.bin";
  const int fd = ::open(vertexPath.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return ioErrorFromErrno(vertexPath, "create");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  {
    // Two stages over batches, so that parsing the next batch overlaps writing this one (the
    // copy into the page cache is a large part of the pass): read (the reader is sequential),
    // then transform, bound and write in file order.
    Progress progress("tiles: vertices", header.vertexCount);
    // Each stage keeps its own failure; `failed` tells the other one to stop.
    Status readFailure, writeFailure;
    std::atomic<bool> failed = false;
    std::vector<std::byte> buffer;
    const auto readBatch = [&](tbb::flow_control& control) -> std::shared_ptr<PlyBatch> {
      auto batch = std::make_shared<PlyBatch>();
      while (!failed) {
        Status status = checkCancelled();
        Result<bool> more = status.ok() ? vertices->next(*batch) : Result<bool>(status);
        if (!more) {
          readFailure = more.status();
          failed = true;
          break;
        }
        if (!*more) break;
        if (batch->kind == PlyBatch::Kind::kVertices) return batch;
      }
      control.stop();
      return nullptr;
    };
    const auto writeBatch = [&](std::shared_ptr<PlyBatch> batch) {
      if (failed) return;
      buffer.resize(batch->positions.size() * kVertexBytes);
      for (std::size_t i = 0; i < batch->positions.size(); ++i) {
        Vec3d p = batch->positions[i];
        if (options.transform && !options.transform(batch->positions[i], p)) {
          failed = true;
          writeFailure =
              badInput(path, fmt::format("vertex {}: cannot be transformed to the tileset's "
                                         "frame (outside the coordinate system?)",
                                         batch->first + i));
          return;
        }
        input.bounds.add(p);
        const double xyz[3] = {p.x, p.y, p.z};
        const Rgba8 color = batch->colors.empty() ? Rgba8{255, 255, 255, 255} : batch->colors[i];
        // The file's normals (turned with the positions), or zero for the normals pass to fill.
        const Vec3f n = batch->normals.empty()
                            ? Vec3f{}
                            : transformNormal(options, batch->positions[i], p, batch->normals[i]);
        const float normal[3] = {n.x, n.y, n.z};
        std::byte* record = buffer.data() + i * kVertexBytes;
        std::memcpy(record, xyz, sizeof xyz);
        std::memcpy(record + sizeof xyz, &color, sizeof color);
        std::memcpy(record + kNormalOffset, normal, sizeof normal);
      }
      if (::write(fd, buffer.data(), buffer.size()) != static_cast<ssize_t>(buffer.size())) {
        failed = true;
        writeFailure = ioErrorFromErrno(vertexPath, "write");
        return;
      }
      progress.advance(batch->positions.size());
    };
    const auto pipeline = [&] {
      using Work = std::shared_ptr<PlyBatch>;
      tbb::parallel_pipeline(
          3, tbb::make_filter<void, Work>(tbb::filter_mode::serial_in_order, readBatch) &
                 tbb::make_filter<Work, void>(tbb::filter_mode::serial_in_order, writeBatch));
    };
    runOn(options.threads, pipeline);
    LODFORGE_TRY(writeFailure);  // the earlier batch's, if both failed
    LODFORGE_TRY(readFailure);
    progress.finish();
  }
  if (input.bounds.empty()) return badInput(path, "no vertices");

  VertexCache cache(fd, header.vertexCount, options.vertexCacheBytes);
  const auto fetch = [&](const PlyBatch& batch, std::size_t t,
                         std::array<CutCorner, 3>& triangle) -> Status {
    for (std::size_t k = 0; k < 3; ++k) {
      if (!cache.fetch(batch.triangles[t + k], triangle[k]))
        return badInput(path, fmt::format("face {}: vertex {} is not in the file (or the "
                                          "vertex work file could not be read)",
                                          batch.first, batch.triangles[t + k]));
    }
    return {};
  };
  read.readFaces = true;
  read.readVertices = false;
  read.batchSize = 1 << 14;  // the batches in flight below stay a few MiB each
  PlyBatch batch;

  // One more pass over the faces when the file has no normals (area-weighted sums of the face
  // normals, over the whole input, so that tiles agree along their borders) or has object ids
  // (the objects are the segments, §3.3: their bounds, memory per object, so that small ones
  // stay whole).
  struct ObjectExtent {
    Aabbd bounds;
    std::uint64_t triangles = 0;
  };
  std::unordered_map<std::uint32_t, ObjectExtent> objects;
  if (!header.hasNormals || header.hasObjectIds) {
    Result<PlyReader> faces = PlyReader::open(path, read);
    if (!faces) return faces.status();
    Progress progress(header.hasNormals ? "tiles: objects" : "tiles: normals", header.faceCount);
    while (true) {
      Result<bool> more = faces->next(batch);
      if (!more) return more.status();
      if (!*more) break;
      if (batch.kind != PlyBatch::Kind::kFaces) continue;
      for (std::size_t t = 0; t + 2 < batch.triangles.size(); t += 3) {
        std::array<CutCorner, 3> triangle;
        LODFORGE_TRY(fetch(batch, t, triangle));
        if (header.hasObjectIds) {
          ObjectExtent& object = objects[batch.triangleObjects[t / 3]];
          for (const CutCorner& corner : triangle) object.bounds.add(corner.position);
          ++object.triangles;
        }
        if (!header.hasNormals) {
          const Vec3f face = toFloat(cross(triangle[1].position - triangle[0].position,
                                           triangle[2].position - triangle[0].position));
          for (std::size_t k = 0; k < 3; ++k) {
            if (!cache.addNormal(batch.triangles[t + k], face))
              return ioErrorFromErrno(vertexPath, "update");
          }
        }
      }
      progress.advance(batch.count);
      LODFORGE_TRY(checkCancelled());
    }
    progress.finish();
  }

  // Pass 2: faces, corners from the cache, into the chunk files (cut, or whole by segment).
  Result<double> fitted = chunkSizeFor(options, input.bounds, header.faceCount);
  if (!fitted) return fitted.status();
  double size = *fitted;
  if (options.chunkSize == 0 && header.hasObjectIds) {
    // Where the triangles are, as far as the objects tell (small ones stay whole anyway).
    size = fitChunkSize(input.bounds, size, leafTriangles(options, header.faceCount),
                        [&](const auto& add) {
                          for (const auto& [id, object] : objects)
                            add(object.bounds.center(), static_cast<double>(object.triangles));
                        });
  }
  const ChunkGrid grid = ChunkGrid::over(input.bounds, size);
  input.chunks = std::make_unique<ChunkWriter>(grid, options.workDirectory + "/chunks",
                                               options.chunkBufferBytes, options.keepInMemory);
  Result<PlyReader> faces = PlyReader::open(path, read);
  if (!faces) return faces.status();
  Progress progress("tiles: chunks", header.faceCount);
  // Three stages over batches of faces, so reading, cutting and writing overlap: read and fetch
  // corners (the reader and the cache are sequential), cut (in parallel), add the pieces in file
  // order (the chunk files come out the same as from one thread).
  struct Batch {
    std::vector<CutCorner> corners;      // 3 per triangle
    std::vector<const Aabbd*> segments;  // per triangle, with object ids
    std::vector<ChunkCell> cells;        // per piece
    std::vector<CutCorner> pieces;       // 3 per piece
    std::uint64_t faces = 0, triangles = 0;
  };
  std::mutex failureMutex;
  Status failure;
  std::atomic<bool> failed = false;
  const auto fail = [&](Status status, tbb::flow_control* control) {
    std::lock_guard lock(failureMutex);
    if (failure.ok()) failure = std::move(status);
    failed = true;
    if (control) control->stop();
  };
  const auto readBatch = [&](tbb::flow_control& control) -> std::shared_ptr<Batch> {
    while (true) {
      if (failed) return control.stop(), nullptr;
      Status status = checkCancelled();
      Result<bool> more = status.ok() ? faces->next(batch) : Result<bool>(status);
      if (!more) return fail(more.status(), &control), nullptr;
      if (!*more) return control.stop(), nullptr;
      if (batch.kind != PlyBatch::Kind::kFaces) continue;
      auto next = std::make_shared<Batch>();
      next->faces = batch.count;
      next->triangles = batch.triangles.size() / 3;
      next->corners.resize(batch.triangles.size());
      next->pieces.reserve(batch.triangles.size() + batch.triangles.size() / 8);
      next->cells.reserve(next->triangles + next->triangles / 8);
      for (std::size_t t = 0; t + 2 < batch.triangles.size(); t += 3) {
        std::array<CutCorner, 3> triangle;
        if (status = fetch(batch, t, triangle); !status.ok())
          return fail(std::move(status), &control), nullptr;
        std::copy(triangle.begin(), triangle.end(), next->corners.data() + t);
        if (header.hasObjectIds) {
          const auto found = objects.find(batch.triangleObjects[t / 3]);
          next->segments.push_back(found == objects.end() ? nullptr : &found->second.bounds);
        }
      }
      return next;
    }
  };
  const auto cutBatch = [&](std::shared_ptr<Batch> work) {
    std::array<CutCorner, 3> triangle;
    for (std::size_t t = 0; t < work->corners.size(); t += 3) {
      std::copy_n(work->corners.data() + t, 3, triangle.begin());
      cutSegmentTriangle(grid, work->segments.empty() ? nullptr : work->segments[t / 3], triangle,
                         work->cells, work->pieces);
    }
    work->corners = {};
    return work;
  };
  const auto addBatch = [&](std::shared_ptr<Batch> work) {
    if (failed) return;
    if (Status status = input.chunks->addPieces(work->cells, work->pieces); !status.ok())
      return fail(std::move(status), nullptr);
    input.inputTriangles += work->triangles;
    progress.advance(work->faces);
  };
  // A few batches in flight: enough to keep every thread busy, little memory.
  const std::size_t tokens = static_cast<std::size_t>(std::max(2, options.threads + 1));
  const auto pipeline = [&] {
    using Work = std::shared_ptr<Batch>;
    tbb::parallel_pipeline(
        tokens, tbb::make_filter<void, Work>(tbb::filter_mode::serial_in_order, readBatch) &
                    tbb::make_filter<Work, Work>(tbb::filter_mode::parallel, cutBatch) &
                    tbb::make_filter<Work, void>(tbb::filter_mode::serial_in_order, addBatch));
  };
  runOn(options.threads, pipeline);
  LODFORGE_TRY(failure);
  LODFORGE_TRY(input.chunks->flush());
  progress.finish();
  std::error_code ignored;
  std::filesystem::remove(vertexPath, ignored);
  input.truncation = faces->truncation() ? faces->truncation() : vertices->truncation();
  return input;
}

Result<ChunkInput> chunkModel(const std::string& path, const ChunkInputOptions& options) {
  ChunkInput input;
  Result<Model> model = readInputModel(path);
  if (!model) return model.status();
  input.inputTriangles = model->triangleCount();
  if (input.inputTriangles == 0) return badInput(path, "the model has no triangles");
  input.colors = model->hasColors();
  // World positions (through the transform, if any) and their bounds.
  std::vector<Vec3d> world(model->vertexCount());
  for (std::size_t v = 0; v < world.size(); ++v) {
    world[v] = model->origin + toDouble(model->positions[v]);
    if (options.transform && !options.transform(world[v], world[v]))
      return badInput(path, fmt::format("vertex {}: cannot be transformed to the tileset's frame "
                                        "(outside the coordinate system?)",
                                        v));
    input.bounds.add(world[v]);
  }
  // Normals: the model's, or area-weighted over each whole object; turned with the positions.
  std::vector<Vec3f> normals = model->normals;
  if (!model->hasNormals()) {
    normals.resize(model->vertexCount());
    for (std::size_t o = 0; o < model->objectCount(); ++o) {
      const ObjectRecord& object = model->objects[o];
      computeVertexNormals(model->objectPositions(o), model->objectIndices(o),
                           std::span(normals).subspan(object.vertexOffset, object.vertexCount));
    }
  }
  if (options.transform) {
    for (std::size_t v = 0; v < world.size(); ++v)
      normals[v] = transformNormal(options, model->origin + toDouble(model->positions[v]), world[v],
                                   normals[v]);
  }
  Result<double> fitted = chunkSizeFor(options, input.bounds, input.inputTriangles);
  if (!fitted) return fitted.status();
  double size = *fitted;
  if (options.chunkSize == 0) {
    size = fitChunkSize(input.bounds, size, leafTriangles(options, input.inputTriangles),
                        [&](const auto& add) {
                          for (std::size_t o = 0; o < model->objectCount(); ++o) {
                            const std::uint64_t offset = model->objects[o].vertexOffset;
                            const auto indices = model->objectIndices(o);
                            for (std::size_t t = 0; t < indices.size(); t += 3)
                              add((world[offset + indices[t]] + world[offset + indices[t + 1]] +
                                   world[offset + indices[t + 2]]) *
                                      (1.0 / 3.0),
                                  1.0);
                          }
                        });
  }
  const ChunkGrid grid = ChunkGrid::over(input.bounds, size);
  input.chunks = std::make_unique<ChunkWriter>(grid, options.workDirectory + "/chunks",
                                               options.chunkBufferBytes, options.keepInMemory);
  Progress progress("tiles: chunks", input.inputTriangles);
  std::vector<std::uint32_t> welded, weldedIndices, component;
  std::vector<Aabbd> segmentBounds;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const ObjectRecord& object = model->objects[o];
    const auto indices = model->objectIndices(o);
    // Segments (§3.3): the object's connected components, over positions welded exactly so
    // that attribute splits (a box's hard edges) do not break a part into faces.
    welded.resize(object.vertexCount);
    const std::uint32_t weldedCount = weldVertices(model->objectPositions(o), {}, {}, {}, welded);
    weldedIndices.assign(indices.begin(), indices.end());
    remapIndices(weldedIndices, welded);
    component.resize(indices.size() / 3);
    const std::uint32_t segments = connectedComponents(weldedCount, weldedIndices, component);
    segmentBounds.assign(segments, Aabbd{});
    for (std::size_t t = 0; t < indices.size(); ++t)
      segmentBounds[component[t / 3]].add(world[object.vertexOffset + indices[t]]);
    for (std::size_t t = 0; t < indices.size(); t += 3) {
      std::array<CutCorner, 3> triangle;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t v = indices[t + k];
        triangle[k].position = world[object.vertexOffset + v];
        triangle[k].color =
            input.colors ? model->colors[object.vertexOffset + v] : Rgba8{255, 255, 255, 255};
        triangle[k].normal = normals[object.vertexOffset + v];
        triangle[k].source = object.vertexOffset + v;
      }
      LODFORGE_TRY(input.chunks->addSegmentTriangle(segmentBounds[component[t / 3]], triangle));
    }
    progress.advance(indices.size() / 3);
    LODFORGE_TRY(checkCancelled());
  }
  LODFORGE_TRY(input.chunks->flush());
  progress.finish();
  return input;
}

}  // namespace

Result<ChunkInput> chunkInput(const std::string& path, const ChunkInputOptions& options) {
  std::error_code error;
  std::filesystem::create_directories(options.workDirectory, error);
  if (error)
    return ioError(options.workDirectory, fmt::format("cannot create: {}", error.message()));
  if (fileExtension(path) == "ply") return chunkPly(path, options);
  return chunkModel(path, options);
}

}  // namespace lodforge
