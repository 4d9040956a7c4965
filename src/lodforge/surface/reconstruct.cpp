#include "lodforge/surface/reconstruct.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/ply_writer.h"
#include "lodforge/io/point_reader.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {

namespace {

// Bytes a point costs here: position, normal, colour, its chunk lists, and the neighbour
// search of the normal estimate (k indices and the graph).
constexpr std::uint64_t kBytesPerPoint = 24 + 12 + 4 + 8 + 12 * 4 * 3;
// Bytes of one chunk in flight per corner: the weight and sum (doubles), count and value.
constexpr std::uint64_t kBytesPerCorner = 8 + 8 + 12 + 12 + 4 + 4;

struct Layout {
  VoxelGrid grid;
  std::uint32_t n = 64;  // voxels along a chunk's edge
  std::array<std::uint64_t, 3> chunks{};
  std::uint64_t chunkCount() const { return chunks[0] * chunks[1] * chunks[2]; }
};

Result<Layout> layOut(std::span<const Vec3d> positions, const PointIndex* index,
                      const std::string& name, const ReconstructOptions& options) {
  if (positions.size() < 4)
    return badInput(name, fmt::format("{} points are too few for a surface: it takes at least 4, "
                                      "and enough to cover the surface at the voxel size",
                                      positions.size()));
  Aabbd bounds;
  for (const Vec3d& p : positions) bounds.add(p);
  int spread = 0;
  for (int a = 0; a < 3; ++a) spread += bounds.max[a] > bounds.min[a] ? 1 : 0;
  if (spread < 2)
    return badInput(name,
                    "all points lie on a line or at one position: a surface needs points "
                    "spread in two directions at least");
  double voxel = options.voxel;
  if (voxel <= 0) voxel = 2 * medianSpacing(positions, *index);
  if (!(voxel > 0) || !std::isfinite(voxel))
    return badInput(name, "the points have no spacing to size voxels by: give --voxel");
  Layout layout;
  layout.n = std::max<std::uint32_t>(2, options.chunkVoxels);
  const auto margin = static_cast<std::uint64_t>(std::ceil(options.distance.radius)) + 1;
  layout.grid.voxel = voxel;
  double corners = 1;
  for (int a = 0; a < 3; ++a) {
    layout.grid.origin[a] = bounds.min[a] - static_cast<double>(margin) * voxel;
    const double along =
        std::ceil((bounds.max[a] - bounds.min[a]) / voxel) + 2.0 * static_cast<double>(margin) + 1;
    corners *= along;
    layout.grid.corners[static_cast<std::size_t>(a)] = static_cast<std::uint64_t>(along);
  }
  // Edge names count corners × 7 in 64 bits; far below that, the mesh would not fit anywhere.
  if (corners > 1e15)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: voxel {:g} is too small for a cloud {:g} across ({:.3g} grid "
                             "corners); try --voxel {:g} or larger",
                             name, voxel, length(bounds.max - bounds.min), corners,
                             length(bounds.max - bounds.min) / 10'000)};
  for (std::size_t a = 0; a < 3; ++a)
    layout.chunks[a] =
        std::max<std::uint64_t>(1, (layout.grid.corners[a] - 1 + layout.n - 1) / layout.n);
  return layout;
}

// The chunks each point reaches (those holding a corner within the radius), points in order.
std::vector<std::vector<std::uint32_t>> bucket(std::span<const Vec3d> positions,
                                               const Layout& layout, double radius) {
  std::vector<std::vector<std::uint32_t>> members(static_cast<std::size_t>(layout.chunkCount()));
  const std::uint64_t n = layout.n;
  for (std::uint32_t i = 0; i < positions.size(); ++i) {
    std::array<std::uint64_t, 3> lo{}, hi{};
    for (std::size_t a = 0; a < 3; ++a) {
      const double g =
          (positions[i][static_cast<int>(a)] - layout.grid.origin[static_cast<int>(a)]) /
          layout.grid.voxel;
      const auto first = static_cast<std::uint64_t>(std::max(0.0, std::ceil(g - radius)));
      const auto last = static_cast<std::uint64_t>(std::max(0.0, std::floor(g + radius)));
      // Corner x lies in chunks ceil(x / n) − 1 … floor(x / n).
      lo[a] = first == 0 ? 0 : (first + n - 1) / n - 1;
      hi[a] = std::min(layout.chunks[a] - 1, last / n);
    }
    for (std::uint64_t z = lo[2]; z <= hi[2]; ++z)
      for (std::uint64_t y = lo[1]; y <= hi[1]; ++y)
        for (std::uint64_t x = lo[0]; x <= hi[0]; ++x)
          members[static_cast<std::size_t>((z * layout.chunks[1] + y) * layout.chunks[0] + x)]
              .push_back(i);
  }
  return members;
}

SurfacePiece chunkPiece(const Layout& layout, std::uint64_t c,
                        std::span<const std::uint32_t> members, std::span<const Vec3d> positions,
                        std::span<const Vec3f> normals, const DistanceOptions& distance) {
  std::vector<Vec3d> p(members.size());
  std::vector<Vec3f> nrm(members.size());
  std::vector<std::uint64_t> ids(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    p[m] = positions[members[m]];
    nrm[m] = normals[members[m]];
    ids[m] = members[m];
  }
  const std::array<std::uint64_t, 3> at = {c % layout.chunks[0],
                                           (c / layout.chunks[0]) % layout.chunks[1],
                                           c / (layout.chunks[0] * layout.chunks[1])};
  CornerValues values;
  for (std::size_t a = 0; a < 3; ++a) {
    values.first[a] = at[a] * layout.n;
    values.size[a] = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(layout.n + 1, layout.grid.corners[a] - values.first[a]));
  }
  signedDistances(layout.grid, {p, nrm, ids}, distance, values);
  return polygonize(layout.grid, values);
}

// Whether a vertex's lattice edge lies in a chunk face (in a plane of corners a multiple of N
// along an axis it does not run along): only those can be in two chunks.
bool onChunkFace(std::uint64_t key, const Layout& layout) {
  const int direction = static_cast<int>(key % 7) + 1;
  std::uint64_t corner = key / 7;
  for (std::size_t a = 0; a < 3; ++a) {
    const std::uint64_t at = corner % layout.grid.corners[a];
    corner /= layout.grid.corners[a];
    if ((direction & (1 << a)) == 0 && at % layout.n == 0) return true;
  }
  return false;
}

// Pieces joined by vertex name as they come, in chunk order.
class Joiner {
 public:
  Joiner(const Layout& layout, ReconstructedMesh& mesh) : layout_(layout), mesh_(mesh) {}

