#include "lodforge/tiling/chunk_ply.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include <tbb/parallel_pipeline.h>

#include <fmt/format.h>

#include "lodforge/core/cluster.h"
#include "lodforge/core/file.h"
#include "lodforge/core/pipeline_failure.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_textures.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/chunk_sizing.h"
#include "lodforge/tiling/vertex_cache.h"

namespace lodforge {
namespace {

// Where a PLY's objects are, for the chunk size and for segments (§3.3): small objects go into
// the chunk of their centre whole.
struct ObjectExtent {
  Aabbd bounds;
  std::uint64_t triangles = 0;
};

// A batch of faces through the cutting pipeline.
struct FaceBatch {
  std::uint64_t first = 0;             // the batch's first face in the file
  std::vector<CutCorner> corners;      // 3 per triangle
  std::vector<const Aabbd*> segments;  // per triangle, with object ids
  std::vector<ChunkCell> cells;        // per piece
  std::vector<CutCorner> pieces;       // 3 per piece
  std::uint64_t faces = 0, triangles = 0;
};

// This rank's share of `count` elements (all of them in a job of one).
PlySlice rankSlice(std::uint64_t count) {
  const auto ranks = static_cast<std::uint64_t>(clusterSize());
  const auto rank = static_cast<std::uint64_t>(clusterRank());
  const std::uint64_t first = count * rank / ranks;
  return {first, count * (rank + 1) / ranks - first};
}

class PlyChunking {
 public:
  PlyChunking(const std::string& path, const ChunkInputOptions& options, bool sliced = false)
      : path_(path),
        options_(options),
        vertexPath_(options.workDirectory + "/vertices.bin"),
        sliced_(sliced) {}
  ~PlyChunking() {
    if (fd_ >= 0) ::close(fd_);
  }
  PlyChunking(const PlyChunking&) = delete;
  PlyChunking& operator=(const PlyChunking&) = delete;

  Status openVertices();
  Status copyVertices();
  Status openCache();
  Status scanFaces();
  Status cutFaces();
  ChunkInput finish();
  // In slices: the ranks' bounds joined, then their chunk pieces and counts.
  Status joinBounds();
  Status joinChunks();
  const PlyHeader& header() const { return header_; }

 private:
  std::shared_ptr<PlyBatch> readVertexBatch(tbb::flow_control& control);
  void writeVertexBatch(const PlyBatch& batch, std::vector<std::byte>& buffer);
  Status fetch(const PlyBatch& batch, std::size_t t, std::array<CutCorner, 3>& triangle);
  Status texture(const PlyBatch& batch, std::size_t t, std::array<CutCorner, 3>& triangle) const;
  PlyReadOptions faceReading() const;
  Result<ChunkGrid> chunkGrid() const;
  std::shared_ptr<FaceBatch> readFaceBatch(tbb::flow_control& control);
  void cutFaceBatch(FaceBatch& work) const;
  void addFaceBatch(const FaceBatch& work);

