#include "lodforge/generate/points.h"

#include <cmath>
#include <vector>

#include <tbb/parallel_for.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/random.h"
#include "lodforge/generate/terrain.h"
#include "lodforge/io/ply_writer.h"

namespace lodforge {

namespace {
constexpr std::uint64_t kBatch = 1 << 15;       // points per independently seeded batch
constexpr std::uint64_t kBatchesPerRound = 32;  // batches computed in parallel, then written

struct PointBatch {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
};

void sampleBatch(const Terrain& terrain, const PointsOptions& options, std::uint64_t batch,
                 std::uint64_t count, PointBatch& out) {
  Random random = Random::forItem(options.seed, batch);
  out.positions.clear();
  out.normals.clear();
  out.colors.clear();
  while (out.positions.size() < count) {
    const double u = random.uniform(0, terrain.width());
    const double v = random.uniform(0, terrain.depth());
    const double jitter = random.uniform(-1, 1) * options.noise;
    if (terrain.inHole(u, v)) continue;  // the scanner saw nothing there
    const Vec3d n = terrain.normal(u, v);
    const Vec3d p = terrain.position(u, v) + n * jitter;
    out.positions.push_back(toFloat(p));
    out.normals.push_back(toFloat(n));
    out.colors.push_back(terrain.color(u, v, p, n));
  }
}
}  // namespace

Result<GenerateStats> generatePoints(const PointsOptions& options, const std::string& path) {
  if (options.points == 0)
    return Error{ErrorKind::kUsage, "a point cloud needs at least one point"};
  if (fileExtension(path) != "ply")
    return Error{ErrorKind::kUsage, fmt::format("{}: the points generator writes .ply", path)};
  const double depth = options.width * 2.0 / 3.0;
  const double spacing = std::sqrt(options.width * depth / static_cast<double>(options.points));
  const Terrain terrain(options.seed, options.width, depth, spacing);

  PlyLayout layout;
  layout.vertexCount = options.points;
  layout.normals = true;
  layout.colors = true;
  layout.comments = {
      fmt::format("lodforge generate points --points {} --seed {}", options.points, options.seed)};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();

  const std::uint64_t batches = (options.points + kBatch - 1) / kBatch;
  std::vector<PointBatch> round(kBatchesPerRound);
  Progress progress("points", options.points);
  for (std::uint64_t first = 0; first < batches; first += kBatchesPerRound) {
    LODFORGE_TRY(checkCancelled());
    const std::uint64_t count = std::min(kBatchesPerRound, batches - first);
    tbb::parallel_for(std::uint64_t{0}, count, [&](std::uint64_t i) {
      const std::uint64_t batch = first + i;
      const std::uint64_t points = std::min(kBatch, options.points - batch * kBatch);
      sampleBatch(terrain, options, batch, points, round[i]);
    });
    for (std::uint64_t i = 0; i < count; ++i) {
      LODFORGE_TRY(writer->writeVertices(round[i].positions, round[i].normals, round[i].colors));
      progress.advance(round[i].positions.size());
    }
  }
  progress.finish();
  const std::uint64_t bytes = writer->fileBytes();
  LODFORGE_TRY(writer->finish());
  return GenerateStats{1, options.points, 0, bytes};
}

}  // namespace lodforge
