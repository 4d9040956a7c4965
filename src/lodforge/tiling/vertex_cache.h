// The vertex work file of a streamed input (chunk_ply, chunk_obj) and the cache its faces'
// corners are fetched through: fixed-size records, a direct-mapped cache of blocks of them read
// with pread (meshes written in scan or grid order touch a few blocks at a time), blocks changed
// by addNormal written back when evicted and by flush().
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {

// A vertex record: position (3 doubles), colour, normal (3 floats; a sum of face normals while a
// normals pass accumulates it); for a textured PLY then its texture coordinate (2 floats).
inline constexpr std::size_t kVertexBytes = 3 * sizeof(double) + sizeof(Rgba8) + 3 * sizeof(float);
inline constexpr std::size_t kNormalOffset = 3 * sizeof(double) + sizeof(Rgba8);
inline constexpr std::size_t kUvBytes = sizeof(Vec2f);

// Writes vertex records in the layout above.
void writeVertexRecord(std::byte* record, Vec3d position, Rgba8 color, Vec3f normal);

class VertexCache {
 public:
  // `fd` holds `vertices` records of `recordBytes`; the cache takes about `bytes`.
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
  std::size_t recordBytes_;
  std::uint64_t slots_ = 0;
  std::vector<std::byte> data_;
  std::vector<std::uint64_t> tags_;
  std::vector<std::uint8_t> dirty_;
};

}  // namespace lodforge