  const std::string& path_;
  const ChunkInputOptions& options_;
  const std::string vertexPath_;
  const bool sliced_;    // this rank's slice of a job's (chunkPlyInSlices)
  VertexLayout layout_;  // of the vertex work file
  std::optional<PlyReader> vertices_, faces_;
  PlyHeader header_;
  int fd_ = -1;
  ChunkInput input_;
  std::optional<VertexCache> cache_;
  std::unordered_map<std::uint32_t, ObjectExtent> objects_;
  std::optional<ChunkGrid> grid_;
  // The pipelines' state: the failure, the faces or vertices read so far, a reader's batch.
  PipelineFailure failure_;
  std::uint64_t read_ = 0;
  std::uint64_t facesDone_ = 0;  // cut into chunks
  PlyBatch batch_;
  std::optional<Progress> progress_;
};

// Pass 1, set-up: the header (a mesh, or refused) and the vertex work file.
Status PlyChunking::openVertices() {
  input_.streamed = true;
  PlyReadOptions read;
  read.readFaces = false;
  read.stopAfterDelivered = true;  // the face pass reads the faces
  read.salvageTruncated = options_.salvageTruncated;
  Result<PlyReader> vertices = PlyReader::open(path_, read);
  if (vertices && sliced_) {
    read.vertexSlice = rankSlice(vertices->header().vertexCount);
    vertices = PlyReader::open(path_, read);
  }
  if (!vertices) return vertices.status();
  vertices_ = std::move(*vertices);
  read_ = read.vertexSlice.first;  // a slice's failures are placed in the whole file
  header_ = vertices_->header();
  if (header_.faceCount == 0) return badInput(path_, "no faces: a tileset needs a mesh");
  if (std::optional<std::string> unread = unreadPlyElements(header_, path_))
    input_.warnings.push_back(std::move(*unread));
  input_.colors = header_.hasColors;
  if (plyTextured(header_)) {
    PlyTextures textures = readPlyTextures(header_, path_, &input_.warnings);
    // A texture that cannot be read draws grey: in the vertex colours.
    for (const Material& m : textures.materials) input_.colors |= m.baseColorImage == kNoImage;
    input_.textures = {std::move(textures.materials), std::move(textures.images)};
    layout_.uvs = header_.hasUvs;
  } else if (header_.hasUvs || header_.hasFaceUvs) {
    input_.warnings.push_back(
        fmt::format("{}: texture coordinates but no texture (no 'comment "
                    "TextureFile' line): drawn without one",
                    path_));
  }
  // Float positions stay floats in the work file, unless a transform makes doubles of them.
  layout_.floatPositions = header_.floatPositions && !options_.transform;
  // Each rank writes its slice in place: none may truncate what the others wrote.
  fd_ = ::open(vertexPath_.c_str(), O_RDWR | O_CREAT | (sliced_ ? 0 : O_TRUNC), 0644);
  if (fd_ < 0) return ioErrorFromErrno(vertexPath_, "create");
  return {};
}

// Pass 1: vertices to the work file, and the bounds. Two stages over batches, so that parsing
// the next batch overlaps writing this one (the copy into the page cache is a large part of the
// pass): read (the reader is sequential), then transform, bound and write in file order.
Status PlyChunking::copyVertices() {
  if (!sliced_) progress_.emplace("tiles: vertices", header_.vertexCount);
  std::vector<std::byte> buffer;  // one batch's records; freed after this pass
  const auto pipeline = [&] {
    using Work = std::shared_ptr<PlyBatch>;
    tbb::parallel_pipeline(3, tbb::make_filter<void, Work>(tbb::filter_mode::serial_in_order,
                                                           [&](tbb::flow_control& control) {
                                                             return readVertexBatch(control);
                                                           }) &
                                  tbb::make_filter<Work, void>(tbb::filter_mode::serial_in_order,
                                                               [&](const Work& batch) {
                                                                 writeVertexBatch(*batch, buffer);
                                                               }));
  };
  runOn(options_.threads, pipeline);
  LODFORGE_TRY(failure_.status());
  if (progress_) progress_->finish();
  if (sliced_) {
    // Closed before the ranks agree that the file is complete: on a shared file system what a
    // rank wrote is seen by the others once it closed the file (close-to-open consistency).
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) return ioErrorFromErrno(vertexPath_, "write");
  }
  return {};
}

// Corners are fetched from the vertex work file, complete (every rank's slice in it).
Status PlyChunking::openCache() {
  if (input_.bounds.empty()) return badInput(path_, "no vertices");
  if (sliced_) {
    // Opened again once every rank closed it (copyVertices): with what every rank wrote.
    fd_ = ::open(vertexPath_.c_str(), O_RDWR);
    if (fd_ < 0) return ioErrorFromErrno(vertexPath_, "open");
  }
  cache_.emplace(fd_, header_.vertexCount, options_.vertexCacheBytes, layout_);
  return {};
}

std::shared_ptr<PlyBatch> PlyChunking::readVertexBatch(tbb::flow_control& control) {
  auto batch = std::make_shared<PlyBatch>();
  while (!failure_.failed()) {
    Status status = checkCancelled();
    Result<bool> more = status.ok() ? vertices_->next(*batch) : Result<bool>(status);
    if (!more) {
      failure_.fail(read_, more.status(), &control);
      return nullptr;
    }
    if (!*more) break;
    if (batch->kind == PlyBatch::Kind::kVertices) {
      read_ += batch->positions.size();
      return batch;
    }
  }
  control.stop();
  return nullptr;
}

void PlyChunking::writeVertexBatch(const PlyBatch& batch, std::vector<std::byte>& buffer) {
  // Not on any failure: the reading stage, ahead, may fail on a later batch before this one's
  // bad vertex is found, and the one nearest the start of the file is the one to report.
  if (failure_.failedBefore(batch.first)) return;
  buffer.resize(batch.positions.size() * layout_.bytes());
  for (std::size_t i = 0; i < batch.positions.size(); ++i) {
    Vec3d p = batch.positions[i];
    if (options_.transform && !options_.transform(batch.positions[i], p)) {
      failure_.fail(batch.first + i,
                    badInput(path_, fmt::format("vertex {}: cannot be transformed to the tileset's "
                                                "frame (outside the coordinate system?)",
                                                batch.first + i)));
      return;
    }
    input_.bounds.add(p);
    const Rgba8 color = batch.colors.empty() ? Rgba8{255, 255, 255, 255} : batch.colors[i];
    // The file's normals (turned with the positions), or zero for the normals pass to fill.
    const Vec3f n = batch.normals.empty()
                        ? Vec3f{}
                        : transformNormal(options_, batch.positions[i], p, batch.normals[i]);
    const Vec2f uv = batch.uvs.empty() ? Vec2f{} : batch.uvs[i];
    writeVertexRecord(buffer.data() + i * layout_.bytes(), layout_, p, color, n, uv);
  }
  // At the batch's place in the file: ranks write their slices side by side.
  const auto offset = static_cast<off_t>(batch.first * layout_.bytes());
  if (::pwrite(fd_, buffer.data(), buffer.size(), offset) != static_cast<ssize_t>(buffer.size())) {
    failure_.fail(batch.first, ioErrorFromErrno(vertexPath_, "write"));
    return;
  }
  if (progress_) progress_->advance(batch.positions.size());
}

Status PlyChunking::fetch(const PlyBatch& batch, std::size_t t,
                          std::array<CutCorner, 3>& triangle) {
  for (std::size_t k = 0; k < 3; ++k) {
    if (!cache_->fetch(batch.triangles[t + k], triangle[k]))
      return badInput(path_, fmt::format("face {}: vertex {} is not in the file (or the "
                                         "vertex work file could not be read)",
                                         batch.first, batch.triangles[t + k]));
  }
  return {};
}

// A textured file's corners: the face's texture, and its corners' coordinates when it has
// them. Corners are not shared by file vertex (a vertex may have other coordinates or another
// texture in another face): welding joins the equal ones. A texture that could not be read
// (warned about) draws grey; a texnumber past the files is refused, as the whole read does.
Status PlyChunking::texture(const PlyBatch& batch, std::size_t t,
                            std::array<CutCorner, 3>& triangle) const {
  const std::uint32_t texture = batch.triangleTextures.empty() ? 0 : batch.triangleTextures[t / 3];
  const auto& materials = input_.textures.materials;
  if (texture != ~0u && texture >= materials.size())
    return badInput(path_, fmt::format("face {}: texnumber {} but the file names {} textures "
                                       "(comment TextureFile)",
                                       batch.first + t / 3, texture, materials.size()));
  const bool drawn = texture != ~0u && materials[texture].baseColorImage != kNoImage;
  for (std::size_t k = 0; k < 3; ++k) {
    triangle[k].material = drawn ? texture : ~0u;
    triangle[k].source = CutCorner::kNoSource;
    if (texture != ~0u && !drawn) triangle[k].color = {128, 128, 128, 255};
    if (!batch.cornerUvs.empty()) triangle[k].uv = batch.cornerUvs[t + k];
  }
  return {};
}

PlyReadOptions PlyChunking::faceReading() const {
  PlyReadOptions read;
  read.salvageTruncated = options_.salvageTruncated;
  read.readFaces = true;
  read.readVertices = false;
  read.batchSize = 1 << 14;  // the batches in flight below stay a few MiB each
  if (sliced_) read.faceSlice = rankSlice(header_.faceCount);
  return read;
}

// One more pass over the faces when the file has no normals (area-weighted sums of the face
// normals, over the whole input, so that tiles agree along their borders) or has object ids
// (the objects are the segments, §3.3: their bounds, memory per object, so that small ones
// stay whole).
Status PlyChunking::scanFaces() {
  if (header_.hasNormals && !header_.hasObjectIds) return {};
  Result<PlyReader> faces = PlyReader::open(path_, faceReading());
  if (!faces) return faces.status();
  Progress progress(header_.hasNormals ? "tiles: objects" : "tiles: normals", header_.faceCount);
  while (true) {
    Result<bool> more = faces->next(batch_);
    if (!more) return more.status();
    if (!*more) break;
    if (batch_.kind != PlyBatch::Kind::kFaces) continue;
    for (std::size_t t = 0; t + 2 < batch_.triangles.size(); t += 3) {
      std::array<CutCorner, 3> triangle;
      LODFORGE_TRY(fetch(batch_, t, triangle));
      if (header_.hasObjectIds) {
        ObjectExtent& object = objects_[batch_.triangleObjects[t / 3]];
        for (const CutCorner& corner : triangle) object.bounds.add(corner.position);
        ++object.triangles;
      }
      if (!header_.hasNormals) {
        const Vec3f face = toFloat(cross(triangle[1].position - triangle[0].position,
                                         triangle[2].position - triangle[0].position));
        for (std::size_t k = 0; k < 3; ++k) {
          if (!cache_->addNormal(batch_.triangles[t + k], face))
            return ioErrorFromErrno(vertexPath_, "update");
        }
      }
    }
    progress.advance(batch_.count);
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  return {};
}

// The chunk grid over the bounds, its size fitted to where the objects are when there are some
// (small ones stay whole anyway).
Result<ChunkGrid> PlyChunking::chunkGrid() const {
  Result<double> fitted = chunkSizeFor(options_, input_.bounds, header_.faceCount);
  if (!fitted) return fitted.status();
  double size = *fitted;
  if (options_.chunkSize == 0 && header_.hasObjectIds) {
    const double fit =
        fitChunkSize(input_.bounds, leafTriangles(options_, header_.faceCount),
                     options_.trianglesPerChunk, [&](const auto& add) {
                       for (const auto& [id, object] : objects_)
                         add(object.bounds.center(), static_cast<double>(object.triangles));
                     });
    size = options_.levels > 0 ? std::min(size, fit) : fit;  // --levels: at least that small
  }
  return ChunkGrid::over(input_.bounds, size);
}

// Pass 2: faces, corners from the cache, into the chunk files (cut, or whole by segment). Three
// stages over batches of faces, so reading, cutting and writing overlap: read and fetch corners
// (the reader and the cache are sequential), cut (in parallel), add the pieces in file order
// (the chunk files come out the same as from one thread).
Status PlyChunking::cutFaces() {
  Result<ChunkGrid> grid = chunkGrid();
  if (!grid) return grid.status();
  grid_ = *grid;
  const std::string chunks = options_.workDirectory + "/chunks";
  input_.chunks = std::make_unique<ChunkWriter>(
      *grid_, sliced_ ? chunkPieceDirectory(chunks, clusterRank()) : chunks,
      options_.chunkBufferBytes, options_.keepInMemory);
  input_.chunks->setTextured(!input_.textures.empty());
  Result<PlyReader> faces = PlyReader::open(path_, faceReading());
  if (!faces) return faces.status();
  faces_ = std::move(*faces);
  read_ = faceReading().faceSlice.first;  // a slice's failures are placed in the whole file
  progress_.reset();
  // In slices, rank 0 shows the whole job's faces (JobProgress) instead of its own.
  if (!sliced_) progress_.emplace("tiles: chunks", header_.faceCount);
  // A few batches in flight: enough to keep every thread busy, little memory.
  const std::size_t tokens = static_cast<std::size_t>(std::max(2, options_.threads + 1));
  const auto pipeline = [&] {
    using Work = std::shared_ptr<FaceBatch>;
    tbb::parallel_pipeline(
        tokens, tbb::make_filter<void, Work>(
                    tbb::filter_mode::serial_in_order,
                    [&](tbb::flow_control& control) { return readFaceBatch(control); }) &
                    tbb::make_filter<Work, Work>(tbb::filter_mode::parallel,
                                                 [&](Work work) {
                                                   cutFaceBatch(*work);
                                                   return work;
                                                 }) &
                    tbb::make_filter<Work, void>(tbb::filter_mode::serial_in_order,
                                                 [&](const Work& work) { addFaceBatch(*work); }));
  };
  runOn(options_.threads, pipeline);
  LODFORGE_TRY(failure_.status());
  LODFORGE_TRY(input_.chunks->flush());
  if (progress_) progress_->finish();
  return {};
}

std::shared_ptr<FaceBatch> PlyChunking::readFaceBatch(tbb::flow_control& control) {
  while (true) {
    if (failure_.failed()) return control.stop(), nullptr;
    Status status = checkCancelled();
    Result<bool> more = status.ok() ? faces_->next(batch_) : Result<bool>(status);
    if (!more) return failure_.fail(read_, more.status(), &control), nullptr;
    if (!*more) return control.stop(), nullptr;
    if (batch_.kind != PlyBatch::Kind::kFaces) continue;
    read_ += batch_.count;
    auto next = std::make_shared<FaceBatch>();
    next->first = batch_.first;
    next->faces = batch_.count;
    next->triangles = batch_.triangles.size() / 3;
    next->corners.resize(batch_.triangles.size());
    next->pieces.reserve(batch_.triangles.size() + batch_.triangles.size() / 8);
    next->cells.reserve(next->triangles + next->triangles / 8);
    for (std::size_t t = 0; t + 2 < batch_.triangles.size(); t += 3) {
      std::array<CutCorner, 3> triangle;
      if (status = fetch(batch_, t, triangle); !status.ok())
        return failure_.fail(batch_.first, std::move(status), &control), nullptr;
      if (!input_.textures.materials.empty()) {
        if (status = texture(batch_, t, triangle); !status.ok())
          return failure_.fail(batch_.first, std::move(status), &control), nullptr;
      }
      std::copy(triangle.begin(), triangle.end(), next->corners.data() + t);
      if (header_.hasObjectIds) {
        const auto found = objects_.find(batch_.triangleObjects[t / 3]);
        next->segments.push_back(found == objects_.end() ? nullptr : &found->second.bounds);
      }
    }
    return next;
  }
}

void PlyChunking::cutFaceBatch(FaceBatch& work) const {
  std::array<CutCorner, 3> triangle;
  for (std::size_t t = 0; t < work.corners.size(); t += 3) {
    std::copy_n(work.corners.data() + t, 3, triangle.begin());
    cutSegmentTriangle(*grid_, work.segments.empty() ? nullptr : work.segments[t / 3], triangle,
                       work.cells, work.pieces);
  }
  work.corners = {};
}

void PlyChunking::addFaceBatch(const FaceBatch& work) {
  if (failure_.failedBefore(work.first)) return;  // as writeVertexBatch
  if (Status status = input_.chunks->addPieces(work.cells, work.pieces); !status.ok())
    return failure_.fail(work.first, std::move(status));
  input_.inputTriangles += work.triangles;
  facesDone_ += work.faces;
  if (progress_) progress_->advance(work.faces);
  if (sliced_) reportProgress("faces", facesDone_);
}

Status PlyChunking::joinBounds() {
  const Aabbd& own = input_.bounds;
  const std::array<std::uint64_t, 6> mine = {
      std::bit_cast<std::uint64_t>(own.min.x), std::bit_cast<std::uint64_t>(own.min.y),
      std::bit_cast<std::uint64_t>(own.min.z), std::bit_cast<std::uint64_t>(own.max.x),
      std::bit_cast<std::uint64_t>(own.max.y), std::bit_cast<std::uint64_t>(own.max.z)};
  Result<std::vector<std::uint64_t>> all = gatherAcrossRanks(mine);
  if (!all) return all.status();
  for (std::size_t at = 0; at + 6 <= all->size(); at += 6) {
    const auto value = [&](std::size_t k) { return std::bit_cast<double>((*all)[at + k]); };
    Aabbd bounds;
    bounds.min = {value(0), value(1), value(2)};
    bounds.max = {value(3), value(4), value(5)};
    input_.bounds.add(bounds);  // min and max: the same whatever the order
  }
  return {};
}

// The ranks' chunk counts added up; the chunks are read back from every rank's pieces.
Status PlyChunking::joinChunks() {
  std::vector<std::uint64_t> mine;
  for (const auto& [index, count] : input_.chunks->triangleCounts())
    mine.insert(mine.end(), {index, count});
  Result<std::vector<std::uint64_t>> all = gatherAcrossRanks(mine);
  if (!all) return all.status();
  std::map<std::uint64_t, std::uint64_t> counts;
  for (std::size_t at = 0; at + 2 <= all->size(); at += 2) counts[(*all)[at]] += (*all)[at + 1];
  Result<std::uint64_t> triangles = sumAcrossRanks(input_.inputTriangles);
  if (!triangles) return triangles.status();
  input_.inputTriangles = *triangles;
  assert(!input_.chunks->textured());  // plyFacesInSlices takes no textured file
  input_.chunks = std::make_unique<ChunkWriter>(ChunkWriter::reopen(
      *grid_, options_.workDirectory + "/chunks", std::move(counts), clusterSize()));
  return {};
}

// The vertex work file goes (in slices, rank 0 removes it once every rank is done with it);
// the input says where a salvaged file was cut short.
ChunkInput PlyChunking::finish() {
  std::error_code ignored;
  if (!sliced_) std::filesystem::remove(vertexPath_, ignored);
  input_.truncation = faces_->truncation() ? faces_->truncation() : vertices_->truncation();
  return std::move(input_);
}

}  // namespace

Result<ChunkInput> chunkPly(const std::string& path, const ChunkInputOptions& options) {
  PlyChunking chunking(path, options);
  LODFORGE_TRY(chunking.openVertices());
  LODFORGE_TRY(chunking.copyVertices());
  LODFORGE_TRY(chunking.openCache());
  LODFORGE_TRY(chunking.scanFaces());
  LODFORGE_TRY(chunking.cutFaces());
  return chunking.finish();
}

Result<std::uint64_t> plyFacesInSlices(const std::string& path, const ChunkInputOptions& options) {
  PlyReadOptions read;
  read.readFaces = false;
  Result<PlyReader> reader = PlyReader::open(path, read);
  if (!reader) return reader.status();
  const PlyHeader& header = reader->header();
  const bool sliceable = header.format != PlyFormat::kAscii && header.stripCount == 0 &&
                         header.hasNormals && !header.hasObjectIds && !header.hasUvs &&
                         !header.hasFaceUvs && !plyTextured(header) && !options.transform &&
                         !options.salvageTruncated && !options.keepInMemory;
  return sliceable ? header.faceCount : 0;
}

Result<ChunkInput> chunkPlyInSlices(const std::string& path, const ChunkInputOptions& options) {
  PlyChunking chunking(path, options, /*sliced=*/true);
  Status step = chunking.openVertices();
  if (step.ok()) step = chunking.copyVertices();
  LODFORGE_TRY(agreeAcrossRanks(step));
  LODFORGE_TRY(chunking.joinBounds());
  step = chunking.openCache();
  if (step.ok()) step = chunking.cutFaces();
  LODFORGE_TRY(agreeAcrossRanks(step));
  LODFORGE_TRY(chunking.joinChunks());
  ChunkInput input = chunking.finish();
  if (clusterRank() == 0) {
    std::error_code ignored;
    std::filesystem::remove(options.workDirectory + "/vertices.bin", ignored);
  }
  return input;
}

}  // namespace lodforge
