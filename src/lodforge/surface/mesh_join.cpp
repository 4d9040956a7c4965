#include "lodforge/surface/mesh_join.h"

#include <cassert>
#include <cstdio>
#include <numeric>

#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/ply_writer.h"

namespace lodforge {

// Union-find over the piece's vertices: a component is small when it has fewer triangles than
// asked and no vertex on a chunk face (one that crosses a face may go on in the next chunk).
std::vector<char> keptTriangles(const ChunkLayout& layout, const SurfacePiece& piece,
                                std::uint64_t minTriangles, std::uint64_t& dropped) {
  assert(piece.indices.size() % 3 == 0 && piece.edges.size() == piece.positions.size());
  const std::size_t triangles = piece.indices.size() / 3;
  std::vector<char> kept(triangles, 1);
  if (minTriangles == 0) return kept;
  std::vector<std::uint32_t> parent(piece.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::uint32_t a = find(piece.indices[3 * t]);
    parent[find(piece.indices[3 * t + 1])] = a;
    parent[find(piece.indices[3 * t + 2])] = a;
  }
  std::vector<std::uint64_t> size(parent.size(), 0);
  std::vector<char> crosses(parent.size(), 0);
  for (std::size_t t = 0; t < triangles; ++t) ++size[find(piece.indices[3 * t])];
  for (std::uint32_t v = 0; v < parent.size(); ++v)
    if (layout.onChunkFace(piece.edges[v])) crosses[find(v)] = 1;
  for (std::uint32_t v = 0; v < parent.size(); ++v)
    if (parent[v] == v && size[v] > 0 && size[v] < minTriangles && !crosses[v]) ++dropped;
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::uint32_t root = find(piece.indices[3 * t]);
    kept[t] = size[root] >= minTriangles || crosses[root] ? 1 : 0;
  }
  return kept;
}

Status PieceJoiner::begin(const ChunkLayout& layout, bool) {
  layout_ = layout;
  return {};
}

Status PieceJoiner::add(std::uint64_t chunk, const SurfacePiece& piece) {
  // The wavefront forgets a face vertex once its last chunk is past: chunks come in order.
  assert(chunk >= nextChunk_);
  assert(piece.normals.size() == piece.positions.size());
  assert(piece.colors.empty() || piece.colors.size() == piece.positions.size());
  nextChunk_ = chunk + 1;
  const std::vector<char> kept = keptTriangles(layout_, piece, minTriangles_, dropped_);
  constexpr std::uint32_t kNone = ~0u;
  local_.assign(piece.positions.size(), kNone);
  triangleBuffer_.clear();
  for (std::size_t t = 0; t < kept.size(); ++t) {
    if (!kept[t]) continue;
    for (std::size_t corner = 0; corner < 3; ++corner) {
      const std::uint32_t v = piece.indices[3 * t + corner];
      if (local_[v] == kNone) {
        const auto next = static_cast<std::uint32_t>(vertices_);
        bool fresh = true;
        if (layout_.onChunkFace(piece.edges[v])) {
          const auto [at, added] = shared_.try_emplace(piece.edges[v], next);
          if (added) expiry_.emplace(layout_.lastChunkHolding(piece.edges[v]), piece.edges[v]);
          fresh = added;
          local_[v] = at->second;
        } else {
          local_[v] = next;
        }
        if (fresh) {
          if (vertices_ >= ~0u)
            return Error{ErrorKind::kLimit,
                         "the surface has more than 4 G vertices, more than a PLY's 32-bit "
                         "indices name: use a larger --voxel"};
          JoinedVertex out{piece.positions[v], piece.normals[v], Rgba8{}};
          if (!piece.colors.empty()) out.color = piece.colors[v];
          LODFORGE_TRY(out_.vertex(out));
          ++vertices_;
        }
      }
      triangleBuffer_.push_back(local_[v]);
    }
  }
  triangles_ += triangleBuffer_.size() / 3;
  LODFORGE_TRY(out_.triangles(triangleBuffer_));
  // Face vertices no later chunk can hold.
  while (!expiry_.empty() && expiry_.top().first <= chunk) {
    shared_.erase(expiry_.top().second);
    expiry_.pop();
  }
  return {};
}

Status MemoryMeshOutput::vertex(const JoinedVertex& v) {
  positions.push_back(v.position);
  normals.push_back(v.normal);
  colors.push_back(v.color);
  return {};
}

Status MemoryMeshOutput::triangles(std::span<const std::uint32_t> more) {
  assert(more.size() % 3 == 0);
  indices.insert(indices.end(), more.begin(), more.end());
  return {};
}

Result<std::unique_ptr<PlyMeshOutput>> PlyMeshOutput::create(const std::string& directory) {
  Result<OutputFile> vertices = OutputFile::create(directory + "/mesh.vertices", 1 << 20);
  if (!vertices) return vertices.status();
  Result<OutputFile> triangles = OutputFile::create(directory + "/mesh.triangles", 1 << 20);
  if (!triangles) return triangles.status();
  return std::unique_ptr<PlyMeshOutput>(
      new PlyMeshOutput(std::move(*vertices), std::move(*triangles)));
}

Status PlyMeshOutput::vertex(const JoinedVertex& v) {
  bounds_.add(v.position);
  ++vertices_;
  return vertexFile_.write(&v, sizeof v);
}

Status PlyMeshOutput::triangles(std::span<const std::uint32_t> indices) {
  assert(indices.size() % 3 == 0);
  indices_ += indices.size();
  return triangleFile_.writeSpan(indices);
}

Status PlyMeshOutput::finish(const std::string& path, bool colors, const std::string& comment) {
  const std::string vertexPath = vertexFile_.path(), trianglePath = triangleFile_.path();
  LODFORGE_TRY(vertexFile_.commit());
  LODFORGE_TRY(triangleFile_.commit());
  // Geo-scale coordinates keep their millimetres as doubles around the centre.
  const bool far = !bounds_.empty() && length(bounds_.center()) > 1e4;
  const Vec3d origin = far ? bounds_.center() : Vec3d{};
  PlyLayout layout;
  layout.vertexCount = vertices_;
  layout.faceCount = indices_ / 3;
  layout.normals = true;
  layout.colors = colors;
  layout.doublePositions = far;
  layout.comments = {comment};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();
  Progress progress("reconstruct: writing", vertices_ + indices_ / 3);
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> rgba;
  LODFORGE_TRY(forEachFileBlock<JoinedVertex>(
      vertexPath, 1 << 15, [&](std::span<const JoinedVertex> block) -> Status {
        positions.resize(block.size());
        normals.resize(block.size());
        rgba.resize(colors ? block.size() : 0);
        for (std::size_t v = 0; v < block.size(); ++v) {
          positions[v] = toFloat(block[v].position - origin);
          normals[v] = block[v].normal;
          if (colors) rgba[v] = block[v].color;
        }
        progress.advance(block.size());
        LODFORGE_TRY(writer->writeVertices(positions, normals, rgba, origin));
        return checkCancelled();
      }));
  LODFORGE_TRY(forEachFileBlock<std::uint32_t>(trianglePath, 3 << 16,
                                               [&](std::span<const std::uint32_t> block) -> Status {
                                                 progress.advance(block.size() / 3);
                                                 LODFORGE_TRY(writer->writeTriangles(block));
                                                 return checkCancelled();
                                               }));
  std::remove(vertexPath.c_str());
  std::remove(trianglePath.c_str());
  progress.finish();
  return writer->finish();
}

}  // namespace lodforge
