#include "lodforge/generate/surface_samples.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <tbb/parallel_for.h>

#include "lodforge/core/progress.h"
#include "lodforge/core/random.h"
#include "lodforge/io/mesh/ply_writer.h"

namespace lodforge {

namespace {

constexpr std::uint64_t kSampleBatch = 1 << 15;  // points per independently seeded batch
constexpr std::uint64_t kSampleRounds = 32;      // batches computed in parallel, then written

// The model's triangles as global corner indices, with the running sum of their areas (the
// sampling distribution) and their unit normals.
struct SampledSurface {
  const Model* model = nullptr;
  std::vector<std::uint32_t> corners;
  std::vector<double> areaSum;  // areaSum[t] = area of triangles [0, t]
  std::vector<Vec3f> faceNormals;
  double noise = 0;  // standard deviation in model units
};

SampledSurface sampledSurfaceOf(const Model& model, double noiseShare) {
  SampledSurface s;
  s.model = &model;
  Aabbd bounds;
  for (const Vec3f& p : model.positions) bounds.add(toDouble(p));
  s.noise = noiseShare * (model.positions.empty() ? 0.0 : length(bounds.size()));
  double sum = 0;
  for (std::size_t o = 0; o < model.objects.size(); ++o) {
    const auto base = static_cast<std::uint32_t>(model.objects[o].vertexOffset);
    const auto local = model.objectIndices(o);
    for (std::size_t k = 0; k + 2 < local.size(); k += 3) {
      const std::uint32_t a = base + local[k], b = base + local[k + 1], c = base + local[k + 2];
      const Vec3d pa = toDouble(model.positions[a]);
      const Vec3d n = cross(toDouble(model.positions[b]) - pa, toDouble(model.positions[c]) - pa);
      const double twiceArea = length(n);
      if (!(twiceArea > 0)) continue;  // never picked: nothing to sample
      s.corners.insert(s.corners.end(), {a, b, c});
      sum += 0.5 * twiceArea;
      s.areaSum.push_back(sum);
      s.faceNormals.push_back(toFloat(n / twiceArea));
    }
  }
  return s;
}

// Box–Muller: one standard normal variate from two uniforms.
double gaussian(Random& random) {
  const double u = 1.0 - random.uniform();  // (0, 1]: the log stays finite
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * random.uniform());
}

// The normal at barycentric (wa, wb, wc) of triangle t: the vertex normals interpolated, or the
// face's where the mesh has none or they cancel there.
Vec3f normalAt(const SampledSurface& s, std::size_t t, double wa, double wb, double wc) {
  const Model& m = *s.model;
  if (!m.hasNormals()) return s.faceNormals[t];
  const std::uint32_t* c = &s.corners[3 * t];
  const Vec3d n = toDouble(m.normals[c[0]]) * wa + toDouble(m.normals[c[1]]) * wb +
                  toDouble(m.normals[c[2]]) * wc;
  const double size = length(n);
  return size > 1e-12 ? toFloat(n / size) : s.faceNormals[t];
}

void sampleSurfaceBatch(const SampledSurface& s, std::uint64_t seed, std::uint64_t batch,
                        std::uint64_t count, std::vector<Vec3f>& positions,
                        std::vector<Vec3f>& normals) {
  Random random = Random::forItem(seed, batch);
  positions.clear();
  normals.clear();
  const Model& m = *s.model;
  for (std::uint64_t i = 0; i < count; ++i) {
    const double at = random.uniform() * s.areaSum.back();
    const auto t = static_cast<std::size_t>(std::min<std::ptrdiff_t>(
        std::upper_bound(s.areaSum.begin(), s.areaSum.end(), at) - s.areaSum.begin(),
        static_cast<std::ptrdiff_t>(s.areaSum.size()) - 1));
    // Uniform over the triangle: the square root keeps the density flat towards corner a.
    const double r = std::sqrt(random.uniform()), v = random.uniform();
    const double wa = 1 - r, wb = r * (1 - v), wc = r * v;
    const std::uint32_t* c = &s.corners[3 * t];
    const Vec3d p = toDouble(m.positions[c[0]]) * wa + toDouble(m.positions[c[1]]) * wb +
                    toDouble(m.positions[c[2]]) * wc;
    const Vec3f n = normalAt(s, t, wa, wb, wc);
    const double offset = s.noise > 0 ? s.noise * gaussian(random) : 0.0;
    positions.push_back(toFloat(p + toDouble(n) * offset));
    normals.push_back(n);
  }
}

}  // namespace

Result<GenerateStats> sampleSurface(const Model& model, const SurfaceSampleOptions& options,
                                    const std::string& path) {
  if (options.points == 0)
    return Error{ErrorKind::kUsage, "a point cloud needs at least one point"};
  if (!(options.noise >= 0) || !std::isfinite(options.noise))
    return Error{ErrorKind::kUsage,
                 fmt::format("--noise {} is not a share of 0 or more", options.noise)};
  const SampledSurface surface = sampledSurfaceOf(model, options.noise);
  if (surface.areaSum.empty())
    return Error{ErrorKind::kBadInput, "the mesh has no triangle with an area to sample"};
  assert(model.positions.size() <= std::numeric_limits<std::uint32_t>::max());
  PlyLayout layout;
  layout.vertexCount = options.points;
  layout.normals = true;
  // A georeferenced mesh (read with an origin) keeps its place: doubles, origin added back.
  layout.doublePositions = model.origin != Vec3d{};
  layout.comments = {
      fmt::format("lodforge generate points --from (mesh) --points {} --seed {} "
                  "--noise {}",
                  options.points, options.seed, options.noise)};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();
  const std::uint64_t batches = (options.points + kSampleBatch - 1) / kSampleBatch;
  std::vector<std::vector<Vec3f>> positions(kSampleRounds), normals(kSampleRounds);
  Progress progress("points", options.points);
  for (std::uint64_t first = 0; first < batches; first += kSampleRounds) {
    LODFORGE_TRY(checkCancelled());
    const std::uint64_t count = std::min(kSampleRounds, batches - first);
    tbb::parallel_for(std::uint64_t{0}, count, [&](std::uint64_t i) {
      const std::uint64_t batch = first + i;
      sampleSurfaceBatch(surface, options.seed, batch,
                         std::min(kSampleBatch, options.points - batch * kSampleBatch),
                         positions[i], normals[i]);
    });
    for (std::uint64_t i = 0; i < count; ++i) {
      LODFORGE_TRY(writer->writeVertices(positions[i], normals[i], {}, model.origin));
      progress.advance(positions[i].size());
    }
  }
  progress.finish();
  const std::uint64_t bytes = writer->fileBytes();
  LODFORGE_TRY(writer->finish());
  return GenerateStats{1, options.points, 0, bytes};
}

}  // namespace lodforge
