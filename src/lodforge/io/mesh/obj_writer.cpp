#include "lodforge/io/mesh/obj_writer.h"

#include <fmt/format.h>

#include "lodforge/core/file.h"

namespace lodforge {

Status writeObj(const Model& model, const std::string& path) {
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  std::string text = "# written by lodforge\n";
  auto flushIfBig = [&]() -> Status {
    if (text.size() < (1 << 20)) return {};
    Status s = file->write(text.data(), text.size());
    text.clear();
    return s;
  };
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const ObjectRecord& record = model.objects[o];
    std::string name(model.objectName(o));
    for (char& c : name) {
      if (c == '\n' || c == '\r' || c == ' ' || c == '\t') c = '_';
    }
    text += fmt::format("o {}\n", name.empty() ? fmt::format("object_{}", o) : name);
    for (std::uint64_t v = record.vertexOffset; v < record.vertexOffset + record.vertexCount; ++v) {
      // World coordinates in double: the shortest text that reads back to the same value.
      const Vec3d p = model.origin + toDouble(model.positions[v]);
      if (model.hasColors()) {
        const Rgba8 c = model.colors[v];
        text += fmt::format("v {} {} {} {} {} {}\n", p.x, p.y, p.z, c.r / 255.0, c.g / 255.0,
                            c.b / 255.0);
      } else {
        text += fmt::format("v {} {} {}\n", p.x, p.y, p.z);
      }
      if (model.hasNormals()) {
        const Vec3f n = model.normals[v];
        text += fmt::format("vn {} {} {}\n", n.x, n.y, n.z);
      }
      LODFORGE_TRY(flushIfBig());
    }
    // OBJ indices are global and 1-based; normals share the vertex numbering.
    const auto indices = model.objectIndices(o);
    for (std::size_t t = 0; t < record.triangleCount; ++t) {
      const std::uint64_t a = indices[3 * t] + record.vertexOffset + 1;
      const std::uint64_t b = indices[3 * t + 1] + record.vertexOffset + 1;
      const std::uint64_t c = indices[3 * t + 2] + record.vertexOffset + 1;
      if (model.hasNormals())
        text += fmt::format("f {0}//{0} {1}//{1} {2}//{2}\n", a, b, c);
      else
        text += fmt::format("f {} {} {}\n", a, b, c);
      LODFORGE_TRY(flushIfBig());
    }
  }
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace lodforge
