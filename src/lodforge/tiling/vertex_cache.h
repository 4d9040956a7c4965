// The vertex work file of a streamed input (chunk_ply, chunk_obj) and the cache its faces'
// corners are fetched through: fixed-size records, a direct-mapped cache of blocks of them read
// with pread (meshes written in scan or grid order touch a few blocks at a time), blocks changed
// by addNormal written back when evicted and by flush().
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {

// A vertex record: position (3 doubles, or 3 floats when the input's are floats: exact, and the
// work file of a 500 M-vertex scan 6 GB smaller), colour, normal (3 floats; a sum of face normals
// while a normals pass accumulates it), then in a textured PLY's its texture coordinate.
struct VertexLayout {
  bool floatPositions = false;
  bool uvs = false;

  constexpr std::size_t positionBytes() const { return (floatPositions ? 4 : 8) * std::size_t{3}; }
  constexpr std::size_t normalOffset() const { return positionBytes() + sizeof(Rgba8); }
  constexpr std::size_t uvOffset() const { return normalOffset() + 3 * sizeof(float); }
  constexpr std::size_t bytes() const { return uvOffset() + (uvs ? sizeof(Vec2f) : 0); }
};

// Writes a vertex record in `layout` (`uv` only where the layout has one).
void writeVertexRecord(std::byte* record, const VertexLayout& layout, Vec3d position, Rgba8 color,
                       Vec3f normal, Vec2f uv = {});

class VertexCache {
 public:
  // `fd` holds `vertices` records in `layout`; the cache takes about `bytes`.
  VertexCache(int fd, std::uint64_t vertices, std::uint64_t bytes, VertexLayout layout);
  // Records of another kind (an OBJ's texture coordinates, normals), `recordBytes` each: read
  // through at() only.
  VertexCache(int fd, std::uint64_t vertices, std::uint64_t bytes, std::size_t recordBytes);

  // A vertex record's position, colour, normal (normalized) and, in longer records, texture
  // coordinate; false past the end or when the file cannot be read.
  bool fetch(std::uint64_t vertex, CutCorner& out);
  // Adds to a vertex record's normal.
  bool addNormal(std::uint64_t vertex, Vec3f add);
  // Any record's bytes (records of other layouts: an OBJ's texture coordinates, normals);
  // nullptr past the end or when the file cannot be read. Valid until the next call.
  const std::byte* at(std::uint64_t index) { return record(index); }
  bool flush();

 private:
  std::byte* record(std::uint64_t vertex);
  std::uint64_t blockVertices(std::uint64_t block) const;
  bool writeBack(std::uint64_t slot);

  int fd_;
  std::uint64_t vertices_;
  std::optional<VertexLayout> layout_;  // none for records of another kind
  std::size_t recordBytes_;
  std::uint64_t slots_ = 0;
  std::vector<std::byte> data_;
  std::vector<std::uint64_t> tags_;
  std::vector<std::uint8_t> dirty_;
};

}  // namespace lodforge
