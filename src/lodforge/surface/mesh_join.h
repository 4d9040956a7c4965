// The chunks' pieces joined into one mesh as they come, in chunk order: a vertex on a chunk face
// is one vertex (by the name of its lattice edge), kept in a map only until the last chunk that
// holds its edge is done, so the map holds a wavefront of chunk faces, not the mesh. Vertices
// and triangles go to an output as they are joined (memory, or files for a mesh larger than RAM).
#pragma once

#include <cstdint>
#include <memory>
#include <queue>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/marching_tetrahedra.h"

namespace lodforge {

struct JoinedVertex {
  Vec3d position;
  Vec3f normal;
  Rgba8 color;
};
static_assert(sizeof(JoinedVertex) == 40);

class MeshOutput {
 public:
  virtual ~MeshOutput() = default;
  virtual Status vertex(const JoinedVertex& v) = 0;
  virtual Status triangles(std::span<const std::uint32_t> indices) = 0;
};

// Where a reconstruction hands its chunks' pieces: a joined mesh (PieceJoiner) or the chunks of
// a tileset (tiles/surface_input).
class PieceSink {
 public:
  virtual ~PieceSink() = default;
  // Once, before the first piece: the lattice and whether the points have colours.
  virtual Status begin(const ChunkLayout& layout, bool colors) = 0;
  // Chunks in ascending order.
  virtual Status add(std::uint64_t chunk, const SurfacePiece& piece) = 0;
};

// Which of a piece's triangles stay when connected pieces with fewer than `minTriangles`
// triangles that touch no chunk face are dropped (a piece that crosses a face is kept: its size
// is only known globally); `dropped` counts the pieces dropped.
std::vector<char> keptTriangles(const ChunkLayout& layout, const SurfacePiece& piece,
                                std::uint64_t minTriangles, std::uint64_t& dropped);

class PieceJoiner : public PieceSink {
 public:
  PieceJoiner(std::uint64_t minTriangles, MeshOutput& out)
      : minTriangles_(minTriangles), out_(out) {}

  Status begin(const ChunkLayout& layout, bool colors) override;
  Status add(std::uint64_t chunk, const SurfacePiece& piece) override;

  std::uint64_t vertices() const { return vertices_; }
  std::uint64_t triangles() const { return triangles_; }
  std::uint64_t droppedPieces() const { return dropped_; }
  std::size_t faceVerticesHeld() const { return shared_.size(); }

 private:
  ChunkLayout layout_;
  std::uint64_t minTriangles_;
  MeshOutput& out_;
  std::unordered_map<std::uint64_t, std::uint32_t> shared_;  // face vertices still wanted
  // (last chunk holding the edge, edge): popped once that chunk is done.
  std::priority_queue<std::pair<std::uint64_t, std::uint64_t>,
                      std::vector<std::pair<std::uint64_t, std::uint64_t>>, std::greater<>>
      expiry_;
  std::vector<std::uint32_t> local_;
  std::vector<std::uint32_t> triangleBuffer_;
  std::uint64_t vertices_ = 0, triangles_ = 0, dropped_ = 0;
  std::uint64_t nextChunk_ = 0;  // the least chunk add() may take next
};

// Into memory.
class MemoryMeshOutput : public MeshOutput {
 public:
  Status vertex(const JoinedVertex& v) override;
  Status triangles(std::span<const std::uint32_t> indices) override;
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> indices;
};

// Into two work files in `directory`, made one binary PLY at the end.
class PlyMeshOutput : public MeshOutput {
 public:
  static Result<std::unique_ptr<PlyMeshOutput>> create(const std::string& directory);
  Status vertex(const JoinedVertex& v) override;
  Status triangles(std::span<const std::uint32_t> indices) override;
  // Writes `path` (under a temporary name renamed when complete): double positions when the
  // mesh is far from the origin, normals, colours when `colors`.
  Status finish(const std::string& path, bool colors, const std::string& comment);

 private:
  PlyMeshOutput(OutputFile vertices, OutputFile triangles)
      : vertexFile_(std::move(vertices)), triangleFile_(std::move(triangles)) {}
  OutputFile vertexFile_, triangleFile_;
  Aabbd bounds_;
  std::uint64_t vertices_ = 0, indices_ = 0;
};

}  // namespace lodforge
