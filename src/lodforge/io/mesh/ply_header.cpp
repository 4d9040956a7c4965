#include "lodforge/io/mesh/ply_header.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace lodforge {

std::string_view plyTypeName(PlyType type) {
  return extraTypePlyName(extraTypeOf(type));
}

std::size_t plyTypeSize(PlyType type) {
  return extraTypeSize(extraTypeOf(type));
}

bool plyTypeIsIntegral(PlyType type) {
  return type != PlyType::kFloat32 && type != PlyType::kFloat64;
}

std::string_view plyFormatName(PlyFormat format) {
  switch (format) {
    case PlyFormat::kAscii:
      return "ascii";
    case PlyFormat::kBinaryLittleEndian:
      return "binary_little_endian";
    case PlyFormat::kBinaryBigEndian:
      return "binary_big_endian";
  }
  return "?";
}

namespace {

constexpr std::size_t kMaxHeaderBytes = 1 << 20;
constexpr std::size_t kMaxHeaderLine = 1 << 16;

// A type by its PLY name ("uchar") or its sized one ("uint8"); PLY has no 64-bit integers.
std::optional<PlyType> parseType(std::string_view name) {
  for (int t = 0; t <= static_cast<int>(ExtraType::kFloat64); ++t) {
    const auto type = static_cast<ExtraType>(t);
    const std::string_view plyName = extraTypePlyName(type);
    if (!plyName.empty() && (name == plyName || name == extraTypeName(type)))
      return static_cast<PlyType>(type);
  }
  return std::nullopt;
}

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

// The header's text, a line at a time: the magic line, then a keyword per line up to
// 'end_header'. Errors name the line.
class HeaderParser {
 public:
  HeaderParser(ByteSource& source, std::uint64_t& lineNumber)
      : source_(source), lineNumber_(lineNumber) {}

  PlyHeader parse() {
    readMagic();
    bool sawFormat = false;
    while (nextLine()) {
      const std::string_view keyword = words_[0];
      if (keyword == "comment" || keyword == "obj_info") {
        header_.comments.emplace_back(
            std::string_view(line_).substr(std::min(line_.size(), keyword.size() + 1)));
      } else if (keyword == "format") {
        parseFormat();
        sawFormat = true;
      } else if (keyword == "element") {
        parseElement();
      } else if (keyword == "property") {
        parseProperty();
      } else {
        fail(fmt::format("unknown header keyword '{}'", keyword.substr(0, 40)));
      }
    }
    if (!sawFormat) fail("header has no 'format' line");
    header_.dataOffset = source_.offset();
    return std::move(header_);
  }

 private:
  [[noreturn]] void fail(std::string_view what) const {
    throw ErrorException{badInputAtLine(source_.name(), lineNumber_, what)};
  }

  void readMagic() {
    if (!source_.readLine(line_, kMaxHeaderLine) || line_ != "ply") {
      throw ErrorException{
          badInputAtByte(source_.name(), 0, "not a PLY file: expected the magic line 'ply'")};
    }
    lineNumber_ = 1;
  }

  // The words of the next line that has any; false at 'end_header'.
  bool nextLine() {
    do {
      if (source_.offset() > kMaxHeaderBytes) fail("header longer than 1 MiB");
      if (!source_.readLine(line_, kMaxHeaderLine))
        fail("file ends inside the header (no 'end_header')");
      ++lineNumber_;
      words_ = splitWords(line_);
    } while (words_.empty());
    return words_[0] != "end_header";
  }

  // format <type> 1.0
  void parseFormat() {
    if (words_.size() != 3) fail("expected 'format <type> 1.0'");
    if (words_[1] == "ascii")
      header_.format = PlyFormat::kAscii;
    else if (words_[1] == "binary_little_endian")
      header_.format = PlyFormat::kBinaryLittleEndian;
    else if (words_[1] == "binary_big_endian")
      header_.format = PlyFormat::kBinaryBigEndian;
    else
      fail(fmt::format("unknown format '{}'", words_[1]));
    if (words_[2] != "1.0") fail(fmt::format("unsupported version '{}'", words_[2]));
  }

