#include "lodforge/io/mesh/obj_reader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tiny_obj_loader.h>

#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"
#include "lodforge/io/mesh/obj_materials.h"

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

// Line (l) and point (p) elements: not surfaces, and tinyobjloader's shapes neither keep nor
// count them all (it drops an edges-only group at the next `g` and repeats lines at each
// `usemtl`), so they are counted from the text.
struct NonFaceElements {
  std::uint64_t lines = 0, lineVertices = 0, points = 0;
};

// tinyobjloader reads an unparseable number ("nan", "1e999", "abc") as 0 without a word, so the
// coordinates are checked here first: bad input must fail loudly, not become a vertex at 0. The
// same pass counts the line and point elements.
Result<NonFaceElements> checkCoordinates(std::string_view text, const std::string& name) {
  Status status;
  NonFaceElements counted;
  forEachLine(text, [&](std::uint64_t line, const std::vector<std::string_view>& words) {
    if (!words.empty() && words[0] == "l") {
      ++counted.lines;
      counted.lineVertices += words.size() - 1;
    } else if (!words.empty() && words[0] == "p") {
      counted.points += words.size() - 1;
    }
    if (words.empty() || (words[0] != "v" && words[0] != "vn" && words[0] != "vt")) return true;
    const bool texture = words[0] == "vt";
    if (words.size() < (texture ? 2u : 4u)) {
      status = badInputAtLine(
          name, line,
          fmt::format("'{}' needs {} coordinates", words[0], texture ? "two" : "three"));
      return false;
    }
    for (std::size_t i = 1; i < words.size() && i <= (texture ? 3u : 6u); ++i) {
      double value = 0;
      const std::string_view w = words[i];
      const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), value);
      // (Texture coordinates are floats: one beyond a float's range is no coordinate either.)
      if (error != std::errc() || end != w.data() + w.size() || !std::isfinite(value) ||
          (texture && std::abs(value) > 1e30)) {
        status = badInputAtLine(
            name, line, fmt::format("expected a finite number, found '{}'", w.substr(0, 40)));
        return false;
      }
    }
    return true;
  });
  if (!status.ok()) return status;
  return counted;
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
  int vertex, normal, texcoord, material;
  bool operator==(const CornerKey&) const = default;
};

struct CornerHash {
  std::size_t operator()(const CornerKey& k) const {
    std::uint64_t h = static_cast<std::uint32_t>(k.vertex);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.normal);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.texcoord);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k.material);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

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
          toRgba8(attrib.colors[3 * v], attrib.colors[3 * v + 1], attrib.colors[3 * v + 2]));
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
  bool anyColor = false;               // vertex colours, or a face with a known material
  bool anyTextured = false;            // a face whose material has a texture
  std::uint64_t cornersWithoutUv = 0;  // corners of textured faces without `vt`
};

Result<FaceSummary> checkFaces(const std::string& text, const std::string& name,
                               const ParsedObj& obj, const ObjTextures& textures) {
  const int vertexCount = static_cast<int>(obj.attrib.vertices.size() / 3);
  const int normalCount = static_cast<int>(obj.attrib.normals.size() / 3);
  const int texcoordCount = static_cast<int>(obj.attrib.texcoords.size() / 2);
  FaceSummary summary;
  summary.anyColor = !obj.attrib.colors.empty();
  auto refuse = [&](std::string_view what, std::string_view plural, int index, int count) {
    return badInputAtLine(
        name, lineOfFace(text, summary.faces),
        fmt::format("face refers to {} {} but the file has {} {}", what, index + 1, count, plural));
  };
  for (const tinyobj::shape_t& shape : obj.shapes) {
    std::size_t corner = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++summary.faces) {
      const int material = shape.mesh.material_ids.empty() ? -1 : shape.mesh.material_ids[f];
      const bool textured = textures.textured(material);
      summary.anyTextured = summary.anyTextured || textured;
      for (unsigned k = 0; k < shape.mesh.num_face_vertices[f]; ++k, ++corner) {
        const tinyobj::index_t& index = shape.mesh.indices[corner];
        if (index.vertex_index < 0 || index.vertex_index >= vertexCount)
          return refuse("vertex", "vertices", index.vertex_index, vertexCount);
        if (index.normal_index >= normalCount)
          return refuse("normal", "normals", index.normal_index, normalCount);
        if (index.texcoord_index >= texcoordCount)
          return refuse("texture coordinate", "texture coordinates", index.texcoord_index,
                        texcoordCount);
        summary.anyNormal = summary.anyNormal || index.normal_index >= 0;
        if (textured && index.texcoord_index < 0) ++summary.cornersWithoutUv;
      }
      if (material >= 0 && static_cast<std::size_t>(material) < obj.materials.size())
        summary.anyColor = true;
    }
  }
  return summary;
}

// A shape's faces that become one object: all of them, or those of one textured material.
struct FaceGroup {
  std::string name;
  std::vector<std::uint32_t> faces;
};

