#include "lodforge/io/mesh/ply_writer.h"

#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/texture_export.h"

namespace lodforge {

namespace {
constexpr std::size_t kSectionBuffer = 4 << 20;

template <class T>
void append(std::vector<std::byte>& out, const T& value) {
  const auto* bytes = reinterpret_cast<const std::byte*>(&value);
  out.insert(out.end(), bytes, bytes + sizeof value);
}
}  // namespace

PlyWriter::PlyWriter(OutputFile file, PlyLayout layout, std::uint64_t vertexStart)
    : file_(std::move(file)), layout_(std::move(layout)) {
  vertices_.cursor = vertexStart;
  faceStart_ = vertexStart + layout_.vertexCount * vertexStride();
  faces_.cursor = faceStart_;
}

std::size_t PlyWriter::vertexStride() const {
  return std::size_t{layout_.doublePositions ? 24u : 12u} + (layout_.normals ? 12u : 0u) +
         (layout_.colors ? 4u : 0u);
}

Result<PlyWriter> PlyWriter::create(const std::string& path, const PlyLayout& layout) {
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by lodforge\n";
  for (const std::string& c : layout.comments) header += fmt::format("comment {}\n", c);
  const char* coordinate = layout.doublePositions ? "double" : "float";
  header += fmt::format("element vertex {}\n", layout.vertexCount);
  header += fmt::format("property {0} x\nproperty {0} y\nproperty {0} z\n", coordinate);
  if (layout.normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (layout.colors) {
    header +=
        "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  }
  if (layout.faceCount > 0) {
    header +=
        fmt::format("element face {}\nproperty list uchar uint vertex_indices\n", layout.faceCount);
    if (layout.objectIds) header += "property uint object_id\n";
    if (layout.faceUvs) header += "property list uchar float texcoord\nproperty int texnumber\n";
  }
  header += "end_header\n";
  if (Status s = file->writeAt(0, header.data(), header.size()); !s.ok()) return s;
  return PlyWriter(std::move(file.value()), layout, header.size());
}

Status PlyWriter::flush(Section& section) {
  LODFORGE_TRY(file_.writeAt(section.cursor, section.buffer.data(), section.buffer.size()));
  section.cursor += section.buffer.size();
  section.buffer.clear();
  return {};
}

Status PlyWriter::writeVertices(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                                std::span<const Rgba8> colors, Vec3d origin) {
  assert(normals.size() == (layout_.normals ? positions.size() : 0));
  assert(colors.size() == (layout_.colors ? positions.size() : 0));
  assert(layout_.doublePositions || (origin == Vec3d{}));
  if (verticesWritten_ + positions.size() > layout_.vertexCount) {
    return Error{ErrorKind::kInternal, fmt::format("{}: more vertices than the {} declared",
                                                   file_.path(), layout_.vertexCount)};
  }
  std::vector<std::byte>& out = vertices_.buffer;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (layout_.doublePositions) {
      const Vec3d p = origin + toDouble(positions[i]);
      append(out, p);
    } else {
      append(out, positions[i]);
    }
    if (layout_.normals) append(out, normals[i]);
    if (layout_.colors) append(out, colors[i]);
    if (out.size() >= kSectionBuffer) LODFORGE_TRY(flush(vertices_));
  }
  verticesWritten_ += positions.size();
  return {};
}

Status PlyWriter::writeTriangles(std::span<const std::uint32_t> indices,
                                 std::span<const std::uint32_t> objectIds,
                                 std::span<const Vec2f> cornerUvs,
                                 std::span<const std::uint32_t> textures) {
  assert(indices.size() % 3 == 0);
  const std::size_t triangles = indices.size() / 3;
  assert(objectIds.size() == (layout_.objectIds ? triangles : 0));
  assert(cornerUvs.size() == (layout_.faceUvs ? 3 * triangles : 0));
  assert(textures.size() == (layout_.faceUvs ? triangles : 0));
  if (facesWritten_ + triangles > layout_.faceCount) {
    return Error{ErrorKind::kInternal, fmt::format("{}: more faces than the {} declared",
                                                   file_.path(), layout_.faceCount)};
  }
  std::vector<std::byte>& out = faces_.buffer;
  for (std::size_t t = 0; t < triangles; ++t) {
    append(out, std::uint8_t{3});
    append(out, indices[3 * t]);
    append(out, indices[3 * t + 1]);
    append(out, indices[3 * t + 2]);
    if (layout_.objectIds) append(out, objectIds[t]);
    if (layout_.faceUvs) {
      append(out, std::uint8_t{6});
      for (std::size_t k = 0; k < 3; ++k) {
        append(out, cornerUvs[3 * t + k].x);
        append(out, 1.0f - cornerUvs[3 * t + k].y);
      }
      append(out, static_cast<std::int32_t>(textures[t]));
    }
    if (out.size() >= kSectionBuffer) LODFORGE_TRY(flush(faces_));
  }
  facesWritten_ += triangles;
  return {};
}

Status PlyWriter::finish() {
  if (verticesWritten_ != layout_.vertexCount || facesWritten_ != layout_.faceCount) {
    return Error{
        ErrorKind::kInternal,
        fmt::format("{}: declared {} vertices and {} faces but wrote {} and {}", file_.path(),
                    layout_.vertexCount, layout_.faceCount, verticesWritten_, facesWritten_)};
  }
  LODFORGE_TRY(flush(vertices_));
  LODFORGE_TRY(flush(faces_));
  return file_.commit();
}

Status writePly(const Model& model, const std::string& path) {
  if (model.vertexCount() > std::numeric_limits<std::uint32_t>::max()) {
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: PLY indices are 32-bit; {} vertices do not fit", path,
                             model.vertexCount())};
  }
  PlyLayout layout;
  layout.vertexCount = model.vertexCount();
  layout.faceCount = model.triangleCount();
  layout.normals = model.hasNormals();
  layout.colors = model.hasColors();
  layout.objectIds = model.objectCount() > 1;
  layout.doublePositions = model.origin != Vec3d{};
  // Textures: the images beside the PLY, named in TextureFile comments; faces carry their
  // corners' coordinates and their image (texnumber, -1 for none).
  layout.faceUvs = model.hasUvs() && !model.images.empty();
  if (layout.faceUvs) {
    SideFiles files;
    Result<std::vector<std::string>> images = addImagesBeside(model, path, files);
    if (!images) return images.status();
    LODFORGE_TRY(files.writeAll());
    for (const std::string& name : *images) layout.comments.push_back("TextureFile " + name);
  }
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();
  LODFORGE_TRY(writer->writeVertices(model.positions, model.normals, model.colors, model.origin));
  // Faces per object: local indices become global, the object's index becomes its id.
  std::vector<std::uint32_t> global;
  std::vector<std::uint32_t> ids, textures;
  std::vector<Vec2f> corners;
  Progress progress("writing " + path, model.triangleCount());
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    if (o % 1024 == 0) LODFORGE_TRY(checkCancelled());
    const ObjectRecord& record = model.objects[o];
    const auto indices = model.objectIndices(o);
    global.resize(indices.size());
    for (std::size_t i = 0; i < indices.size(); ++i)
      global[i] = static_cast<std::uint32_t>(indices[i] + record.vertexOffset);
    if (layout.objectIds) ids.assign(record.triangleCount, static_cast<std::uint32_t>(o));
    if (layout.faceUvs) {
      const std::uint32_t m = record.material;
      const std::uint32_t image =
          m < model.materials.size() ? model.materials[m].baseColorImage : kNoImage;
      textures.assign(record.triangleCount, image);  // kNoImage is -1 as an int
      corners.clear();
      for (std::uint32_t v : global) corners.push_back(model.uvs[v]);
    }
    LODFORGE_TRY(writer->writeTriangles(global, ids, corners, textures));
    progress.advance(record.triangleCount);
  }
  progress.finish();
  return writer->finish();
}

}  // namespace lodforge