  // element <name> <count>
  void parseElement() {
    if (words_.size() != 3) fail("expected 'element <name> <count>'");
    PlyElement e;
    e.name = words_[1];
    const auto [end, error] =
        std::from_chars(words_[2].data(), words_[2].data() + words_[2].size(), e.count);
    if (error != std::errc() || end != words_[2].data() + words_[2].size())
      fail(fmt::format("element count '{}' is not a whole number", words_[2]));
    header_.elements.push_back(std::move(e));
  }

  // property <type> <name>, or property list <count type> <item type> <name>
  void parseProperty() {
    if (header_.elements.empty()) fail("property before any element");
    PlyProperty p;
    if (words_.size() == 5 && words_[1] == "list") {
      const auto countType = parseType(words_[2]);
      const auto itemType = parseType(words_[3]);
      if (!countType || !itemType) fail(fmt::format("unknown type in '{}'", line_));
      if (!plyTypeIsIntegral(*countType)) fail("list count type must be an integer type");
      p.isList = true;
      p.countType = *countType;
      p.type = *itemType;
      p.name = words_[4];
    } else if (words_.size() == 3) {
      const auto type = parseType(words_[1]);
      if (!type) fail(fmt::format("unknown type '{}'", words_[1]));
      p.type = *type;
      p.name = words_[2];
    } else {
      fail(
          "expected 'property <type> <name>' or 'property list <count type> <item type> "
          "<name>'");
    }
    header_.elements.back().properties.push_back(std::move(p));
  }

  ByteSource& source_;
  std::uint64_t& lineNumber_;
  std::string line_;
  std::vector<std::string_view> words_;  // of line_
  PlyHeader header_;
};

int findProperty(const PlyElement& e, std::initializer_list<std::string_view> names) {
  for (std::string_view name : names) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      if (e.properties[i].name == name) return static_cast<int>(i);
    }
  }
  return -1;
}

// A vertex's texture coordinates, under the names exporters give them (scalars only).
void assignUvRoles(const PlyElement& v, PlyRoles& roles) {
  for (const auto& [u, w] :
       {std::pair{"s", "t"}, std::pair{"u", "v"}, std::pair{"texture_u", "texture_v"},
        std::pair{"texture_s", "texture_t"}}) {
    const int a = findProperty(v, {u}), b = findProperty(v, {w});
    if (a < 0 || b < 0 || v.properties[static_cast<std::size_t>(a)].isList ||
        v.properties[static_cast<std::size_t>(b)].isList)
      continue;
    roles.u = a, roles.v = b;
    return;
  }
}

// The vertex index list of a face or strip element.
int indexListRole(const std::string& file, const PlyElement& e) {
  const int role = findProperty(e, {"vertex_indices", "vertex_index"});
  if (role < 0 || !e.properties[static_cast<std::size_t>(role)].isList) {
    throw ErrorException{
        badInput(file, fmt::format("{} element lacks the list 'vertex_indices'", e.name))};
  }
  if (!plyTypeIsIntegral(e.properties[static_cast<std::size_t>(role)].type)) {
    throw ErrorException{
        badInput(file, fmt::format("{} vertex indices must have an integer type", e.name))};
  }
  return role;
}