  void add(const SurfacePiece& piece) {
    local_.resize(piece.positions.size());
    for (std::size_t v = 0; v < piece.positions.size(); ++v) {
      const auto next = static_cast<std::uint32_t>(mesh_.positions.size());
      if (!onChunkFace(piece.edges[v], layout_)) {
        local_[v] = next;
        mesh_.positions.push_back(piece.positions[v]);
        continue;
      }
      const auto [at, added] = shared_.try_emplace(piece.edges[v], next);
      if (added) mesh_.positions.push_back(piece.positions[v]);
      local_[v] = at->second;
    }
    for (std::uint32_t i : piece.indices) mesh_.indices.push_back(local_[i]);
  }

 private:
  const Layout& layout_;
  ReconstructedMesh& mesh_;
  std::unordered_map<std::uint64_t, std::uint32_t> shared_;  // face vertices only
  std::vector<std::uint32_t> local_;
};

// Drops connected pieces of fewer than `least` triangles (and the vertices only they used).
std::uint64_t dropSmallPieces(ReconstructedMesh& mesh, std::uint64_t least) {
  if (least == 0 || mesh.indices.empty()) return 0;
  std::vector<std::uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const std::uint32_t a = find(mesh.indices[t]);
    parent[find(mesh.indices[t + 1])] = a;
    parent[find(mesh.indices[t + 2])] = a;
  }
  std::unordered_map<std::uint32_t, std::uint64_t> triangles;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) ++triangles[find(mesh.indices[t])];
  std::uint64_t dropped = 0;
  for (const auto& [root, count] : triangles) dropped += count < least ? 1 : 0;
  if (dropped == 0) return 0;
  std::vector<std::uint32_t> kept;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
    if (triangles[find(mesh.indices[t])] >= least)
      kept.insert(kept.end(), mesh.indices.begin() + static_cast<std::ptrdiff_t>(t),
                  mesh.indices.begin() + static_cast<std::ptrdiff_t>(t + 3));
  std::vector<std::uint32_t> renumber(mesh.positions.size(), ~0u);
  std::vector<Vec3d> positions;
  for (std::uint32_t& i : kept) {
    if (renumber[i] == ~0u) {
      renumber[i] = static_cast<std::uint32_t>(positions.size());
      positions.push_back(mesh.positions[i]);
    }
    i = renumber[i];
  }
  mesh.positions = std::move(positions);
  mesh.indices = std::move(kept);
  return dropped;
}

// Each vertex takes the colour of the nearest input point.
void colourVertices(const PointIndex& tree, std::span<const Rgba8> colors,
                    ReconstructedMesh& mesh) {
  mesh.colors.resize(mesh.positions.size());
  tbb::parallel_for(std::size_t{0}, mesh.positions.size(), [&](std::size_t v) {
    std::uint32_t nearest = 0;
    double d2 = 0;
    tree.nearest(mesh.positions[v], 1, &nearest, &d2);
    mesh.colors[v] = colors[nearest];
  });
}

}  // namespace

