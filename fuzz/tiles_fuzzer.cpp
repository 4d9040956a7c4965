// The work files of `lodforge tiles` (node meshes, chunk soups) on any bytes: the first byte picks
// the reader. Either a bad-input error naming the file, or a mesh whose every index is in range
// and whose colours, normals, features, texture coordinates and materials match its vertices.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

#include "lodforge/tiling/chunk_store.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  if (size == 0) return 0;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data) + 1, size - 1);
  const bool mesh = data[0] % 2 == 0;
  const std::string name = mesh ? "fuzz.mesh" : "fuzz.tri";
  const Result<MeshPart> part = mesh ? parseMesh(bytes, name) : parseChunk(bytes, name);
  if (!part) {
    if (part.error().kind != ErrorKind::kBadInput || part.error().message.rfind(name, 0) != 0) {
      std::fprintf(stderr, "unexpected error: %s\n", part.error().message.c_str());
      std::abort();
    }
    return 0;
  }
  if (part->indices.size() % 3 != 0) std::abort();
  if (!part->colors.empty() && part->colors.size() != part->positions.size()) std::abort();
  if (!part->normals.empty() && part->normals.size() != part->positions.size()) std::abort();
  if (!part->features.empty() && part->features.size() != part->positions.size()) std::abort();
  if (!part->uvs.empty() && part->uvs.size() != part->positions.size()) std::abort();
  if (part->materials.size() != part->uvs.size()) std::abort();
  for (std::uint32_t i : part->indices) {
    if (i >= part->positions.size()) std::abort();
  }
  return 0;
}
