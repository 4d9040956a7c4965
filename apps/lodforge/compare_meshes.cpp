// `lodforge compare A.ply B.ply`: how far two surfaces lie from each other — the symmetric
// Hausdorff and RMS distance of the project's sampler (core/distance), and the mean each way —
// e.g. a reconstruction against the surface its points were sampled from. When both are
// textured with the same images (matched by their bytes), also how far B's texture mapping is
// from A's in texels (textureDistance): the texture-space error of a simplification.
#include "compare_meshes.h"

#include <algorithm>
#include <array>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/checksum.h"
#include "lodforge/core/distance.h"
#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"
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

// A's images: by the checksum of their bytes (to find B's images among them), their sizes, and
// each one's index among them (the first with the same bytes).
struct ReferenceImages {
  std::map<std::uint64_t, std::uint32_t> byBytes;
  std::vector<std::array<std::uint32_t, 2>> texels;
  std::vector<std::uint32_t> own;
};

Result<ReferenceImages> referenceImagesOf(const Model& reference) {
  ReferenceImages out;
  for (std::size_t i = 0; i < reference.images.size(); ++i) {
    Result<std::vector<std::byte>> bytes = imageBytes(reference.images[i]);
    if (!bytes) return bytes.status();
    const auto [at, fresh] = out.byBytes.emplace(checksum64(*bytes), static_cast<std::uint32_t>(i));
    out.own.push_back(at->second);
    out.texels.push_back({reference.images[i].width, reference.images[i].height});
  }
  return out;
}

// Each of B's images as the index of A's image with the same bytes (~0u: one A lacks).
Result<std::vector<std::uint32_t>> matchImages(const Model& model,
                                               const ReferenceImages& reference) {
  std::vector<std::uint32_t> imageToReference(model.images.size(), ~0u);
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    Result<std::vector<std::byte>> bytes = imageBytes(model.images[i]);
    if (!bytes) return bytes.status();
    if (const auto found = reference.byBytes.find(checksum64(*bytes));
        found != reference.byBytes.end())
      imageToReference[i] = found->second;
  }
  return imageToReference;
}

// Each triangle's texture, through its material's image (~0u: none, or an image A lacks).
std::vector<std::uint32_t> texturesOf(const Model& model,
                                      std::span<const std::uint32_t> imageToReference) {
  std::vector<std::uint32_t> texture;
  for (const ObjectRecord& o : model.objects) {
    std::uint32_t t = ~0u;
    if (model.hasUvs() && o.material < model.materials.size() &&
        model.materials[o.material].baseColorImage != kNoImage)
      t = imageToReference[model.materials[o.material].baseColorImage];
    texture.insert(texture.end(), o.triangleCount, t);
  }
  return texture;
}

// The texture-space error of B against A, when both are textured with images they share.
Result<std::optional<TextureDistance>> compareTextures(const Model& a, const Flat& fa,
                                                       const Model& b, const Flat& fb,
                                                       std::uint32_t samples) {
  if (!a.hasUvs() || !b.hasUvs() || a.images.empty()) return std::optional<TextureDistance>();
  Result<ReferenceImages> reference = referenceImagesOf(a);
  if (!reference) return reference.status();
  Result<std::vector<std::uint32_t>> matched = matchImages(b, *reference);
  if (!matched) return matched.status();
  const std::vector<std::uint32_t> ta = texturesOf(a, reference->own), tb = texturesOf(b, *matched);
  if (std::all_of(tb.begin(), tb.end(), [](std::uint32_t t) { return t == ~0u; }))
    return std::optional<TextureDistance>();
  const TexturedSurface sa{fa.positions, fa.indices, a.uvs, ta, reference->texels};
  const TexturedSurface sb{fb.positions, fb.indices, b.uvs, tb, reference->texels};
  return std::optional(textureDistance(sa, sb, samples));
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
  // Where the largest distances are: a reader looks there (thin parts, rims, holes).
  const Vec3d onA = d.farthestOnA + first->origin, onB = d.farthestOnB + first->origin;
  detail(global,
         fmt::format("largest {} → {}: {:.6g} at ({:.9g}, {:.9g}, {:.9g}); {} → {}: "
                     "{:.6g} at ({:.9g}, {:.9g}, {:.9g})",
                     a, b, d.maxAB, onA.x, onA.y, onA.z, b, a, d.maxBA, onB.x, onB.y, onB.z));
  Result<std::optional<TextureDistance>> texture =
      compareTextures(*first, fa, *second, fb, samples);
  if (!texture) return texture.status();
  if (*texture)
    say(global, fmt::format("texture error {} → {} in texels: mean {:.3g}  median {:.3g}  "
                            "95th percentile {:.3g}  max {:.3g}  ({} samples; {} where {} has "
                            "another texture)",
                            a, b, (*texture)->mean, (*texture)->median, (*texture)->p95,
                            (*texture)->max, (*texture)->samples, (*texture)->otherTexture, b));
  if (json.empty()) return {};
  nlohmann::json report = {{"a", a},
                           {"b", b},
                           {"samples", samples},
                           {"hausdorff", d.hausdorff},
                           {"rms", d.rms},
                           {"mean_ab", d.meanAB},
                           {"mean_ba", d.meanBA},
                           {"max_ab", d.maxAB},
                           {"max_ba", d.maxBA},
                           {"farthest_on_a", {onA.x, onA.y, onA.z}},
                           {"farthest_on_b", {onB.x, onB.y, onB.z}}};
  if (*texture)
    report["texture_texels"] = {
        {"mean", (*texture)->mean},       {"median", (*texture)->median},
        {"p95", (*texture)->p95},         {"max", (*texture)->max},
        {"samples", (*texture)->samples}, {"other_texture", (*texture)->otherTexture}};
  Result<OutputFile> file = OutputFile::create(json);
  if (!file) return file.status();
  const std::string text = report.dump(2) + "\n";
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace lodforge::cli
