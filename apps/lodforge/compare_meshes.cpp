// `lodforge compare A.ply B.ply`: how far two surfaces lie from each other — the symmetric
// Hausdorff and RMS distance of the project's sampler (core/distance), and the mean each way —
// e.g. a reconstruction against the surface its points were sampled from.
#include "compare_meshes.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/distance.h"
#include "lodforge/core/file.h"
#include "lodforge/io/model_io.h"
#include "lodforge/io/points/point_reader.h"
#include "outputs.h"

namespace lodforge::cli {

namespace {

// Every object's triangles in one array, positions relative to `origin`.
struct Flat {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
};

Flat flatten(const Model& model, Vec3d origin) {
  Flat flat;
  const Vec3f shift = toFloat(model.origin - origin);
  flat.positions.reserve(model.positions.size());
  for (const Vec3f& p : model.positions) flat.positions.push_back(p + shift);
  for (std::size_t o = 0; o < model.objects.size(); ++o) {
    const auto base = static_cast<std::uint32_t>(model.objects[o].vertexOffset);
    for (std::uint32_t i : model.objectIndices(o)) flat.indices.push_back(base + i);
  }
  return flat;
}

bool isGeometryPath(const std::string& path) {
  return formatFromPath(path) != FileFormat::kUnknown || isPointCloudPath(path);
}

// Each side must be a surface: a point cloud (an .xyz, a LAS) has no triangles to measure, and
// a PNG beside a mesh is neither comparison.
Status checkSurfacePath(const std::string& path) {
  if (formatFromPath(path) == FileFormat::kUnknown && isPointCloudPath(path))
    return badInput(path,
                    "a point cloud: it has no triangles to measure (compare measures the "
                    "distance between two surfaces)");
  if (formatFromPath(path) == FileFormat::kUnknown)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: not a mesh; compare takes two meshes, or two PNG files or "
                             "folders of them",
                             path)};
  return {};
}

}  // namespace

bool isMeshComparison(const std::string& a, const std::string& b) {
  return isGeometryPath(a) || isGeometryPath(b);
}

Status runCompareMeshes(const Global& global, const std::string& a, const std::string& b,
                        std::uint32_t samples, const std::string& json) {
  LODFORGE_TRY(checkSurfacePath(a));
  LODFORGE_TRY(checkSurfacePath(b));
  LODFORGE_TRY(claimIfGiven(json, jsonOutput(), {a, b}));
  Result<Model> first = readModel(a);
  if (!first) return first.status();
  Result<Model> second = readModel(b);
  if (!second) return second.status();
  if (first->triangleCount() == 0 || second->triangleCount() == 0)
    return badInput(first->triangleCount() == 0 ? a : b, "has no triangles to measure");
  const Flat fa = flatten(*first, first->origin), fb = flatten(*second, first->origin);
  const SurfaceDistance d =
      surfaceDistance(fa.positions, fa.indices, fb.positions, fb.indices, samples);
  say(global, fmt::format("hausdorff {:.6g}  rms {:.6g}  mean {} → {}: {:.6g}  mean {} → {}: "
                          "{:.6g}  ({} samples on each)",
                          d.hausdorff, d.rms, a, b, d.meanAB, b, a, d.meanBA, samples));
  if (json.empty()) return {};
  const nlohmann::json report = {{"a", a},
                                 {"b", b},
                                 {"samples", samples},
                                 {"hausdorff", d.hausdorff},
                                 {"rms", d.rms},
                                 {"mean_ab", d.meanAB},
                                 {"mean_ba", d.meanBA}};
  Result<OutputFile> file = OutputFile::create(json);
  if (!file) return file.status();
  const std::string text = report.dump(2) + "\n";
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace lodforge::cli