// The vertex's scalar properties that are not a position, normal or colour, packed one after
// the other in their own types.
void planExtras(const PlyElement& vertex, PlyRoles& roles, PointExtras& extras) {
  const std::array<int, 12> known = {roles.x,    roles.y,     roles.z,   roles.nx,
                                     roles.ny,   roles.nz,    roles.red, roles.green,
                                     roles.blue, roles.alpha, roles.u,   roles.v};
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const PlyProperty& p = vertex.properties[i];
    if (p.isList || std::find(known.begin(), known.end(), static_cast<int>(i)) != known.end())
      continue;
    ExtraField field;
    field.name = printableText(p.name);
    field.type = extraTypeOf(p.type);
    field.offset = extras.stride;
    extras.stride += static_cast<std::uint32_t>(extraTypeSize(field.type));
    extras.fields.push_back(std::move(field));
    roles.extras.push_back(static_cast<int>(i));
  }
}

}  // namespace

PlyHeader parsePlyHeader(ByteSource& source, std::uint64_t& lineNumber) {
  return HeaderParser(source, lineNumber).parse();
}

namespace {

// A face's roles: its index list, object id (the first candidate that is a scalar), corner
// texture coordinates (a list) and texture number (a scalar).
void assignFaceRoles(PlyHeader& header, const std::string& name,
                     std::span<const std::string> objectIdProperties, PlyRoles& roles) {
  const PlyElement& f = header.elements[static_cast<std::size_t>(roles.faceElement)];
  const auto isList = [&](int role) { return f.properties[static_cast<std::size_t>(role)].isList; };
  roles.faceIndices = indexListRole(name, f);
  for (const std::string& candidate : objectIdProperties) {
    roles.objectId = findProperty(f, {candidate});
    if (roles.objectId >= 0 && !isList(roles.objectId)) break;
    roles.objectId = -1;
  }
  header.faceCount = f.count;
  header.hasObjectIds = roles.objectId >= 0;
  roles.faceTexcoords = findProperty(f, {"texcoord"});
  if (roles.faceTexcoords >= 0 && !isList(roles.faceTexcoords)) roles.faceTexcoords = -1;
  roles.texnumber = findProperty(f, {"texnumber"});
  if (roles.texnumber >= 0 && isList(roles.texnumber)) roles.texnumber = -1;
  header.hasFaceUvs = roles.faceTexcoords >= 0;
  header.hasTextureNumbers = roles.texnumber >= 0;
}

}  // namespace

