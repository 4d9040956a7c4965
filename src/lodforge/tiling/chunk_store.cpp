#include "lodforge/tiling/chunk_store.h"

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/tiling/normal_codec.h"
#include "lodforge/tiling/weld.h"

namespace lodforge {

namespace {

// A chunk file is a run of blocks, one per append: magic, vertex count, triangle count (u32
// each), the vertex records, then three u32 indices per triangle into the block's records. A
// textured input's blocks ("LFCT") have longer records.
constexpr char kBlockMagic[4] = {'L', 'F', 'C', 'K'};
constexpr char kTexturedBlockMagic[4] = {'L', 'F', 'C', 'T'};
constexpr std::size_t kBlockHeaderBytes = sizeof kBlockMagic + 2 * sizeof(std::uint32_t);
// A vertex record: position (3 doubles), colour, normal (octahedral, 2 x 16 bits), feature; in
// a textured block then its texture coordinate (2 floats) and material.
constexpr std::size_t kCornerBytes = 3 * sizeof(double) + sizeof(Rgba8) + 2 * sizeof(std::uint32_t);
constexpr std::size_t kTexturedCornerBytes = kCornerBytes + sizeof(Vec2f) + sizeof(std::uint32_t);

std::size_t cornerBytes(bool textured) {
  return textured ? kTexturedCornerBytes : kCornerBytes;
}

void writeRecord(std::byte* out, const CutCorner& corner, bool textured) {
  const double xyz[3] = {corner.position.x, corner.position.y, corner.position.z};
  const std::uint32_t normal = encodeNormal(corner.normal);
  std::memcpy(out, xyz, sizeof xyz);
  std::memcpy(out + sizeof xyz, &corner.color, sizeof(Rgba8));
  std::memcpy(out + sizeof xyz + sizeof(Rgba8), &normal, sizeof normal);
  std::memcpy(out + sizeof xyz + sizeof(Rgba8) + sizeof normal, &corner.feature,
              sizeof corner.feature);
  if (!textured) return;
  std::memcpy(out + kCornerBytes, &corner.uv, sizeof(Vec2f));
  std::memcpy(out + kCornerBytes + sizeof(Vec2f), &corner.material, sizeof corner.material);
}

// Appends the vertex records in `bytes` (a whole number of them) to the mesh.
void appendRecords(std::span<const std::byte> bytes, MeshPart& mesh, bool textured) {
  const std::size_t size = cornerBytes(textured);
  const std::size_t first = mesh.positions.size(), count = bytes.size() / size;
  mesh.positions.resize(first + count);
  mesh.colors.resize(first + count);
  mesh.normals.resize(first + count);
  mesh.features.resize(first + count);
  if (textured) {
    mesh.uvs.resize(first + count);
    mesh.materials.resize(first + count);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* at = bytes.data() + i * size;
    if (textured) {
      std::memcpy(&mesh.uvs[first + i], at + kCornerBytes, sizeof(Vec2f));
      std::memcpy(&mesh.materials[first + i], at + kCornerBytes + sizeof(Vec2f),
                  sizeof(std::uint32_t));
    }
    double xyz[3];
    std::uint32_t normal;
    std::memcpy(xyz, at, sizeof xyz);
    mesh.positions[first + i] = {xyz[0], xyz[1], xyz[2]};
    std::memcpy(&mesh.colors[first + i], at + sizeof xyz, sizeof(Rgba8));
    std::memcpy(&normal, at + sizeof xyz + sizeof(Rgba8), sizeof normal);
    mesh.normals[first + i] = decodeNormal(normal);
    std::memcpy(&mesh.features[first + i], at + sizeof xyz + sizeof(Rgba8) + sizeof normal,
                sizeof(std::uint32_t));
  }
}

std::uint64_t hashSource(std::uint64_t key) {
  key ^= key >> 33;
  key *= 0xFF51AFD7ED558CCDull;
  return key ^ (key >> 33);
}

Status appendTo(const std::string& path, std::initializer_list<std::span<const std::byte>> parts) {
  std::FILE* file = std::fopen(path.c_str(), "ab");
  if (file == nullptr) return ioErrorFromErrno(path, "open for appending");
  bool ok = true;
  for (std::span<const std::byte> bytes : parts)
    ok = ok && std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  const bool closed = std::fclose(file) == 0;
  if (!ok || !closed) return ioErrorFromErrno(path, "append");
  return {};
}

}  // namespace

ChunkWriter::ChunkWriter(ChunkGrid grid, std::string directory, std::uint64_t bufferBytes,
                         bool keepInMemory)
    : grid_(grid),
      directory_(std::move(directory)),
      bufferBytes_(bufferBytes),
      keepInMemory_(keepInMemory) {
  // A failure shows when the first chunk file cannot be created (a constructor has no Status).
  std::error_code ignored;
  std::filesystem::create_directories(directory_, ignored);
}

ChunkWriter ChunkWriter::reopen(ChunkGrid grid, std::string directory,
                                std::map<std::uint64_t, std::uint64_t> counts, int pieces) {
  ChunkWriter writer(grid, std::move(directory), 0);
  for (const auto& [index, count] : counts) writer.triangles_ += count;
  writer.counts_ = std::move(counts);
  writer.pieces_ = pieces;
  return writer;
}

std::string ChunkWriter::chunkPath(const ChunkCell& cell) const {
  return fmt::format("{}/{}_{}_{}.tri", directory_, cell[0], cell[1], cell[2]);
}

std::string chunkPieceDirectory(const std::string& chunkDirectory, int r) {
  return fmt::format("{}/rank-{}", chunkDirectory, r);
}

std::vector<std::string> ChunkWriter::chunkFiles(const ChunkCell& cell) const {
  if (pieces_ == 0) return {chunkPath(cell)};
  std::vector<std::string> files;
  const std::string name = std::filesystem::path(chunkPath(cell)).filename().string();
  for (int r = 0; r < pieces_; ++r)
    files.push_back(chunkPieceDirectory(directory_, r) + "/" + name);
  return files;
}

Status ChunkWriter::add(const ChunkCell& cell, std::span<const CutCorner, 3> corners) {
  const std::uint64_t index = grid_.cellIndex(cell);
  if (index != lastIndex_ || lastBuffer_ == nullptr) {
    lastIndex_ = index;
    lastBuffer_ = &buffers_[index];
    lastCount_ = &counts_[index];
  }
  Buffer& buffer = *lastBuffer_;
  for (const CutCorner& corner : corners) buffer.indices.push_back(vertexOf(buffer, corner));
  ++*lastCount_;
  ++triangles_;
  buffered_ += 3 * sizeof(std::uint32_t);
  if (buffered_ >= bufferBytes_ && !keepInMemory_) return flush();
  return {};
}

std::uint32_t ChunkWriter::vertexOf(Buffer& buffer, const CutCorner& corner) {
  const auto addRecord = [&] {
    const std::size_t at = buffer.vertices.size();
    const std::size_t size = cornerBytes(textured_);
    buffer.vertices.resize(at + size);
    writeRecord(buffer.vertices.data() + at, corner, textured_);
    buffered_ += size;
    return static_cast<std::uint32_t>(at / size);
  };
  if (corner.source == CutCorner::kNoSource) return addRecord();  // made by a cut: weld later
  constexpr std::uint32_t kRun = 64, kNoRecord = ~0u;
  if (2 * (std::size_t{buffer.runCount} + 1) > buffer.runs.size()) {
    // Grow (a power of two, at most half full) and re-insert.
    const std::size_t capacity = std::max<std::size_t>(16, 2 * buffer.runs.size());
    std::vector<std::uint64_t> runs(capacity, 0);
    std::vector<std::uint32_t> runBlock(capacity);
    for (std::size_t i = 0; i < buffer.runs.size(); ++i) {
      if (buffer.runs[i] == 0) continue;
      std::size_t slot = hashSource(buffer.runs[i]) & (capacity - 1);
      while (runs[slot] != 0) slot = (slot + 1) & (capacity - 1);
      runs[slot] = buffer.runs[i];
      runBlock[slot] = buffer.runBlock[i];
    }
    buffered_ += (capacity - buffer.runs.size()) * (sizeof(std::uint64_t) + sizeof(std::uint32_t));
    buffer.runs = std::move(runs);
    buffer.runBlock = std::move(runBlock);
  }
  const std::uint64_t key = corner.source / kRun + 1;
  const std::size_t mask = buffer.runs.size() - 1;
  std::size_t slot = hashSource(key) & mask;
  while (buffer.runs[slot] != 0 && buffer.runs[slot] != key) slot = (slot + 1) & mask;
  if (buffer.runs[slot] == 0) {
    buffer.runs[slot] = key;
    buffer.runBlock[slot] = static_cast<std::uint32_t>(buffer.blocks.size() / kRun);
    buffer.blocks.resize(buffer.blocks.size() + kRun, kNoRecord);
    buffered_ += kRun * sizeof(std::uint32_t);
    ++buffer.runCount;
  }
  std::uint32_t& record =
      buffer.blocks[std::size_t{buffer.runBlock[slot]} * kRun + corner.source % kRun];
  if (record == kNoRecord) record = addRecord();
  return record;
}

Status ChunkWriter::addTriangle(const std::array<CutCorner, 3>& triangle) {
  pieceCells_.clear();
  pieceCorners_.clear();
  cutTriangle(grid_, triangle, pieceCells_, pieceCorners_);
  return addPieces(pieceCells_, pieceCorners_);
}

Status ChunkWriter::addSegmentTriangle(const Aabbd& segment,
                                       const std::array<CutCorner, 3>& triangle) {
  pieceCells_.clear();
  pieceCorners_.clear();
  cutSegmentTriangle(grid_, &segment, triangle, pieceCells_, pieceCorners_);
  return addPieces(pieceCells_, pieceCorners_);
}

Status ChunkWriter::addPieces(std::span<const ChunkCell> cells,
                              std::span<const CutCorner> corners) {
  assert(corners.size() == 3 * cells.size());
  for (std::size_t p = 0; p < cells.size(); ++p)
    LODFORGE_TRY(add(cells[p], std::span<const CutCorner, 3>(corners.data() + 3 * p, 3)));
  return {};
}

void cutSegmentTriangle(const ChunkGrid& grid, const Aabbd* segment,
                        const std::array<CutCorner, 3>& triangle, std::vector<ChunkCell>& cells,
                        std::vector<CutCorner>& corners) {
  if (segment != nullptr && segment->longestSide() < grid.size) {
    cells.push_back(grid.cellOf(segment->center()));
    corners.insert(corners.end(), triangle.begin(), triangle.end());
    return;
  }
  cutTriangle(grid, triangle, cells, corners);
}

Status ChunkWriter::flush() {
  if (keepInMemory_) return {};
  for (auto& [index, buffer] : buffers_) {
    if (buffer.indices.empty()) continue;
    std::byte header[kBlockHeaderBytes];
    const std::uint32_t counts[2] = {
        static_cast<std::uint32_t>(buffer.vertices.size() / cornerBytes(textured_)),
        static_cast<std::uint32_t>(buffer.indices.size() / 3)};
    std::memcpy(header, textured_ ? kTexturedBlockMagic : kBlockMagic, sizeof kBlockMagic);
    std::memcpy(header + sizeof kBlockMagic, counts, sizeof counts);
    LODFORGE_TRY(appendTo(chunkPath(cellOfIndex(grid_, index)),
                          {std::span<const std::byte>(header), buffer.vertices,
                           std::as_bytes(std::span(buffer.indices))}));
  }
  buffers_.clear();
  lastBuffer_ = nullptr;
  buffered_ = 0;
  return {};
}

Result<MeshPart> parseChunk(std::span<const std::byte> bytes, const std::string& name) {
  MeshPart mesh;
  std::size_t at = 0;
  while (at < bytes.size()) {
    if (bytes.size() - at < kBlockHeaderBytes)
      return badInputAtByte(name, at, "chunk file ends inside a block header");
    const bool textured =
        std::memcmp(bytes.data() + at, kTexturedBlockMagic, sizeof kBlockMagic) == 0;
    if (!textured && std::memcmp(bytes.data() + at, kBlockMagic, sizeof kBlockMagic) != 0)
      return badInputAtByte(name, at, "not a chunk block (work file of `lodforge tiles`)");
    if (at > 0 && textured != !mesh.uvs.empty())
      return badInputAtByte(name, at, "chunk blocks with and without textures in one file");
    std::uint32_t counts[2];
    std::memcpy(counts, bytes.data() + at + sizeof kBlockMagic, sizeof counts);
    const std::uint64_t recordBytes = std::uint64_t{counts[0]} * cornerBytes(textured);
    const std::uint64_t indexCount = 3 * std::uint64_t{counts[1]};
    const std::uint64_t rest = bytes.size() - at - kBlockHeaderBytes;
    if (recordBytes > rest || indexCount > (rest - recordBytes) / sizeof(std::uint32_t))
      return badInputAtByte(name, at, "chunk block runs past the end of the file");
    if (mesh.positions.size() + counts[0] > std::numeric_limits<std::uint32_t>::max())
      return badInputAtByte(name, at, "chunk file holds more than 2^32 vertices");
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    const std::byte* records = bytes.data() + at + kBlockHeaderBytes;
    appendRecords(std::span(records, static_cast<std::size_t>(recordBytes)), mesh, textured);
    const std::byte* indices = records + recordBytes;
    for (std::uint64_t i = 0; i < indexCount; ++i) {
      std::uint32_t v;
      std::memcpy(&v, indices + 4 * i, sizeof v);
      if (v >= counts[0])
        return badInputAtByte(name, static_cast<std::uint64_t>(indices - bytes.data()) + 4 * i,
                              "chunk file index out of range");
      mesh.indices.push_back(base + v);
    }
    at += kBlockHeaderBytes + static_cast<std::size_t>(recordBytes + 4 * indexCount);
  }
  // Positions and texture coordinates feed sorts and casts: damage must not reach them.
  LODFORGE_TRY(checkFinite(mesh, name));
  weldExact(mesh);
  return mesh;
}

Result<MeshPart> loadChunk(const std::string& path) {
  Result<std::vector<std::byte>> read = readFileBytes(path);
  if (!read) return read.error();
  return parseChunk(read.value(), path);
}

Result<MeshPart> ChunkWriter::load(const ChunkCell& cell) const {
  const auto it = buffers_.find(grid_.cellIndex(cell));
  if (it == buffers_.end() && pieces_ > 0) return loadPieces(cell);
  if (it == buffers_.end()) return loadChunk(chunkPath(cell));
  MeshPart mesh;
  appendRecords(it->second.vertices, mesh, textured_);
  mesh.indices = it->second.indices;
  weldExact(mesh);
  return mesh;
}

// Blocks follow one another: the pieces in rank order are the chunk as one writer makes it. A
// piece a rank wrote and this one cannot see (a shared file system out of step, a piece gone)
// shows in the triangle count, which must be the chunk's.
Result<MeshPart> ChunkWriter::loadPieces(const ChunkCell& cell) const {
  std::vector<std::byte> bytes;
  for (const std::string& piece : chunkFiles(cell)) {
    std::error_code missing;
    if (!std::filesystem::exists(piece, missing)) continue;  // a rank with none of it
    Result<std::vector<std::byte>> read = readFileBytes(piece);
    if (!read) return read.error();
    bytes.insert(bytes.end(), read->begin(), read->end());
  }
  const std::string name = chunkPath(cell);
  std::uint64_t triangles = 0;
  for (std::size_t at = 0; at + kBlockHeaderBytes <= bytes.size();) {
    const bool textured =
        std::memcmp(bytes.data() + at, kTexturedBlockMagic, sizeof kBlockMagic) == 0;
    std::uint32_t counts[2];
    std::memcpy(counts, bytes.data() + at + sizeof kBlockMagic, sizeof counts);
    triangles += counts[1];
    at += kBlockHeaderBytes + std::uint64_t{counts[0]} * cornerBytes(textured) +
          std::uint64_t{counts[1]} * 12;
  }
  const auto expected = counts_.find(grid_.cellIndex(cell));
  if (expected == counts_.end() || expected->second != triangles)
    return Error{ErrorKind::kIo,
                 fmt::format("{}: its pieces hold {} triangles, the ranks wrote {} (a piece "
                             "missing from the shared work directory?)",
                             name, triangles, expected == counts_.end() ? 0 : expected->second)};
  return parseChunk(bytes, name);
}

ChunkCell cellOfIndex(const ChunkGrid& grid, std::uint64_t index) {
  const auto dx = static_cast<std::uint64_t>(grid.dims[0]);
  const auto dy = static_cast<std::uint64_t>(grid.dims[1]);
  return {static_cast<std::int32_t>(index % dx), static_cast<std::int32_t>(index / dx % dy),
          static_cast<std::int32_t>(index / (dx * dy))};
}

}  // namespace lodforge
