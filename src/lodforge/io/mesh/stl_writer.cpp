#include "lodforge/io/mesh/stl_writer.h"

#include <cstring>
#include <vector>

#include <fmt/format.h>

#include "lodforge/core/file.h"

namespace lodforge {

namespace {

struct Facet {
  Vec3f normal;
  Vec3f corners[3];
};

Facet facetOf(const Model& model, std::size_t object, std::size_t triangle) {
  const auto positions = model.objectPositions(object);
  const auto indices = model.objectIndices(object);
  Facet f;
  for (std::size_t k = 0; k < 3; ++k) {
    // STL has no origin: world coordinates, rounded to float.
    f.corners[k] = toFloat(model.origin + toDouble(positions[indices[3 * triangle + k]]));
  }
  f.normal = normalizeOr(cross(f.corners[1] - f.corners[0], f.corners[2] - f.corners[0]), Vec3f{});
  return f;
}

}  // namespace

Status writeStl(const Model& model, const std::string& path, const StlWriteOptions& options) {
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  if (options.ascii) {
    std::string text;
    for (std::size_t o = 0; o < model.objectCount(); ++o) {
      std::string name(model.objectName(o));
      for (char& c : name) {
        if (c == '\n' || c == '\r') c = ' ';
      }
      text = fmt::format("solid {}\n", name);
      for (std::size_t t = 0; t < model.objects[o].triangleCount; ++t) {
        const Facet f = facetOf(model, o, t);
        text +=
            fmt::format("facet normal {} {} {}\nouter loop\n", f.normal.x, f.normal.y, f.normal.z);
        for (const Vec3f& c : f.corners) text += fmt::format("vertex {} {} {}\n", c.x, c.y, c.z);
        text += "endloop\nendfacet\n";
        if (text.size() > (1 << 20)) {
          LODFORGE_TRY(file->write(text.data(), text.size()));
          text.clear();
        }
      }
      text += fmt::format("endsolid {}\n", name);
      LODFORGE_TRY(file->write(text.data(), text.size()));
    }
    return file->commit();
  }
  if (model.triangleCount() > 0xFFFFFFFFull) {
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: binary STL holds at most 2^32-1 triangles", path)};
  }
  char header[80] = {};
  std::snprintf(header, sizeof header, "binary STL written by lodforge");
  const auto count = static_cast<std::uint32_t>(model.triangleCount());
  LODFORGE_TRY(file->write(header, sizeof header));
  LODFORGE_TRY(file->write(&count, 4));
  std::vector<std::byte> batch;
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    for (std::size_t t = 0; t < model.objects[o].triangleCount; ++t) {
      const Facet f = facetOf(model, o, t);
      std::byte record[50] = {};
      std::memcpy(record, &f, 48);
      batch.insert(batch.end(), record, record + 50);
      if (batch.size() > (1 << 20)) {
        LODFORGE_TRY(file->write(batch.data(), batch.size()));
        batch.clear();
      }
    }
  }
  LODFORGE_TRY(file->write(batch.data(), batch.size()));
  return file->commit();
}

}  // namespace lodforge
