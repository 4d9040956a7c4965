#include "lodforge/tiling/chunk_store.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/position_hash.h"

namespace lodforge {

void weldExact(MeshPart& mesh) {
  // A mesh of no objects (a scan: chunk records always carry the field) keeps no features.
  if (std::all_of(mesh.features.begin(), mesh.features.end(),
                  [](std::uint32_t f) { return f == kNoFeature; }))
    mesh.features.clear();
  const std::uint32_t count = mesh.vertexCount();
  // Each vertex points at the first vertex (lowest index) with its position: an open-addressing
  // table keyed by position, filled in vertex order.
  std::size_t capacity = 16;
  while (capacity < 2 * std::size_t{count}) capacity *= 2;
  std::vector<std::uint32_t> table(capacity, ~0u);
  std::vector<std::uint32_t> representative(count);
  const bool features = !mesh.features.empty();
  const auto featureOf = [&](std::uint32_t v) { return features ? mesh.features[v] : kNoFeature; };
  for (std::uint32_t v = 0; v < count; ++v) {
    const Vec3d& p = mesh.positions[v];
    const std::uint32_t feature = featureOf(v);
    std::size_t slot = (hashExactPosition(p) ^ feature * 0x9E3779B97F4A7C15ull) & (capacity - 1);
    while (table[slot] != ~0u &&
           !(mesh.positions[table[slot]] == p && featureOf(table[slot]) == feature))
      slot = (slot + 1) & (capacity - 1);
    if (table[slot] == ~0u) table[slot] = v;
    representative[v] = table[slot];
  }
  // Triangles over representatives; drop those that repeat a corner.
  std::size_t kept = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = representative[mesh.indices[t]],
                        b = representative[mesh.indices[t + 1]],
                        c = representative[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  // Renumber the used vertices in order of first use.
  std::vector<std::uint32_t> remap(count, ~0u);
  std::uint32_t next = 0;
  for (std::uint32_t& v : mesh.indices) {
    if (remap[v] == ~0u) remap[v] = next++;
    v = remap[v];
  }
  std::vector<Vec3d> positions(next);
  std::vector<Rgba8> colors(mesh.colors.empty() ? 0 : next);
  std::vector<Vec3f> normals(mesh.normals.empty() ? 0 : next);
  std::vector<std::uint32_t> featureOfVertex(features ? next : 0);
  // The members of each group whose normals were summed, as a list through `summedNext`.
  std::vector<std::uint32_t> summedHead(normals.empty() ? 0 : next, ~0u);
  std::vector<std::uint32_t> summedNext(normals.empty() ? 0 : count, ~0u);
  for (std::uint32_t v = 0; v < count; ++v) {
    // Distinct normals of a group are averaged (a part's hard edge, split in the input, meets
    // here); a normal seen already in the group is the same vertex stored again.
    const std::uint32_t to = remap[representative[v]];
    if (to != ~0u && !normals.empty()) {
      bool seen = false;
      for (std::uint32_t m = summedHead[to]; m != ~0u && !seen; m = summedNext[m])
        seen = mesh.normals[m] == mesh.normals[v];
      if (!seen) {
        normals[to] = normals[to] + mesh.normals[v];
        summedNext[v] = summedHead[to];
        summedHead[to] = v;
      }
    }
    if (remap[v] == ~0u) continue;  // not a representative, or unused
    positions[remap[v]] = mesh.positions[v];
    if (!colors.empty()) colors[remap[v]] = mesh.colors[v];
    if (features) featureOfVertex[remap[v]] = mesh.features[v];
  }
  for (std::size_t v = 0; v < normals.size(); ++v)
    normals[v] = normalizeOr(normals[v], Vec3f{0, 0, 1});
  mesh.positions = std::move(positions);
  mesh.colors = std::move(colors);
  mesh.normals = std::move(normals);
  mesh.features = std::move(featureOfVertex);
}

std::vector<std::uint32_t> distinctFeatures(const MeshPart& mesh) {
  std::vector<std::uint32_t> out(mesh.features);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (!out.empty() && out.back() == kNoFeature) out.pop_back();
  return out;
}

MeshPart concatenate(std::span<const MeshPart> parts) {
  MeshPart out;
  const bool colors =
      std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.colors.empty(); });
  const bool normals =
      std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.normals.empty(); });
  const bool features = std::any_of(parts.begin(), parts.end(),
                                    [](const MeshPart& p) { return !p.features.empty(); });
  for (const MeshPart& part : parts) {
    const std::uint32_t base = out.vertexCount();
    out.positions.insert(out.positions.end(), part.positions.begin(), part.positions.end());
    if (colors) {
      if (part.colors.empty()) {
        out.colors.resize(out.positions.size(), Rgba8{255, 255, 255, 255});
      } else {
        out.colors.insert(out.colors.end(), part.colors.begin(), part.colors.end());
      }
    }
    if (normals) {
      if (part.normals.empty()) {
        out.normals.resize(out.positions.size(), Vec3f{0, 0, 1});
      } else {
        out.normals.insert(out.normals.end(), part.normals.begin(), part.normals.end());
      }
    }
    if (features) {
      if (part.features.empty()) {
        out.features.resize(out.positions.size(), kNoFeature);
      } else {
        out.features.insert(out.features.end(), part.features.begin(), part.features.end());
      }
    }
    for (std::uint32_t i : part.indices) out.indices.push_back(base + i);
  }
  return out;
}