Result<ReconstructedMesh> reconstructPoints(std::vector<Vec3d> positions,
                                            std::vector<Vec3f> normals, std::vector<Rgba8> colors,
                                            const std::string& name,
                                            const ReconstructOptions& options,
                                            std::vector<SurfacePiece>* pieces) {
  // One k-d tree over the points, if the spacing, the normals or the colours need it.
  std::optional<PointIndex> index;
  if (options.voxel <= 0 || normals.empty() || !colors.empty()) index.emplace(positions);
  Result<Layout> layout = layOut(positions, index ? &*index : nullptr, name, options);
  if (!layout) return layout.status();
  const std::uint64_t corners = std::uint64_t{layout->n + 1} * (layout->n + 1) * (layout->n + 1);
  if (options.memoryLimit > 0 && corners * kBytesPerCorner > options.memoryLimit / 2)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: a chunk of {}³ voxels needs {} of grid, more than half of "
                             "--memory-limit {}: use a smaller --chunk-size",
                             name, layout->n, formatBytes(corners * kBytesPerCorner),
                             formatBytes(options.memoryLimit))};
  ReconstructedMesh mesh;
  mesh.grid = layout->grid;
  mesh.chunkVoxels = layout->n;
  mesh.points = positions.size();
  mesh.chunks = layout->chunkCount();
  if (normals.empty()) {
    normals = estimateNormals(positions, *index, options.normals);
    mesh.estimatedNormals = true;
  }
  LODFORGE_TRY(checkCancelled());
  const std::vector<std::vector<std::uint32_t>> members =
      bucket(positions, *layout, options.distance.radius);
  // A few chunks per thread at a time, joined in chunk order and freed: only those pieces are
  // held besides the mesh.
  const auto batch =
      static_cast<std::size_t>(4 * std::max(1, tbb::this_task_arena::max_concurrency()));
  std::vector<SurfacePiece> made(batch);
  Joiner joiner(*layout, mesh);
  Progress progress("reconstruct: chunks", members.size());
  for (std::size_t first = 0; first < members.size(); first += batch) {
    const std::size_t last = std::min(members.size(), first + batch);
    tbb::parallel_for(first, last, [&](std::size_t c) {
      made[c - first] = members[c].empty() ? SurfacePiece{}
                                           : chunkPiece(*layout, c, members[c], positions, normals,
                                                        options.distance);
    });
    for (std::size_t c = first; c < last; ++c) {
      joiner.add(made[c - first]);
      if (pieces) pieces->push_back(std::move(made[c - first]));
      made[c - first] = SurfacePiece{};
    }
    progress.advance(last - first);
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  mesh.droppedPieces = dropSmallPieces(mesh, options.minTriangles);
  if (!colors.empty()) colourVertices(*index, colors, mesh);
  return mesh;
}

Result<ReconstructedMesh> reconstructSurface(const std::string& input,
                                             const ReconstructOptions& options) {
  Result<PointReader> reader = PointReader::open(input, 1 << 16, options.salvageTruncated, false);
  if (!reader) return reader.status();
  const PointCloudInfo& info = reader->info();
  if (options.memoryLimit > 0 && info.count && *info.count * kBytesPerPoint > options.memoryLimit)
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: {} points need about {} here, more than --memory-limit {}", input,
                             formatCount(*info.count), formatBytes(*info.count * kBytesPerPoint),
                             formatBytes(options.memoryLimit))};
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;
  std::vector<Rgba8> colors;
  // Reserved when the count is known: growing by doubling would hold half as much again.
  const auto count = static_cast<std::size_t>(info.count.value_or(0));
  positions.reserve(count);
  if (info.hasNormals) normals.reserve(count);
  if (info.hasColors) colors.reserve(count);
  Progress progress("reconstruct: reading", info.count.value_or(0));
  PointBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    positions.insert(positions.end(), batch.positions.begin(), batch.positions.end());
    normals.insert(normals.end(), batch.normals.begin(), batch.normals.end());
    colors.insert(colors.end(), batch.colors.begin(), batch.colors.end());
    progress.advance(batch.size());
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  for (Vec3f& n : normals) n = normalizeOr(n, Vec3f{0, 0, 1});
  return reconstructPoints(std::move(positions), std::move(normals), std::move(colors), input,
                           options);
}

Status writeReconstruction(const ReconstructedMesh& mesh, const std::string& path) {
  Aabbd bounds;
  for (const Vec3d& p : mesh.positions) bounds.add(p);
  // Geo-scale coordinates keep their millimetres as doubles around the centre.
  const bool far = !bounds.empty() && length(bounds.center()) > 1e4;
  const Vec3d origin = far ? bounds.center() : Vec3d{};
  std::vector<Vec3f> positions(mesh.positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v)
    positions[v] = toFloat(mesh.positions[v] - origin);
  std::vector<Vec3f> normals(positions.size());
  computeVertexNormals(positions, mesh.indices, normals);
  PlyLayout layout;
  layout.vertexCount = positions.size();
  layout.faceCount = mesh.indices.size() / 3;
  layout.normals = true;
  layout.colors = !mesh.colors.empty();
  layout.doublePositions = far;
  layout.comments = {"lodforge reconstruct"};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();
  LODFORGE_TRY(writer->writeVertices(positions, normals, mesh.colors, origin));
  LODFORGE_TRY(writer->writeTriangles(mesh.indices));
  return writer->finish();
}

}  // namespace lodforge