// A shape that uses a texture and another material splits into an object per textured
// material (named "shape (material)") and one of its other faces: an object with a texture has
// one material (model.h).
std::vector<FaceGroup> groupFaces(const ParsedObj& obj, std::size_t s,
                                  const ObjTextures& textures) {
  const tinyobj::shape_t& shape = obj.shapes[s];
  const std::string name = shape.name.empty() ? fmt::format("object {}", s) : shape.name;
  const auto& ids = shape.mesh.material_ids;
  const std::size_t faceCount = shape.mesh.num_face_vertices.size();
  auto groupOf = [&](std::size_t f) {
    return textures.textured(ids.empty() ? -1 : ids[f]) ? ids[f] : -1;
  };
  std::vector<int> order;  // textured materials (or -1) in order of first use
  for (std::size_t f = 0; f < faceCount; ++f) {
    if (std::find(order.begin(), order.end(), groupOf(f)) == order.end())
      order.push_back(groupOf(f));
  }
  std::vector<FaceGroup> groups(order.size());
  for (std::size_t g = 0; g < order.size(); ++g) {
    groups[g].name =
        order.size() == 1 || order[g] < 0
            ? name
            : fmt::format("{} ({})", name, obj.materials[static_cast<std::size_t>(order[g])].name);
  }
  for (std::size_t f = 0; f < faceCount; ++f) {
    const auto g =
        static_cast<std::size_t>(std::find(order.begin(), order.end(), groupOf(f)) - order.begin());
    groups[g].faces.push_back(static_cast<std::uint32_t>(f));
  }
  return groups;
}

// Where the OBJ's parts go, for one object being built.
struct ObjContext {
  const ParsedObj& obj;
  const FaceSummary& summary;
  const ObjTextures& textures;
};

// Appends the vertex of one corner: position, normal (flagging a missing one), colour, UV.
void addCorner(Model& model, const ObjContext& context, const tinyobj::index_t& index, int material,
               bool& allNormals) {
  const tinyobj::attrib_t& attrib = context.obj.attrib;
  const bool vertexColors = !attrib.colors.empty();
  const bool textured = context.textures.textured(material);
  const bool materialColor = !vertexColors && !textured && material >= 0 &&
                             static_cast<std::size_t>(material) < context.obj.materials.size();
  const auto v = static_cast<std::size_t>(index.vertex_index);
  const Vec3d p{attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]};
  model.positions.push_back(toFloat(p - model.origin));
  if (context.summary.anyNormal) {
    Vec3f n{};
    if (index.normal_index >= 0) {
      const auto i = static_cast<std::size_t>(index.normal_index);
      n = {static_cast<float>(attrib.normals[3 * i]), static_cast<float>(attrib.normals[3 * i + 1]),
           static_cast<float>(attrib.normals[3 * i + 2])};
    } else {
      allNormals = false;
    }
    model.normals.push_back(n);
  }
  if (context.summary.anyColor) {
    Rgba8 color;  // white: a texture's own colour, or no colour at all
    if (vertexColors) {
      color = toRgba8(attrib.colors[3 * v], attrib.colors[3 * v + 1], attrib.colors[3 * v + 2]);
    } else if (materialColor) {
      const auto& kd = context.obj.materials[static_cast<std::size_t>(material)].diffuse;
      color = toRgba8(kd[0], kd[1], kd[2]);
    }
    model.colors.push_back(color);
  }
  if (context.summary.anyTextured) {
    Vec2f uv;
    if (textured && index.texcoord_index >= 0) {
      const auto t = static_cast<std::size_t>(index.texcoord_index);
      uv = context.textures.toUv(material, static_cast<float>(attrib.texcoords[2 * t]),
                                 static_cast<float>(attrib.texcoords[2 * t + 1]));
    }
    model.uvs.push_back(uv);
  }
}

// One group of a shape's faces as one object: a vertex per distinct (position, normal, UV,
// material colour) corner, polygons fan-triangulated; smooth normals for the whole object
// where some corners lack `vn`.
void addGroup(Model& model, ModelBuilder& builder, const ObjContext& context,
              const tinyobj::mesh_t& mesh, std::span<const std::size_t> firstCorner,
              const FaceGroup& group) {
  builder.beginObject(group.name);
  const std::size_t firstVertex = model.positions.size();
  std::unordered_map<CornerKey, std::uint32_t, CornerHash> local;
  bool allNormals = true;
  std::vector<std::uint32_t> polygon;
  for (std::uint32_t f : group.faces) {
    const int material = mesh.material_ids.empty() ? -1 : mesh.material_ids[f];
    if (context.textures.textured(material))
      model.objects.back().material = context.textures.material[static_cast<std::size_t>(material)];
    const bool keepsMaterial = context.obj.attrib.colors.empty();
    polygon.clear();
    for (std::size_t corner = firstCorner[f]; corner < firstCorner[f + 1]; ++corner) {
      const tinyobj::index_t& index = mesh.indices[corner];
      const CornerKey key{index.vertex_index, index.normal_index, index.texcoord_index,
                          keepsMaterial ? material : -1};
      auto [it, inserted] =
          local.try_emplace(key, static_cast<std::uint32_t>(model.positions.size() - firstVertex));
      polygon.push_back(it->second);
      if (inserted) addCorner(model, context, index, material, allNormals);
    }
    for (std::size_t k = 2; k < polygon.size(); ++k)
      model.indices.insert(model.indices.end(), {polygon[0], polygon[k - 1], polygon[k]});
  }
  builder.endObject();
  if (context.summary.anyNormal && !allNormals) {
    const std::size_t o = model.objects.size() - 1;
    computeVertexNormals(
        model.objectPositions(o), model.objectIndices(o),
        std::span(model.normals).subspan(firstVertex, model.objects[o].vertexCount));
  }
}

