#include "lodforge/tiling/mesh_file.h"

#include <cmath>
#include <cstdint>
#include <cstring>

#include "lodforge/core/file.h"

namespace lodforge {

namespace {

// Then seven u64 counts (positions, colours, normals, features, UVs, materials, indices) and
// the arrays.
constexpr char kMeshMagic[8] = {'L', 'F', 'M', 'E', 'S', 'H', '4', '\0'};
constexpr int kArrays = 7;

}  // namespace

Status checkFinite(const MeshPart& mesh, const std::string& name) {
  for (const Vec3d& p : mesh.positions)
    if (!isFinite(p))
      return badInput(name, "a position is not a finite number (damaged work file?)");
  for (const Vec2f& uv : mesh.uvs)
    if (!(std::abs(uv.x) < 1e30f && std::abs(uv.y) < 1e30f))
      return badInput(name, "a texture coordinate is not a finite number (damaged work file?)");
  return {};
}

Status saveMesh(const MeshPart& mesh, const std::string& path) {
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  const std::uint64_t header[kArrays] = {
      mesh.positions.size(), mesh.colors.size(),    mesh.normals.size(), mesh.features.size(),
      mesh.uvs.size(),       mesh.materials.size(), mesh.indices.size()};
  LODFORGE_TRY(out->write(kMeshMagic, sizeof kMeshMagic));
  LODFORGE_TRY(out->write(header, sizeof header));
  LODFORGE_TRY(out->writeSpan(std::span<const Vec3d>(mesh.positions)));
  LODFORGE_TRY(out->writeSpan(std::span<const Rgba8>(mesh.colors)));
  LODFORGE_TRY(out->writeSpan(std::span<const Vec3f>(mesh.normals)));
  LODFORGE_TRY(out->writeSpan(std::span<const std::uint32_t>(mesh.features)));
  LODFORGE_TRY(out->writeSpan(std::span<const Vec2f>(mesh.uvs)));
  LODFORGE_TRY(out->writeSpan(std::span<const std::uint32_t>(mesh.materials)));
  LODFORGE_TRY(out->writeSpan(std::span<const std::uint32_t>(mesh.indices)));
  return out->commit();
}

Result<MeshPart> loadMesh(const std::string& path) {
  Result<std::vector<std::byte>> read = readFileBytes(path);
  if (!read) return read.error();
  return parseMesh(read.value(), path);
}

Result<MeshPart> parseMesh(std::span<const std::byte> bytes, const std::string& name) {
  std::uint64_t header[kArrays];
  if (bytes.size() < sizeof kMeshMagic + sizeof header ||
      std::memcmp(bytes.data(), kMeshMagic, sizeof kMeshMagic) != 0)
    return badInputAtByte(name, 0, "not a lodforge mesh file (work file of `lodforge tiles`)");
  std::memcpy(header, bytes.data() + sizeof kMeshMagic, sizeof header);
  // Counts first, in a way that cannot overflow: each must fit the bytes that are there.
  const std::uint64_t body = bytes.size() - sizeof kMeshMagic - sizeof header;
  const std::uint64_t sizes[kArrays] = {sizeof(Vec3d),         sizeof(Rgba8), sizeof(Vec3f),
                                        sizeof(std::uint32_t), sizeof(Vec2f), sizeof(std::uint32_t),
                                        sizeof(std::uint32_t)};
  std::uint64_t total = 0;
  for (int i = 0; i < kArrays; ++i) {
    if (header[i] > body / sizes[i])
      return badInputAtByte(name, sizeof kMeshMagic, "mesh file sizes do not match its counts");
    total += header[i] * sizes[i];
  }
  if (total != body || (header[1] != 0 && header[1] != header[0]) ||
      (header[2] != 0 && header[2] != header[0]) || (header[3] != 0 && header[3] != header[0]) ||
      (header[4] != 0 && header[4] != header[0]) || header[5] != header[4] || header[6] % 3 != 0)
    return badInputAtByte(name, sizeof kMeshMagic, "mesh file sizes do not match its counts");
  MeshPart mesh;
  mesh.positions.resize(header[0]);
  mesh.colors.resize(header[1]);
  mesh.normals.resize(header[2]);
  mesh.features.resize(header[3]);
  mesh.uvs.resize(header[4]);
  mesh.materials.resize(header[5]);
  mesh.indices.resize(header[6]);
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
  take(mesh.uvs.data(), header[4], sizeof(Vec2f));
  take(mesh.materials.data(), header[5], sizeof(std::uint32_t));
  const std::byte* indicesAt = at;
  take(mesh.indices.data(), header[6], sizeof(std::uint32_t));
  for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= header[0])
      return badInputAtByte(name, static_cast<std::uint64_t>(indicesAt - bytes.data()) + 4 * i,
                            "mesh file index out of range");
  }
  LODFORGE_TRY(checkFinite(mesh, name));
  return mesh;
}

}  // namespace lodforge
