#include "lodforge/io/mesh/obj_reader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <tiny_obj_loader.h>

#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"

namespace lodforge {

namespace {

// Calls fn(lineNumber, words) for every line of the text; stops when fn returns false.
template <class Fn>
void forEachLine(std::string_view text, Fn&& fn) {
  std::uint64_t lineNumber = 0;
  std::vector<std::string_view> words;
  for (std::size_t start = 0; start < text.size();) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    ++lineNumber;
    const std::string_view line = text.substr(start, end - start);
    words.clear();
    for (std::size_t i = 0; i < line.size();) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      if (j > i) words.push_back(line.substr(i, j - i));
      i = j;
    }
    if (!fn(lineNumber, words)) return;
    start = end + 1;
  }
}

// tinyobjloader reads an unparseable number ("nan", "1e999", "abc") as 0 without a word, so the
// coordinates are checked here first: bad input must fail loudly, not become a vertex at 0.
Status checkCoordinates(std::string_view text, const std::string& name) {
  Status status;
  forEachLine(text, [&](std::uint64_t line, const std::vector<std::string_view>& words) {
    if (words.empty() || (words[0] != "v" && words[0] != "vn")) return true;
    if (words.size() < 4) {
      status = badInputAtLine(name, line, fmt::format("'{}' needs three coordinates", words[0]));
      return false;
    }
    for (std::size_t i = 1; i < words.size() && i <= 6; ++i) {
      double value = 0;
      const std::string_view w = words[i];
      const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), value);
      if (error != std::errc() || end != w.data() + w.size() || !std::isfinite(value)) {
        status = badInputAtLine(
            name, line, fmt::format("expected a finite number, found '{}'", w.substr(0, 40)));
        return false;
      }
    }
    return true;
  });
  return status;
}

// The line of the n-th face tinyobjloader kept (it drops faces with fewer than 3 corners).
std::uint64_t lineOfFace(std::string_view text, std::uint64_t face) {
  std::uint64_t seen = 0, found = 0;
  forEachLine(text, [&](std::uint64_t line, const std::vector<std::string_view>& words) {
    if (words.size() >= 4 && words[0] == "f") {
      if (seen++ == face) {
        found = line;
        return false;
      }
    }
    return true;
  });
  return found;
}

struct CornerKey {
  int vertex, normal, material;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  std::size_t operator()(const CornerKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.vertex);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.normal);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.material);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

Rgba8 toRgba(double r, double g, double b) {
  auto c = [](double v) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  return {c(r), c(g), c(b), 255};
}

// A file of vertices and no faces (a point cloud, or a mesh cut short before its faces) reads as
// one object of all its vertices and no triangles, as a PLY without faces does.
void addVerticesOnly(Model& model, const tinyobj::attrib_t& attrib, const std::string& name) {
  const std::size_t count = attrib.vertices.size() / 3;
  if (count == 0) return;
  const bool colors = attrib.colors.size() == attrib.vertices.size();
  ModelBuilder builder(model);
  builder.beginObject(std::filesystem::path(name).stem().string());
  model.positions.reserve(count);
  if (colors) model.colors.reserve(count);
  for (std::size_t v = 0; v < count; ++v) {
    const Vec3d p{attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]};
    model.positions.push_back(toFloat(p - model.origin));
    if (colors)
      model.colors.push_back(
          toRgba(attrib.colors[3 * v], attrib.colors[3 * v + 1], attrib.colors[3 * v + 2]));
  }
  builder.endObject();
}

// What tinyobjloader read.
struct ParsedObj {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
};

Result<ParsedObj> parseObj(const std::string& text, const std::string& name,
                           const std::string& baseDir) {
  ParsedObj obj;
  std::string warnings, errors;
  std::istringstream stream(text);
  tinyobj::MaterialFileReader materialReader(baseDir);
  const bool ok = tinyobj::LoadObj(&obj.attrib, &obj.shapes, &obj.materials, &warnings, &errors,
                                   &stream, baseDir.empty() ? nullptr : &materialReader,
                                   /*triangulate=*/false, /*default_vcols_fallback=*/false);
  if (!ok) {
    std::string message = errors.empty() ? "cannot parse" : errors;
    while (!message.empty() && (message.back() == '\n' || message.back() == '.'))
      message.pop_back();
    return badInput(name, message);
  }
  return obj;
}

// What the faces hold, once every index is checked against the file's counts.
struct FaceSummary {
  std::uint64_t faces = 0;
  bool anyNormal = false;
  bool anyColor = false;  // vertex colours, or a face with a known material
};

Result<FaceSummary> checkFaces(const std::string& text, const std::string& name,
                               const ParsedObj& obj) {
  const int vertexCount = static_cast<int>(obj.attrib.vertices.size() / 3);
  const int normalCount = static_cast<int>(obj.attrib.normals.size() / 3);
  FaceSummary summary;
  summary.anyColor = !obj.attrib.colors.empty();
  for (const tinyobj::shape_t& shape : obj.shapes) {
    std::size_t corner = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++summary.faces) {
      for (unsigned k = 0; k < shape.mesh.num_face_vertices[f]; ++k, ++corner) {
        const tinyobj::index_t& index = shape.mesh.indices[corner];
        if (index.vertex_index < 0 || index.vertex_index >= vertexCount) {
          return badInputAtLine(name, lineOfFace(text, summary.faces),
                                fmt::format("face refers to vertex {} but the file has {} vertices",
                                            index.vertex_index + 1, vertexCount));
        }
        if (index.normal_index >= normalCount) {
          return badInputAtLine(name, lineOfFace(text, summary.faces),
                                fmt::format("face refers to normal {} but the file has {} normals",
                                            index.normal_index + 1, normalCount));
        }
        summary.anyNormal = summary.anyNormal || index.normal_index >= 0;
      }
      if (!shape.mesh.material_ids.empty() && shape.mesh.material_ids[f] >= 0 &&
          static_cast<std::size_t>(shape.mesh.material_ids[f]) < obj.materials.size()) {
        summary.anyColor = true;
      }
    }
  }
  return summary;
}