void addShape(Model& model, ModelBuilder& builder, const ObjContext& context, std::size_t s) {
  const tinyobj::mesh_t& mesh = context.obj.shapes[s].mesh;
  std::vector<std::size_t> firstCorner(mesh.num_face_vertices.size() + 1, 0);
  for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f)
    firstCorner[f + 1] = firstCorner[f] + mesh.num_face_vertices[f];
  for (const FaceGroup& group : groupFaces(context.obj, s, context.textures))
    addGroup(model, builder, context, mesh, firstCorner, group);
}

// Where textures may lie: beside the OBJ, and beside each material library it names.
std::vector<std::string> textureDirectories(std::string_view text, const std::string& baseDir) {
  std::vector<std::string> directories{baseDir};
  forEachLine(text, [&](std::uint64_t, const std::vector<std::string_view>& words) {
    if (words.size() >= 2 && words[0] == "mtllib") {
      const std::string library(words[1].data(), words.back().data() + words.back().size());
      const std::string parent = std::filesystem::path(baseDir + library).parent_path().string();
      if (!parent.empty() && parent + "/" != baseDir) directories.push_back(parent + "/");
    }
    return true;
  });
  return directories;
}

// Line and point elements beside faces are reported, not dropped in silence. (A file of
// vertices without faces is read as a point set instead.)
void warnLinesAndPoints(const NonFaceElements& counted, const std::string& name,
                        std::vector<std::string>* warnings) {
  std::vector<std::string> parts;
  if (counted.lines > 0)
    parts.push_back(fmt::format("{} line element{} ({} vertices)", counted.lines,
                                counted.lines == 1 ? "" : "s", counted.lineVertices));
  if (counted.points > 0)
    parts.push_back(fmt::format("{} point{}", counted.points, counted.points == 1 ? "" : "s"));
  if (warnings == nullptr || parts.empty()) return;
  warnings->push_back(
      fmt::format("{}: {} not read: only faces are", name, fmt::join(parts, " and ")));
}

Result<Model> build(const std::string& text, const std::string& name, const std::string& baseDir,
                    std::vector<std::string>* warnings) {
  Result<NonFaceElements> nonFaces = checkCoordinates(text, name);
  if (!nonFaces) return nonFaces.status();
  Result<ParsedObj> obj = parseObj(text, name, baseDir);
  if (!obj) return obj.status();
  Model model;
  const ObjTextures textures =
      baseDir.empty()
          ? ObjTextures{}
          : resolveObjTextures(obj->materials, textureDirectories(text, baseDir), model, warnings);
  Result<FaceSummary> summary = checkFaces(text, name, *obj, textures);
  if (!summary) return summary.status();
  if (summary->cornersWithoutUv > 0 && warnings)
    warnings->push_back(
        fmt::format("{}: {} corners of textured faces have no texture coordinate "
                    "(vt); they sample the texture's corner",
                    name, summary->cornersWithoutUv));
  // World positions in double, then one origin for the model.
  Aabbd world;
  const std::vector<tinyobj::real_t>& vertices = obj->attrib.vertices;
  for (std::size_t v = 0; v + 2 < vertices.size(); v += 3)
    world.add(Vec3d{vertices[v], vertices[v + 1], vertices[v + 2]});
  model.origin = chooseOrigin(world);
  if (summary->faces == 0) {
    addVerticesOnly(model, obj->attrib, name);
    return model;
  }
  warnLinesAndPoints(*nonFaces, name, warnings);
  ModelBuilder builder(model);
  const ObjContext context{*obj, *summary, textures};
  for (std::size_t s = 0; s < obj->shapes.size(); ++s) {
    if (obj->shapes[s].mesh.num_face_vertices.empty()) continue;  // lines or points only
    addShape(model, builder, context, s);
  }
  dropUnusedMaterials(model);
  return model;
}

}  // namespace

Result<Model> readObj(const std::string& path, std::vector<std::string>* warnings) {
  Result<std::string> text = readFileToString(path, std::uint64_t{1} << 40);
  if (!text) return text.status();
  std::string baseDir = std::filesystem::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  return build(*text, path, baseDir + "/", warnings);
}

Result<Model> readObjFromMemory(std::span<const std::byte> bytes, const std::string& name) {
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  return build(text, name, "", nullptr);
}

}  // namespace lodforge