namespace {

constexpr char kMeshMagic[8] = {'L', 'F', 'M', 'E', 'S', 'H', '3', '\0'};
// A chunk file is a run of blocks, one per append: magic, vertex count, triangle count (u32
// each), the vertex records, then three u32 indices per triangle into the block's records.
constexpr char kBlockMagic[4] = {'L', 'F', 'C', 'K'};
constexpr std::size_t kBlockHeaderBytes = sizeof kBlockMagic + 2 * sizeof(std::uint32_t);
// A vertex record: position (3 doubles), colour, normal (octahedral, 2 x 16 bits), feature.
constexpr std::size_t kCornerBytes = 3 * sizeof(double) + sizeof(Rgba8) + 2 * sizeof(std::uint32_t);

// Octahedral encoding of a unit normal (Cigolle et al. 2014): 0.005 degrees at 16 bits per
// axis, a third of the bytes of three floats in every chunk-file corner.
std::uint32_t encodeNormal(Vec3f n) {
  const float sum = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  if (!(sum > 0)) return 0;  // unknown: decodes to +z
  float u = n.x / sum, v = n.y / sum;
  if (n.z < 0) {
    const float fu = (1 - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
    const float fv = (1 - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
    u = fu, v = fv;
  }
  const auto snorm = [](float x) {
    return static_cast<std::uint16_t>(static_cast<std::int16_t>(roundToLong(x * 32767.0f)));
  };
  return static_cast<std::uint32_t>(snorm(u)) | static_cast<std::uint32_t>(snorm(v)) << 16;
}

Vec3f decodeNormal(std::uint32_t packed) {
  const float u = static_cast<float>(static_cast<std::int16_t>(packed & 0xFFFF)) / 32767.0f;
  const float v = static_cast<float>(static_cast<std::int16_t>(packed >> 16)) / 32767.0f;
  Vec3f n{u, v, 1 - std::abs(u) - std::abs(v)};
  if (n.z < 0) {
    n.x = (1 - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
    n.y = (1 - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
  }
  return normalizeOr(n, Vec3f{0, 0, 1});
}

void writeRecord(std::byte* out, const CutCorner& corner) {
  const double xyz[3] = {corner.position.x, corner.position.y, corner.position.z};
  const std::uint32_t normal = encodeNormal(corner.normal);
  std::memcpy(out, xyz, sizeof xyz);
  std::memcpy(out + sizeof xyz, &corner.color, sizeof(Rgba8));
  std::memcpy(out + sizeof xyz + sizeof(Rgba8), &normal, sizeof normal);
  std::memcpy(out + sizeof xyz + sizeof(Rgba8) + sizeof normal, &corner.feature,
              sizeof corner.feature);
}

// Appends the vertex records in `bytes` (a whole number of them) to the mesh.
void appendRecords(std::span<const std::byte> bytes, MeshPart& mesh) {
  const std::size_t first = mesh.positions.size(), count = bytes.size() / kCornerBytes;
  mesh.positions.resize(first + count);
  mesh.colors.resize(first + count);
  mesh.normals.resize(first + count);
  mesh.features.resize(first + count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* at = bytes.data() + i * kCornerBytes;
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

Result<std::vector<std::byte>> readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return ioError(path, "cannot open");
  const auto size = static_cast<std::size_t>(in.tellg());
  std::vector<std::byte> bytes(size);
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)))
    return ioError(path, "cannot read");
  return bytes;
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

Status saveMesh(const MeshPart& mesh, const std::string& path) {
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  const std::uint64_t header[5] = {mesh.positions.size(), mesh.colors.size(), mesh.normals.size(),
                                   mesh.features.size(), mesh.indices.size()};
  LODFORGE_TRY(out->write(kMeshMagic, sizeof kMeshMagic));
  LODFORGE_TRY(out->write(header, sizeof header));
  LODFORGE_TRY(out->writeSpan(std::span<const Vec3d>(mesh.positions)));
  LODFORGE_TRY(out->writeSpan(std::span<const Rgba8>(mesh.colors)));
  LODFORGE_TRY(out->writeSpan(std::span<const Vec3f>(mesh.normals)));
  LODFORGE_TRY(out->writeSpan(std::span<const std::uint32_t>(mesh.features)));
  LODFORGE_TRY(out->writeSpan(std::span<const std::uint32_t>(mesh.indices)));
  return out->commit();
}

Result<MeshPart> loadMesh(const std::string& path) {
  Result<std::vector<std::byte>> read = readWhole(path);
  if (!read) return read.error();
  return parseMesh(read.value(), path);
}

Result<MeshPart> parseMesh(std::span<const std::byte> bytes, const std::string& name) {
  std::uint64_t header[5];
  if (bytes.size() < sizeof kMeshMagic + sizeof header ||
      std::memcmp(bytes.data(), kMeshMagic, sizeof kMeshMagic) != 0)
    return badInputAtByte(name, 0, "not a lodforge mesh file (work file of `lodforge tiles`)");
  std::memcpy(header, bytes.data() + sizeof kMeshMagic, sizeof header);
  // Counts first, in a way that cannot overflow: each must fit the bytes that are there.
  const std::uint64_t body = bytes.size() - sizeof kMeshMagic - sizeof header;
  const std::uint64_t sizes[5] = {sizeof(Vec3d), sizeof(Rgba8), sizeof(Vec3f),
                                  sizeof(std::uint32_t), sizeof(std::uint32_t)};
  std::uint64_t total = 0;
  for (int i = 0; i < 5; ++i) {
    if (header[i] > body / sizes[i])
      return badInputAtByte(name, sizeof kMeshMagic, "mesh file sizes do not match its counts");
    total += header[i] * sizes[i];
  }
  if (total != body || (header[1] != 0 && header[1] != header[0]) ||
      (header[2] != 0 && header[2] != header[0]) || (header[3] != 0 && header[3] != header[0]) ||
      header[4] % 3 != 0)
    return badInputAtByte(name, sizeof kMeshMagic, "mesh file sizes do not match its counts");
  MeshPart mesh;
  mesh.positions.resize(header[0]);
  mesh.colors.resize(header[1]);
  mesh.normals.resize(header[2]);
  mesh.features.resize(header[3]);
  mesh.indices.resize(header[4]);
  const std::byte* at = bytes.data() + sizeof kMeshMagic + sizeof header;
  // (memcpy of nothing from or to an empty vector's null data() is undefined, hence the guards)
  const auto take = [&at](void* to, std::uint64_t count, std::uint64_t size) {
    if (count > 0) std::memcpy(to, at, count * size);
    at += count * size;
  };
  take(mesh.positions.data(), header[0], sizeof(Vec3d));
  take(mesh.colors.data(), header[1], sizeof(Rgba8));
  take(mesh.normals.data(), header[2], sizeof(Vec3f));
  take(mesh.features.data(), header[3], sizeof(std::uint32_t));
  const std::byte* indicesAt = at;
  take(mesh.indices.data(), header[4], sizeof(std::uint32_t));
  for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= header[0])
      return badInputAtByte(name, static_cast<std::uint64_t>(indicesAt - bytes.data()) + 4 * i,
                            "mesh file index out of range");
  }
  return mesh;
}

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
                                std::map<std::uint64_t, std::uint64_t> counts) {
  ChunkWriter writer(grid, std::move(directory), 0);
  for (const auto& [index, count] : counts) writer.triangles_ += count;
  writer.counts_ = std::move(counts);
  return writer;
}

std::string ChunkWriter::chunkPath(const ChunkCell& cell) const {
  return fmt::format("{}/{}_{}_{}.tri", directory_, cell[0], cell[1], cell[2]);
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
    buffer.vertices.resize(at + kCornerBytes);
    writeRecord(buffer.vertices.data() + at, corner);
    buffered_ += kCornerBytes;
    return static_cast<std::uint32_t>(at / kCornerBytes);
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
        static_cast<std::uint32_t>(buffer.vertices.size() / kCornerBytes),
        static_cast<std::uint32_t>(buffer.indices.size() / 3)};
    std::memcpy(header, kBlockMagic, sizeof kBlockMagic);
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
    if (std::memcmp(bytes.data() + at, kBlockMagic, sizeof kBlockMagic) != 0)
      return badInputAtByte(name, at, "not a chunk block (work file of `lodforge tiles`)");
    std::uint32_t counts[2];
    std::memcpy(counts, bytes.data() + at + sizeof kBlockMagic, sizeof counts);
    const std::uint64_t recordBytes = std::uint64_t{counts[0]} * kCornerBytes;
    const std::uint64_t indexCount = 3 * std::uint64_t{counts[1]};
    const std::uint64_t rest = bytes.size() - at - kBlockHeaderBytes;
    if (recordBytes > rest || indexCount > (rest - recordBytes) / sizeof(std::uint32_t))
      return badInputAtByte(name, at, "chunk block runs past the end of the file");
    if (mesh.positions.size() + counts[0] > std::numeric_limits<std::uint32_t>::max())
      return badInputAtByte(name, at, "chunk file holds more than 2^32 vertices");
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    const std::byte* records = bytes.data() + at + kBlockHeaderBytes;
    appendRecords(std::span(records, static_cast<std::size_t>(recordBytes)), mesh);
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
  weldExact(mesh);
  return mesh;
}

Result<MeshPart> loadChunk(const std::string& path) {
  Result<std::vector<std::byte>> read = readWhole(path);
  if (!read) return read.error();
  return parseChunk(read.value(), path);
}

Result<MeshPart> ChunkWriter::load(const ChunkCell& cell) const {
  const auto it = buffers_.find(grid_.cellIndex(cell));
  if (it == buffers_.end()) return loadChunk(chunkPath(cell));
  MeshPart mesh;
  appendRecords(it->second.vertices, mesh);
  mesh.indices = it->second.indices;
  weldExact(mesh);
  return mesh;
}

ChunkCell cellOfIndex(const ChunkGrid& grid, std::uint64_t index) {
  const auto dx = static_cast<std::uint64_t>(grid.dims[0]);
  const auto dy = static_cast<std::uint64_t>(grid.dims[1]);
  return {static_cast<std::int32_t>(index % dx), static_cast<std::int32_t>(index / dx % dy),
          static_cast<std::int32_t>(index / (dx * dy))};
}

}  // namespace lodforge