PlyRoles assignPlyRoles(PlyHeader& header, const std::string& name, bool readExtras,
                        std::span<const std::string> objectIdProperties) {
  PlyRoles roles;
  for (std::size_t i = 0; i < header.elements.size(); ++i) {
    const PlyElement& e = header.elements[i];
    int* role = e.name == "vertex"      ? &roles.vertexElement
                : e.name == "face"      ? &roles.faceElement
                : e.name == "tristrips" ? &roles.stripElement
                                        : nullptr;
    if (!role) continue;
    if (*role >= 0) throw ErrorException{badInput(name, fmt::format("two '{}' elements", e.name))};
    *role = static_cast<int>(i);
  }
  if (roles.vertexElement < 0)
    throw ErrorException{badInput(name, "no 'vertex' element in the header")};
  const PlyElement& v = header.elements[static_cast<std::size_t>(roles.vertexElement)];
  roles.x = findProperty(v, {"x"});
  roles.y = findProperty(v, {"y"});
  roles.z = findProperty(v, {"z"});
  if (roles.x < 0 || roles.y < 0 || roles.z < 0)
    throw ErrorException{badInput(name, "vertex element lacks x, y or z")};
  for (int role : {roles.x, roles.y, roles.z}) {
    if (v.properties[static_cast<std::size_t>(role)].isList)
      throw ErrorException{badInput(name, "vertex x, y, z must be scalars")};
  }
  roles.nx = findProperty(v, {"nx", "normal_x"});
  roles.ny = findProperty(v, {"ny", "normal_y"});
  roles.nz = findProperty(v, {"nz", "normal_z"});
  roles.red = findProperty(v, {"red", "diffuse_red", "r"});
  roles.green = findProperty(v, {"green", "diffuse_green", "g"});
  roles.blue = findProperty(v, {"blue", "diffuse_blue", "b"});
  roles.alpha = findProperty(v, {"alpha", "diffuse_alpha", "a"});
  header.vertexCount = v.count;
  header.hasNormals = roles.nx >= 0 && roles.ny >= 0 && roles.nz >= 0;
  header.hasColors = roles.red >= 0 && roles.green >= 0 && roles.blue >= 0;
  assignUvRoles(v, roles);
  header.hasUvs = roles.u >= 0 && roles.v >= 0;
  for (const std::string& comment : header.comments) {
    if (comment.starts_with("TextureFile ")) header.textureFiles.push_back(comment.substr(12));
  }
  if (readExtras) planExtras(v, roles, header.extras);
  const auto typeOf = [&](int role) { return v.properties[static_cast<std::size_t>(role)].type; };
  header.doublePositions = typeOf(roles.x) == PlyType::kFloat64;
  header.floatPositions = typeOf(roles.x) == PlyType::kFloat32 &&
                          typeOf(roles.y) == PlyType::kFloat32 &&
                          typeOf(roles.z) == PlyType::kFloat32;
  if (header.vertexCount > std::numeric_limits<std::uint32_t>::max()) {
    throw ErrorException{badInput(name, fmt::format("{} vertices: lodforge indexes at most 2^32-1 "
                                                    "vertices per file",
                                                    header.vertexCount))};
  }
  if (roles.faceElement >= 0) assignFaceRoles(header, name, objectIdProperties, roles);
  if (roles.stripElement >= 0) {
    const PlyElement& s = header.elements[static_cast<std::size_t>(roles.stripElement)];
    roles.stripIndices = indexListRole(name, s);
    header.stripCount = s.count;
    // Strips carry no object id or texture: their triangles would belong to no object.
    if (header.hasObjectIds || header.hasFaceUvs || header.hasTextureNumbers) {
      throw ErrorException{
          Error{ErrorKind::kUnsupported,
                fmt::format("{}: faces with {} and 'tristrips' in one file are not supported", name,
                            header.hasObjectIds ? "object ids" : "textures")}};
    }
  }
  return roles;
}

void checkPlyCountsFitFile(const PlyHeader& header, std::uint64_t fileSize,
                           const std::string& name) {
  // Every element needs some minimum number of bytes, so a header claiming 10^12 vertices in a
  // small file is caught here.
  const std::uint64_t available = fileSize - header.dataOffset;
  std::uint64_t needed = 0;
  for (const PlyElement& e : header.elements) {
    std::uint64_t minBytes = 0;
    for (const PlyProperty& p : e.properties) {
      if (header.format == PlyFormat::kAscii)
        minBytes += 2;  // a digit and a separator
      else
        minBytes += p.isList ? plyTypeSize(p.countType) : plyTypeSize(p.type);
    }
    if (minBytes > 0 && e.count > (available - std::min(available, needed)) / minBytes + 1) {
      throw ErrorException{badInputAtByte(
          name, header.dataOffset,
          fmt::format("header declares {} '{}' elements of at least {} bytes each, but only {} "
                      "bytes follow the header (room for {} at most): the file is truncated{}",
                      e.count, e.name, minBytes, available,
                      (available - std::min(available, needed)) / minBytes, kPlySalvageHint))};
    }
    needed += e.count * minBytes;
  }
}

std::optional<std::string> unreadPlyElements(const PlyHeader& header, const std::string& name) {
  std::vector<std::string> skipped;
  for (const PlyElement& e : header.elements) {
    if (e.count > 0 && e.name != "vertex" && e.name != "face" && e.name != "tristrips")
      skipped.push_back(fmt::format("'{}' ({})", e.name, e.count));
  }
  if (skipped.empty()) return std::nullopt;
  return fmt::format("{}: element{} not read: {}", name, skipped.size() == 1 ? "" : "s",
                     fmt::join(skipped, ", "));
}

}  // namespace lodforge