// One shape as one object: a vertex per distinct (position, normal, material colour) corner,
// polygons fan-triangulated; smooth normals for the whole object where some corners lack `vn`.
void addShape(Model& model, ModelBuilder& builder, const ParsedObj& obj, std::size_t s,
              const FaceSummary& summary) {
  const tinyobj::attrib_t& attrib = obj.attrib;
  const tinyobj::mesh_t& mesh = obj.shapes[s].mesh;
  const bool vertexColors = !attrib.colors.empty();
  builder.beginObject(obj.shapes[s].name.empty() ? fmt::format("object {}", s)
                                                 : obj.shapes[s].name);
  const std::size_t firstVertex = model.positions.size();
  std::unordered_map<CornerKey, std::uint32_t, CornerHash> local;
  bool allNormals = true;
  std::size_t corner = 0;
  std::vector<std::uint32_t> polygon;
  for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
    const int material = mesh.material_ids.empty() ? -1 : mesh.material_ids[f];
    const bool materialColor =
        !vertexColors && material >= 0 && static_cast<std::size_t>(material) < obj.materials.size();
    polygon.clear();
    for (unsigned k = 0; k < mesh.num_face_vertices[f]; ++k, ++corner) {
      const tinyobj::index_t& index = mesh.indices[corner];
      const CornerKey key{index.vertex_index, index.normal_index, materialColor ? material : -1};
      auto [it, inserted] =
          local.try_emplace(key, static_cast<std::uint32_t>(model.positions.size() - firstVertex));
      polygon.push_back(it->second);
      if (!inserted) continue;
      const auto v = static_cast<std::size_t>(index.vertex_index);
      const Vec3d p{attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]};
      model.positions.push_back(toFloat(p - model.origin));
      if (summary.anyNormal) {
        Vec3f n{};
        if (index.normal_index >= 0) {
          const auto i = static_cast<std::size_t>(index.normal_index);
          n = {static_cast<float>(attrib.normals[3 * i]),
               static_cast<float>(attrib.normals[3 * i + 1]),
               static_cast<float>(attrib.normals[3 * i + 2])};
        } else {
          allNormals = false;
        }
        model.normals.push_back(n);
      }
      if (summary.anyColor) {
        Rgba8 color;
        if (vertexColors) {
          color = toRgba(attrib.colors[3 * v], attrib.colors[3 * v + 1], attrib.colors[3 * v + 2]);
        } else if (materialColor) {
          const auto& kd = obj.materials[static_cast<std::size_t>(material)].diffuse;
          color = toRgba(kd[0], kd[1], kd[2]);
        }
        model.colors.push_back(color);
      }
    }
    for (std::size_t k = 2; k < polygon.size(); ++k)
      model.indices.insert(model.indices.end(), {polygon[0], polygon[k - 1], polygon[k]});
  }
  builder.endObject();
  if (summary.anyNormal && !allNormals) {
    const std::size_t o = model.objects.size() - 1;
    computeVertexNormals(
        model.objectPositions(o), model.objectIndices(o),
        std::span(model.normals).subspan(firstVertex, model.objects[o].vertexCount));
  }
}

Result<Model> build(const std::string& text, const std::string& name, const std::string& baseDir) {
  LODFORGE_TRY(checkCoordinates(text, name));
  Result<ParsedObj> obj = parseObj(text, name, baseDir);
  if (!obj) return obj.status();
  Result<FaceSummary> summary = checkFaces(text, name, *obj);
  if (!summary) return summary.status();
  // World positions in double, then one origin for the model.
  Aabbd world;
  const std::vector<tinyobj::real_t>& vertices = obj->attrib.vertices;
  for (std::size_t v = 0; v + 2 < vertices.size(); v += 3)
    world.add(Vec3d{vertices[v], vertices[v + 1], vertices[v + 2]});
  Model model;
  model.origin = chooseOrigin(world);
  if (summary->faces == 0) {
    addVerticesOnly(model, obj->attrib, name);
    return model;
  }
  ModelBuilder builder(model);
  for (std::size_t s = 0; s < obj->shapes.size(); ++s) {
    if (obj->shapes[s].mesh.num_face_vertices.empty()) continue;  // lines or points only
    addShape(model, builder, *obj, s, *summary);
  }
  return model;
}

}  // namespace

Result<Model> readObj(const std::string& path) {
  Result<std::string> text = readFileToString(path, std::uint64_t{1} << 40);
  if (!text) return text.status();
  std::string baseDir = std::filesystem::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  return build(*text, path, baseDir + "/");
}

Result<Model> readObjFromMemory(std::span<const std::byte> bytes, const std::string& name) {
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return build(text, name, "");
}

}  // namespace lodforge
