#include "lodforge/io/mesh/ply_reader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>

#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"

namespace lodforge {

std::string_view plyTypeName(PlyType type) {
  static constexpr std::string_view kNames[] = {"char", "uchar", "short", "ushort",
                                                "int",  "uint",  "float", "double"};
  return kNames[static_cast<int>(type)];
}

std::size_t plyTypeSize(PlyType type) {
  static constexpr std::size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(type)];
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
// An ascii element is one line, and a triangle strip is one element: 300 K six-digit indices
// take 2 MB. The bound keeps a file without line breaks from growing the line without end.
constexpr std::size_t kMaxAsciiLine = std::size_t{64} << 20;
constexpr std::uint64_t kMaxPolygon = 1 << 20;  // corners in one face; more is not a mesh
constexpr std::uint64_t kStripRun = 4096;       // binary strip indices read at once

bool isIntegral(PlyType t) {
  return t != PlyType::kFloat32 && t != PlyType::kFloat64;
}

std::optional<PlyType> parseType(std::string_view name) {
  static constexpr std::pair<std::string_view, PlyType> kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [n, t] : kTypes) {
    if (n == name) return t;
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

// Where each property lodforge understands sits in its element; -1 when absent.
struct Roles {
  int vertexElement = -1, faceElement = -1;
  int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1;
  int red = -1, green = -1, blue = -1, alpha = -1;
  int faceIndices = -1, objectId = -1;
  int stripElement = -1, stripIndices = -1;  // 'tristrips' and its index list
  std::vector<int> extras;                   // vertex properties carried as extra fields
};

ExtraType extraTypeOf(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
      return ExtraType::kInt8;
    case PlyType::kUint8:
      return ExtraType::kUint8;
    case PlyType::kInt16:
      return ExtraType::kInt16;
    case PlyType::kUint16:
      return ExtraType::kUint16;
    case PlyType::kInt32:
      return ExtraType::kInt32;
    case PlyType::kUint32:
      return ExtraType::kUint32;
    case PlyType::kFloat32:
      return ExtraType::kFloat32;
    case PlyType::kFloat64:
      return ExtraType::kFloat64;
  }
  return ExtraType::kFloat64;
}

// A value of a PLY scalar (exact in a double) stored as its type.
void storeExtra(std::byte* at, ExtraType type, double v) {
  const auto put = [at](auto x) { std::memcpy(at, &x, sizeof x); };
  switch (type) {
    case ExtraType::kInt8:
      return put(static_cast<std::int8_t>(v));
    case ExtraType::kUint8:
      return put(static_cast<std::uint8_t>(v));
    case ExtraType::kInt16:
      return put(static_cast<std::int16_t>(v));
    case ExtraType::kUint16:
      return put(static_cast<std::uint16_t>(v));
    case ExtraType::kInt32:
      return put(static_cast<std::int32_t>(v));
    case ExtraType::kUint32:
      return put(static_cast<std::uint32_t>(v));
    case ExtraType::kFloat32:
      return put(static_cast<float>(v));
    default:
      return put(v);
  }
}

int findProperty(const PlyElement& e, std::initializer_list<std::string_view> names) {
  for (std::string_view name : names) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      if (e.properties[i].name == name) return static_cast<int>(i);
    }
  }
  return -1;
}

// The vertex index list of a face or strip element.
int indexListRole(const std::string& file, const PlyElement& e) {
  const int role = findProperty(e, {"vertex_indices", "vertex_index"});
  if (role < 0 || !e.properties[static_cast<std::size_t>(role)].isList) {
    throw ErrorException{
        badInput(file, fmt::format("{} element lacks the list 'vertex_indices'", e.name))};
  }
  if (!isIntegral(e.properties[static_cast<std::size_t>(role)].type)) {
    throw ErrorException{
        badInput(file, fmt::format("{} vertex indices must have an integer type", e.name))};
  }
  return role;
}

// A strip restarts at index -1; in an unsigned index type that is the all-ones value, when it
// is no vertex's index.
bool isStripRestart(double raw, PlyType type, std::uint64_t vertexCount) {
  switch (type) {
    case PlyType::kUint8:
      return raw == 0xFF && raw >= static_cast<double>(vertexCount);
    case PlyType::kUint16:
      return raw == 0xFFFF && raw >= static_cast<double>(vertexCount);
    case PlyType::kUint32:
      return raw == 0xFFFF'FFFF && raw >= static_cast<double>(vertexCount);
    default:
      return raw == -1;
  }
}

}  // namespace

struct PlyReader::State {
  ByteSource source;
  std::optional<std::span<const std::byte>> memory;  // the bytes, when read from memory
  PlyReadOptions options;
  PlyHeader header;
  Roles roles;
  bool swap = false;              // binary data in the other byte order than this machine
  std::size_t element = 0;        // element being read
  std::uint64_t elementDone = 0;  // how many of it are read
  // ascii tokenizer
  std::string line;
  std::size_t linePos = 0;
  std::uint64_t lineNumber = 0;
  std::uint64_t elementStart = 0;  // byte or line where the current element began
  std::vector<double> values;      // scratch: scalar property values of one element

  explicit State(ByteSource s) : source(std::move(s)) {}

  [[noreturn]] void fail(std::string_view what) const { throw ErrorException{positioned(what)}; }
  Error positioned(std::string_view what) const {
    if (header.format == PlyFormat::kAscii)
      return badInputAtLine(source.name(), elementStart, what);
    return badInputAtByte(source.name(), elementStart, what);
  }

  // What a user whose file was cut short can do (every command that reads PLY takes it).
  static constexpr std::string_view kSalvageHint =
      "; --salvage reads the complete elements before the cut";

  // The input stops early. An error, unless salvaging: then reading ends after the last
  // complete element and `truncation` says where.
  struct Truncated {};
  [[noreturn]] void fileEnds(std::string_view what) {
    if (!options.salvageTruncated) fail(fmt::format("{}{}", what, kSalvageHint));
    truncation = positioned(what).message;
    throw Truncated{};
  }
  std::optional<std::string> truncation;
  std::size_t faceFirstCorner = 0;  // where the face being read began in batch.triangles

  // --- header ---------------------------------------------------------------------------------

  void parseHeader();
  void assignRoles();
  void checkCountsFitFile();

  // --- values ---------------------------------------------------------------------------------

  std::string_view nextToken(const PlyElement& e) {
    while (true) {
      while (linePos < line.size() && (line[linePos] == ' ' || line[linePos] == '\t')) ++linePos;
      if (linePos < line.size()) break;
      if (!source.readLine(line, kMaxAsciiLine)) {
        fileEnds(
            fmt::format("{} {}: file ends before the element is complete", e.name, elementDone));
      }
      ++lineNumber;
      linePos = 0;
    }
    const std::size_t start = linePos;
    while (linePos < line.size() && line[linePos] != ' ' && line[linePos] != '\t') ++linePos;
    return std::string_view(line).substr(start, linePos - start);
  }

  double readNumber(const PlyElement& e, const PlyProperty& p, PlyType type) {
    if (header.format == PlyFormat::kAscii) {
      const std::string_view token = nextToken(e);
      double value = 0;
      const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (error != std::errc() || end != token.data() + token.size()) {
        fail(fmt::format("{} {}: expected a number for '{}', found '{}'", e.name, elementDone,
                         p.name, token.substr(0, 40)));
      }
      if (isIntegral(type) && value != std::floor(value)) {
        fail(fmt::format("{} {}: expected an integer for '{}', found '{}'", e.name, elementDone,
                         p.name, token.substr(0, 40)));
      }
      return value;
    }
    std::byte bytes[8];
    if (!source.read(bytes, plyTypeSize(type))) {
      fileEnds(
          fmt::format("{} {}: file ends inside property '{}' ({} of {} '{}' elements complete)",
                      e.name, elementDone, p.name, elementDone, e.count, e.name));
    }
    return decodeNumber(bytes, type);
  }

  // A list's length, checked against what the rest of the file can hold (unless `mustFit` is
  // false: then the list is read up to where the file ends).
  std::uint64_t readListCount(const PlyElement& e, const PlyProperty& p, bool mustFit = true) {
    const double count = readNumber(e, p, p.countType);
    if (count < 0)
      fail(fmt::format("{} {}: negative list length for '{}'", e.name, elementDone, p.name));
    if (count > 4294967295.0) {  // more than any count type holds (an ascii file may say so)
      fail(fmt::format("{} {}: list length {} for '{}' is too large", e.name, elementDone, count,
                       p.name));
    }
    const auto n = static_cast<std::uint64_t>(count);
    if (!mustFit) return n;
    // Items need a byte each plus a separator in ascii (the current line's rest counts too).
    const bool ascii = header.format == PlyFormat::kAscii;
    const std::uint64_t available = source.remaining() + (ascii ? line.size() - linePos + 1 : 0);
    if (n > available / (ascii ? 2 : plyTypeSize(p.type))) {
      fileEnds(fmt::format("{} {}: list '{}' claims {} items, more than the rest of the file holds",
                           e.name, elementDone, p.name, n));
    }
    return n;
  }

  void skipProperty(const PlyElement& e, const PlyProperty& p) {
    if (!p.isList) {
      readNumber(e, p, p.type);
      return;
    }
    const std::uint64_t n = readListCount(e, p);
    if (header.format != PlyFormat::kAscii) {
      if (!source.skip(n * plyTypeSize(p.type)))
        fileEnds(fmt::format("{} {}: file ends inside list '{}'", e.name, elementDone, p.name));
      return;
    }
    for (std::uint64_t i = 0; i < n; ++i) readNumber(e, p, p.type);
  }

  void beginElement() {
    if (header.format == PlyFormat::kAscii) {
      // Each element starts on a fresh line; leftovers on the previous line are an error.
      while (linePos < line.size() && (line[linePos] == ' ' || line[linePos] == '\t')) ++linePos;
      if (linePos < line.size()) {
        fail(fmt::format("unexpected '{}' after the end of an element",
                         std::string_view(line).substr(linePos, 40)));
      }
      elementStart = lineNumber + 1;
    } else {
      elementStart = source.offset();
    }
  }

  // A binary element of scalar properties only has a fixed size: read whole, then decoded from
  // memory (one read per vertex instead of one per property). Empty: not fixed.
  std::vector<std::size_t> recordOffsets;  // per property
  int recordElement = -1;
  std::vector<std::byte> record;       // one element's bytes
  std::vector<std::byte> cornerBytes;  // a binary face's corners
  void planRecord(const PlyElement& e);
  void planExtras(const PlyElement& vertex);
  template <class T>
  double decode(const std::byte* at) const {
    T value;
    std::memcpy(&value, at, sizeof value);
    if constexpr (sizeof(T) == 2) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap16(std::bit_cast<std::uint16_t>(value)));
    } else if constexpr (sizeof(T) == 4) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap32(std::bit_cast<std::uint32_t>(value)));
    } else if constexpr (sizeof(T) == 8) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap64(std::bit_cast<std::uint64_t>(value)));
    }
    return static_cast<double>(value);
  }
  double decodeNumber(const std::byte* at, PlyType type) const {
    switch (type) {
      case PlyType::kInt8:
        return decode<std::int8_t>(at);
      case PlyType::kUint8:
        return decode<std::uint8_t>(at);
      case PlyType::kInt16:
        return decode<std::int16_t>(at);
      case PlyType::kUint16:
        return decode<std::uint16_t>(at);
      case PlyType::kInt32:
        return decode<std::int32_t>(at);
      case PlyType::kUint32:
        return decode<std::uint32_t>(at);
      case PlyType::kFloat32:
        return decode<float>(at);
      case PlyType::kFloat64:
        return decode<double>(at);
    }
    return 0;
  }

  void readVertex(PlyBatch& batch);
  void readFace(PlyBatch& batch);
  void skipElement(const PlyElement& e);
  bool next(PlyBatch& batch);

  // --- triangle strips ------------------------------------------------------------------------

  // Where the strip being read stands. A strip can be longer than a batch (igea is one strip of
  // 268 K triangles), so this carries over from one batch to the next.
  struct Strip {
    bool open = false;           // its length is read, not all its indices yet
    std::uint64_t left = 0;      // indices still to read
    std::uint64_t run = 0;       // indices since the strip began or restarted
    std::uint32_t a = 0, b = 0;  // the last two indices of the run
  } strip;
  std::uint64_t stripTriangles = 0;  // delivered so far

  void readStrips(PlyBatch& batch);
  void beginStrip(const PlyElement& e);
  void readStripIndices(const PlyElement& e, PlyBatch& batch, std::size_t limit);
  void addStripIndex(double raw, PlyType type, std::uint64_t at, PlyBatch& batch);
  std::uint64_t countStripTriangles();
};

void PlyReader::State::parseHeader() {
  const std::string& name = source.name();
  auto at = [&](std::string_view what) { return badInputAtLine(name, lineNumber, what); };
  if (!source.readLine(line, kMaxHeaderLine) || line != "ply") {
    throw ErrorException{badInputAtByte(name, 0, "not a PLY file: expected the magic line 'ply'")};
  }
  lineNumber = 1;
  bool sawFormat = false;
  while (true) {
    if (source.offset() > kMaxHeaderBytes) throw ErrorException{at("header longer than 1 MiB")};
    if (!source.readLine(line, kMaxHeaderLine))
      throw ErrorException{at("file ends inside the header (no 'end_header')")};
    ++lineNumber;
    const std::vector<std::string_view> words = splitWords(line);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info") {
      header.comments.emplace_back(
          std::string_view(line).substr(std::min(line.size(), keyword.size() + 1)));
      continue;
    }
    if (keyword == "format") {
      if (words.size() != 3) throw ErrorException{at("expected 'format <type> 1.0'")};
      if (words[1] == "ascii")
        header.format = PlyFormat::kAscii;
      else if (words[1] == "binary_little_endian")
        header.format = PlyFormat::kBinaryLittleEndian;
      else if (words[1] == "binary_big_endian")
        header.format = PlyFormat::kBinaryBigEndian;
      else
        throw ErrorException{at(fmt::format("unknown format '{}'", words[1]))};
      if (words[2] != "1.0")
        throw ErrorException{at(fmt::format("unsupported version '{}'", words[2]))};
      sawFormat = true;
      continue;
    }
    if (keyword == "element") {
      if (words.size() != 3) throw ErrorException{at("expected 'element <name> <count>'")};
      PlyElement e;
      e.name = words[1];
      const auto [end, error] =
          std::from_chars(words[2].data(), words[2].data() + words[2].size(), e.count);
      if (error != std::errc() || end != words[2].data() + words[2].size())
        throw ErrorException{at(fmt::format("element count '{}' is not a whole number", words[2]))};
      header.elements.push_back(std::move(e));
      continue;
    }
    if (keyword == "property") {
      if (header.elements.empty()) throw ErrorException{at("property before any element")};
      PlyProperty p;
      if (words.size() == 5 && words[1] == "list") {
        const auto countType = parseType(words[2]);
        const auto itemType = parseType(words[3]);
        if (!countType || !itemType)
          throw ErrorException{at(fmt::format("unknown type in '{}'", line))};
        if (!isIntegral(*countType))
          throw ErrorException{at("list count type must be an integer type")};
        p.isList = true;
        p.countType = *countType;
        p.type = *itemType;
        p.name = words[4];
      } else if (words.size() == 3) {
        const auto type = parseType(words[1]);
        if (!type) throw ErrorException{at(fmt::format("unknown type '{}'", words[1]))};
        p.type = *type;
        p.name = words[2];
      } else {
        throw ErrorException{
            at("expected 'property <type> <name>' or 'property list <count type> "
               "<item type> <name>'")};
      }
      header.elements.back().properties.push_back(std::move(p));
      continue;
    }
    throw ErrorException{at(fmt::format("unknown header keyword '{}'", keyword.substr(0, 40)))};
  }
  if (!sawFormat) throw ErrorException{at("header has no 'format' line")};
  line.clear();  // the data starts on a fresh line
  linePos = 0;
  header.dataOffset = source.offset();
  swap = (header.format == PlyFormat::kBinaryBigEndian) ==
         (std::endian::native == std::endian::little);
  if (header.format == PlyFormat::kAscii) swap = false;
}

void PlyReader::State::assignRoles() {
  const std::string& name = source.name();
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
  if (options.readExtras) planExtras(v);
  header.doublePositions =
      v.properties[static_cast<std::size_t>(roles.x)].type == PlyType::kFloat64;
  if (header.vertexCount > std::numeric_limits<std::uint32_t>::max()) {
    throw ErrorException{badInput(name, fmt::format("{} vertices: lodforge indexes at most 2^32-1 "
                                                    "vertices per file",
                                                    header.vertexCount))};
  }
  if (roles.faceElement >= 0) {
    const PlyElement& f = header.elements[static_cast<std::size_t>(roles.faceElement)];
    roles.faceIndices = indexListRole(name, f);
    for (const std::string& candidate : options.objectIdProperties) {
      roles.objectId = findProperty(f, {candidate});
      if (roles.objectId >= 0 && !f.properties[static_cast<std::size_t>(roles.objectId)].isList)
        break;
      roles.objectId = -1;
    }
    header.faceCount = f.count;
    header.hasObjectIds = roles.objectId >= 0;
  }
  if (roles.stripElement >= 0) {
    const PlyElement& s = header.elements[static_cast<std::size_t>(roles.stripElement)];
    roles.stripIndices = indexListRole(name, s);
    header.stripCount = s.count;
    // Strips carry no object id: their triangles would belong to no object.
    if (header.hasObjectIds) {
      throw ErrorException{Error{
          ErrorKind::kUnsupported,
          fmt::format("{}: faces with object ids and 'tristrips' in one file are not supported",
                      name)}};
    }
  }
}

void PlyReader::State::checkCountsFitFile() {
  // Refuse before allocating anything: every element needs some minimum number of bytes, so a
  // header claiming 10^12 vertices in a small file is caught here. (Salvaging reads what is
  // there instead; readAll bounds its reservations by the file size.)
  if (options.salvageTruncated) return;
  const std::uint64_t available = source.size() - header.dataOffset;
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
          source.name(), header.dataOffset,
          fmt::format("header declares {} '{}' elements of at least {} bytes each, but only {} "
                      "bytes follow the header (room for {} at most): the file is truncated{}",
                      e.count, e.name, minBytes, available,
                      (available - std::min(available, needed)) / minBytes, kSalvageHint))};
    }
    needed += e.count * minBytes;
  }
}

void PlyReader::State::planRecord(const PlyElement& e) {
  recordElement = static_cast<int>(element);
  recordOffsets.clear();
  if (header.format == PlyFormat::kAscii) return;
  std::size_t offset = 0;
  for (const PlyProperty& p : e.properties) {
    if (p.isList) {
      recordOffsets.clear();
      return;
    }
    recordOffsets.push_back(offset);
    offset += plyTypeSize(p.type);
  }
  record.resize(offset);
}

// The vertex's scalar properties that are not a position, normal or colour, packed one after
// the other in their own types.
void PlyReader::State::planExtras(const PlyElement& vertex) {
  const std::array<int, 10> known = {roles.x,  roles.y,   roles.z,     roles.nx,   roles.ny,
                                     roles.nz, roles.red, roles.green, roles.blue, roles.alpha};
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const PlyProperty& p = vertex.properties[i];
    if (p.isList || std::find(known.begin(), known.end(), static_cast<int>(i)) != known.end())
      continue;
    ExtraField field;
    field.name = printableText(p.name);
    field.type = extraTypeOf(p.type);
    field.offset = header.extras.stride;
    header.extras.stride += static_cast<std::uint32_t>(extraTypeSize(field.type));
    header.extras.fields.push_back(std::move(field));
    roles.extras.push_back(static_cast<int>(i));
  }
}

void PlyReader::State::readVertex(PlyBatch& batch) {
  const PlyElement& e = header.elements[element];
  values.resize(e.properties.size());
  beginElement();
  if (recordElement != static_cast<int>(element)) planRecord(e);
  // Whole records while one fits in what is left (otherwise property by property, which says
  // where the file ends).
  if (!recordOffsets.empty() && source.remaining() >= record.size()) {
    if (!source.read(record.data(), record.size())) fail("cannot read a vertex record");
    for (std::size_t i = 0; i < e.properties.size(); ++i)
      values[i] = decodeNumber(record.data() + recordOffsets[i], e.properties[i].type);
  } else {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if (p.isList) {
        skipProperty(e, p);
        values[i] = 0;
      } else {
        values[i] = readNumber(e, p, p.type);
      }
    }
  }
  auto value = [&](int role) { return values[static_cast<std::size_t>(role)]; };
  const Vec3d position{value(roles.x), value(roles.y), value(roles.z)};
  if (!isFinite(position)) {
    fail(fmt::format("vertex {}: coordinate is not a finite number ({}, {}, {})", elementDone,
                     position.x, position.y, position.z));
  }
  batch.positions.push_back(position);
  if (header.hasNormals) {
    const Vec3f normal{static_cast<float>(value(roles.nx)), static_cast<float>(value(roles.ny)),
                       static_cast<float>(value(roles.nz))};
    if (!isFinite(normal)) fail(fmt::format("vertex {}: normal is not finite", elementDone));
    batch.normals.push_back(normal);
  }
  if (header.hasColors) {
    auto channel = [&](int role) -> std::uint8_t {
      if (role < 0) return 255;
      const double v = value(role);
      switch (e.properties[static_cast<std::size_t>(role)].type) {
        case PlyType::kUint8:
        case PlyType::kInt8:
          return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
        case PlyType::kUint16:
        case PlyType::kInt16:
          return static_cast<std::uint8_t>(std::clamp(v / 257.0, 0.0, 255.0));
        case PlyType::kFloat32:
        case PlyType::kFloat64:
          if (!std::isfinite(v)) fail(fmt::format("vertex {}: colour is not finite", elementDone));
          return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
        default:
          return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
      }
    };
    batch.colors.push_back(
        {channel(roles.red), channel(roles.green), channel(roles.blue), channel(roles.alpha)});
  }
  if (!roles.extras.empty()) {
    const std::size_t at = batch.extras.size();
    batch.extras.resize(at + header.extras.stride);
    for (std::size_t k = 0; k < roles.extras.size(); ++k) {
      const ExtraField& field = header.extras.fields[k];
      const double v = value(roles.extras[k]);
      const bool integer = field.type != ExtraType::kFloat32 && field.type != ExtraType::kFloat64;
      if (integer && !fitsExtraType(v, field.type))  // ascii text can say anything
        fail(fmt::format("vertex {}: {} does not fit property '{}' ({})", elementDone, v,
                         field.name, extraTypeName(field.type)));
      storeExtra(batch.extras.data() + at + field.offset, field.type, v);
    }
  }
}

void PlyReader::State::readFace(PlyBatch& batch) {
  const PlyElement& e = header.elements[element];
  beginElement();
  std::uint32_t objectId = 0;
  const std::size_t firstCorner = batch.triangles.size();
  faceFirstCorner = firstCorner;
  std::uint64_t corners = 0;
  std::uint32_t fanFirst = 0, fanPrevious = 0;
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const PlyProperty& p = e.properties[i];
    if (static_cast<int>(i) == roles.faceIndices) {
      corners = readListCount(e, p);
      if (corners > kMaxPolygon) fail(fmt::format("face {}: {} corners", elementDone, corners));
      // Binary corners in one read (readListCount made sure the file holds them).
      const bool whole = header.format != PlyFormat::kAscii;
      const std::size_t size = plyTypeSize(p.type);
      if (whole) {
        cornerBytes.resize(corners * size);
        if (!source.read(cornerBytes.data(), cornerBytes.size()))
          fail("cannot read a face's corners");
      }
      for (std::uint64_t k = 0; k < corners; ++k) {
        const double raw =
            whole ? decodeNumber(cornerBytes.data() + k * size, p.type) : readNumber(e, p, p.type);
        if (raw < 0 || raw >= static_cast<double>(header.vertexCount)) {
          fail(fmt::format("face {}: vertex index {} out of range (the file has {} vertices)",
                           elementDone, raw, header.vertexCount));
        }
        const auto index = static_cast<std::uint32_t>(raw);
        // Fan triangulation: (first, previous, current) for every corner after the second.
        if (k == 0) fanFirst = index;
        if (k >= 2) batch.triangles.insert(batch.triangles.end(), {fanFirst, fanPrevious, index});
        fanPrevious = index;
      }
    } else if (static_cast<int>(i) == roles.objectId) {
      const double raw = readNumber(e, p, p.type);
      if (raw < 0 || raw > std::numeric_limits<std::uint32_t>::max())
        fail(fmt::format("face {}: object id {} out of range", elementDone, raw));
      objectId = static_cast<std::uint32_t>(raw);
    } else {
      skipProperty(e, p);
    }
  }
  // Faces with fewer than 3 corners carry no area and yield no triangles.
  if (header.hasObjectIds) {
    const std::size_t triangles = (batch.triangles.size() - firstCorner) / 3;
    batch.triangleObjects.insert(batch.triangleObjects.end(), triangles, objectId);
  }
}

void PlyReader::State::skipElement(const PlyElement& e) {
  bool fixedSize = header.format != PlyFormat::kAscii;
  std::uint64_t size = 0;
  for (const PlyProperty& p : e.properties) {
    fixedSize = fixedSize && !p.isList;
    size += plyTypeSize(p.type);
  }
  if (fixedSize) {
    elementStart = source.offset();
    if (!source.skip((e.count - elementDone) * size))
      fileEnds(fmt::format("file ends inside the '{}' elements", e.name));
    elementDone = e.count;
    return;
  }
  for (; elementDone < e.count; ++elementDone) {
    beginElement();
    for (const PlyProperty& p : e.properties) skipProperty(e, p);
  }
}

// Strips deliver triangles: a batch holds about batchSize of them, from as many strips as that
// takes, and a strip longer than that goes on in the next batch.
void PlyReader::State::readStrips(PlyBatch& batch) {
  const PlyElement& e = header.elements[element];
  const std::size_t limit = 3 * std::max<std::size_t>(options.batchSize, 1);
  while (elementDone < e.count && batch.triangles.size() < limit) {
    if (!strip.open) beginStrip(e);
    readStripIndices(e, batch, limit);
    if (strip.left > 0) continue;
    // The properties after the index list, if any.
    for (std::size_t i = static_cast<std::size_t>(roles.stripIndices) + 1; i < e.properties.size();
         ++i)
      skipProperty(e, e.properties[i]);
    strip.open = false;
    ++elementDone;
  }
}

void PlyReader::State::beginStrip(const PlyElement& e) {
  beginElement();
  const auto list = static_cast<std::size_t>(roles.stripIndices);
  for (std::size_t i = 0; i < list; ++i) skipProperty(e, e.properties[i]);
  // Salvaging reads a strip up to where the file ends: its whole triangles are good.
  strip = {.open = true,
           .left = readListCount(e, e.properties[list], !options.salvageTruncated),
           .run = 0};
}

// Reads indices of the open strip until it ends or the batch holds `limit` corners.
void PlyReader::State::readStripIndices(const PlyElement& e, PlyBatch& batch, std::size_t limit) {
  const PlyProperty& p = e.properties[static_cast<std::size_t>(roles.stripIndices)];
  const std::size_t size = plyTypeSize(p.type);
  while (strip.left > 0 && batch.triangles.size() < limit) {
    if (header.format == PlyFormat::kAscii) {
      const double raw = readNumber(e, p, p.type);
      --strip.left;
      addStripIndex(raw, p.type, lineNumber, batch);
      continue;
    }
    // Binary: a run of indices in one read, no more than can fill the batch (each index adds a
    // triangle at most).
    const std::uint64_t room = (limit - batch.triangles.size() + 2) / 3;
    const std::uint64_t n = std::min({strip.left, kStripRun, room, source.remaining() / size});
    if (n == 0) {
      fileEnds(fmt::format("{} {}: file ends inside list '{}' ({} indices to go)", e.name,
                           elementDone, p.name, strip.left));
    }
    cornerBytes.resize(n * size);
    if (!source.read(cornerBytes.data(), cornerBytes.size())) fail("cannot read a strip's indices");
    const std::uint64_t start = source.offset() - n * size;
    for (std::uint64_t k = 0; k < n; ++k)
      addStripIndex(decodeNumber(cornerBytes.data() + k * size, p.type), p.type, start + k * size,
                    batch);
    strip.left -= n;
  }
}

// Triangle k of a run (since the strip began or restarted) is (i[k], i[k+1], i[k+2]), with the
// first two swapped for odd k so that all face the same way. Triangles with a repeated index
// are how strips join (and turn): they are dropped, but still count for k. `at` is the index's
// byte (binary) or line (ascii), for the error.
void PlyReader::State::addStripIndex(double raw, PlyType type, std::uint64_t at, PlyBatch& batch) {
  if (isStripRestart(raw, type, header.vertexCount)) {
    strip.run = 0;
    return;
  }
  if (raw < 0 || raw >= static_cast<double>(header.vertexCount)) {
    elementStart = at;
    fail(fmt::format("{} {}: vertex index {} out of range (the file has {} vertices)",
                     header.elements[element].name, elementDone, raw, header.vertexCount));
  }
  const auto c = static_cast<std::uint32_t>(raw);
  if (strip.run >= 2 && strip.a != strip.b && strip.b != c && strip.a != c) {
    if (strip.run % 2 == 0)
      batch.triangles.insert(batch.triangles.end(), {strip.a, strip.b, c});
    else
      batch.triangles.insert(batch.triangles.end(), {strip.b, strip.a, c});
  }
  strip.a = strip.b;
  strip.b = c;
  ++strip.run;
}

// A pass over the strips alone (the elements before them skipped, by seeking where they have a
// fixed size) that counts their triangles. Salvaging, it counts those before the cut.
std::uint64_t PlyReader::State::countStripTriangles() {
  PlyBatch batch;
  std::uint64_t triangles = 0;
  try {
    for (; element < static_cast<std::size_t>(roles.stripElement); ++element) {
      elementDone = 0;
      skipElement(header.elements[element]);
    }
    elementDone = 0;
    while (elementDone < header.elements[element].count) {
      batch.triangles.clear();
      readStrips(batch);
      triangles += batch.triangles.size() / 3;
    }
  } catch (const Truncated&) {
    triangles += batch.triangles.size() / 3;
  }
  return triangles;
}

bool PlyReader::State::next(PlyBatch& batch) {
  batch.positions.clear();
  batch.normals.clear();
  batch.colors.clear();
  batch.extras.clear();
  batch.triangles.clear();
  batch.triangleObjects.clear();
  batch.count = 0;
  bool reading = false, readingStrips = false;
  try {
    while (element < header.elements.size()) {
      const PlyElement& e = header.elements[element];
      const bool isVertex =
          static_cast<int>(element) == roles.vertexElement && options.readVertices;
      const bool isFace = static_cast<int>(element) == roles.faceElement && options.readFaces;
      const bool isStrip = static_cast<int>(element) == roles.stripElement && options.readFaces;
      if (elementDone == e.count || (!isVertex && !isFace && !isStrip)) {
        if (elementDone < e.count) skipElement(e);
        ++element;
        elementDone = 0;
        continue;
      }
      reading = true;
      if (isStrip) {
        // Numbered after the faces, so that faces and strips together count to faceCount.
        readingStrips = true;
        batch.kind = PlyBatch::Kind::kFaces;
        batch.first = stripTriangles;
        if (roles.faceElement >= 0)
          batch.first += header.elements[static_cast<std::size_t>(roles.faceElement)].count;
        readStrips(batch);
        batch.count = batch.triangles.size() / 3;
        stripTriangles += batch.count;
        if (batch.count > 0) return true;
        continue;  // the last strips were all degenerate
      }
      batch.kind = isVertex ? PlyBatch::Kind::kVertices : PlyBatch::Kind::kFaces;
      batch.first = elementDone;
      const std::uint64_t end = std::min<std::uint64_t>(e.count, elementDone + options.batchSize);
      for (; elementDone < end; ++elementDone) {
        if (isVertex)
          readVertex(batch);
        else
          readFace(batch);
      }
      batch.count = end - batch.first;
      return true;
    }
    return false;
  } catch (const Truncated&) {
    // Salvaging: keep the complete elements of this batch, drop the one cut short, and stop.
    element = header.elements.size();
    if (!reading) return false;
    if (readingStrips) {  // every triangle read so far is whole
      batch.count = batch.triangles.size() / 3;
      stripTriangles += batch.count;
      return batch.count > 0;
    }
    if (batch.kind == PlyBatch::Kind::kFaces) batch.triangles.resize(faceFirstCorner);
    batch.count = elementDone - batch.first;
    return batch.count > 0;
  }
}

// --- PlyReader --------------------------------------------------------------------------------

PlyReader::PlyReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
PlyReader::PlyReader(PlyReader&&) noexcept = default;
PlyReader& PlyReader::operator=(PlyReader&&) noexcept = default;
PlyReader::~PlyReader() = default;

std::uint64_t PlyReader::bytesAfterHeader() const {
  return state_->source.size() - state_->header.dataOffset;
}

Result<PlyReader> PlyReader::start(std::unique_ptr<State> state) {
  try {
    state->parseHeader();
    state->checkCountsFitFile();
    state->assignRoles();
    if (state->roles.stripElement >= 0) {
      // A second reader over the same bytes counts the strips' triangles; this one stays at the
      // start of the data.
      Result<ByteSource> source = state->memory
                                      ? ByteSource::fromMemory(*state->memory, state->source.name())
                                      : ByteSource::openFile(state->source.name());
      if (!source) return source.status();
      State counter(std::move(source.value()));
      counter.options = state->options;
      counter.parseHeader();
      counter.assignRoles();
      state->header.faceCount += counter.countStripTriangles();
    }
  } catch (const ErrorException& e) {
    return e.error;
  }
  return PlyReader(std::move(state));
}

Result<PlyReader> PlyReader::open(const std::string& path, const PlyReadOptions& options) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  auto state = std::make_unique<State>(std::move(source.value()));
  state->options = options;
  return start(std::move(state));
}

Result<PlyReader> PlyReader::fromMemory(std::span<const std::byte> bytes, std::string name,
                                        const PlyReadOptions& options) {
  auto state = std::make_unique<State>(ByteSource::fromMemory(bytes, std::move(name)));
  state->memory = bytes;
  state->options = options;
  return start(std::move(state));
}

const PlyHeader& PlyReader::header() const {
  return state_->header;
}

const std::optional<std::string>& PlyReader::truncation() const {
  return state_->truncation;
}

Result<bool> PlyReader::next(PlyBatch& batch) {
  try {
    return state_->next(batch);
  } catch (const ErrorException& e) {
    return e.error;
  }
}

// --- readPly ----------------------------------------------------------------------------------

namespace {

std::string stemOf(const std::string& name) {
  return std::filesystem::path(name).stem().string();
}

// Groups triangles by object id; each object gets its own copy of the vertices it uses, in
// ascending file order, so objects are self-contained (shared vertices are duplicated).
void splitByObject(Model& model, const std::vector<Vec3f>& positions,
                   const std::vector<Vec3f>& normals, const std::vector<Rgba8>& colors,
                   const std::vector<std::uint32_t>& triangles,
                   const std::vector<std::uint32_t>& triangleObjects) {
  const std::size_t triangleCount = triangleObjects.size();
  std::vector<std::uint32_t> order(triangleCount);
  for (std::uint32_t t = 0; t < triangleCount; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return triangleObjects[a] < triangleObjects[b];
  });
  std::vector<std::uint32_t> local(positions.size(), ~0u);
  std::vector<std::uint32_t> used;
  ModelBuilder builder(model);
  for (std::size_t begin = 0; begin < triangleCount;) {
    const std::uint32_t id = triangleObjects[order[begin]];
    std::size_t end = begin;
    while (end < triangleCount && triangleObjects[order[end]] == id) ++end;
    used.clear();
    for (std::size_t i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k)
        used.push_back(triangles[3 * order[i] + static_cast<std::size_t>(k)]);
    }
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    builder.beginObject(fmt::format("object {}", id));
    for (std::size_t i = 0; i < used.size(); ++i) {
      local[used[i]] = static_cast<std::uint32_t>(i);
      model.positions.push_back(positions[used[i]]);
      if (!normals.empty()) model.normals.push_back(normals[used[i]]);
      if (!colors.empty()) model.colors.push_back(colors[used[i]]);
    }
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t t = order[i];
      model.indices.insert(
          model.indices.end(),
          {local[triangles[3 * t]], local[triangles[3 * t + 1]], local[triangles[3 * t + 2]]});
    }
    builder.endObject();
    begin = end;
  }
}

Result<Model> readAll(PlyReader& reader, const std::string& name,
                      std::vector<std::string>* warnings) {
  const PlyHeader& header = reader.header();
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint32_t> triangleObjects;
  // Counts were checked against the file size, except when salvaging: bound them here too.
  const std::uint64_t dataBytes = reader.bytesAfterHeader();
  const std::uint64_t vertexGuess =
      std::min(header.vertexCount, dataBytes / 3 + 1);  // 3 x int8 at least
  positions.reserve(vertexGuess);
  if (header.hasNormals) normals.reserve(vertexGuess);
  if (header.hasColors) colors.reserve(vertexGuess);
  triangles.reserve(3 * std::min(header.faceCount, dataBytes / 4 + 1));

  Model model;
  bool originChosen = false;
  PlyBatch batch;
  Progress progress("reading " + std::filesystem::path(name).filename().string(),
                    header.vertexCount + header.faceCount);
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader.next(batch);
    if (!more) return more.status();
    if (!*more) break;
    if (batch.kind == PlyBatch::Kind::kVertices) {
      if (!originChosen && !batch.positions.empty()) {
        // Streaming cannot see the bounds first; the first vertex stands for them.
        Aabbd first;
        first.add(batch.positions.front());
        model.origin = chooseOrigin(first);
        originChosen = true;
      }
      for (const Vec3d& p : batch.positions) positions.push_back(toFloat(p - model.origin));
      normals.insert(normals.end(), batch.normals.begin(), batch.normals.end());
      colors.insert(colors.end(), batch.colors.begin(), batch.colors.end());
    } else {
      triangles.insert(triangles.end(), batch.triangles.begin(), batch.triangles.end());
      triangleObjects.insert(triangleObjects.end(), batch.triangleObjects.begin(),
                             batch.triangleObjects.end());
    }
    progress.advance(batch.count);
  }
  progress.finish();
  if (reader.truncation()) {
    if (warnings) warnings->push_back(*reader.truncation() + "; kept what came before");
    // Salvaged: faces that come before a cut-short vertex list may name missing vertices.
    std::size_t kept = 0;
    for (std::size_t t = 0; t < triangles.size() / 3; ++t) {
      if (std::max({triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]}) >=
          positions.size())
        continue;
      std::copy_n(&triangles[3 * t], 3, &triangles[3 * kept]);
      if (!triangleObjects.empty()) triangleObjects[kept] = triangleObjects[t];
      ++kept;
    }
    triangles.resize(3 * kept);
    if (!triangleObjects.empty()) triangleObjects.resize(kept);
  }
  if (header.hasObjectIds) {
    splitByObject(model, positions, normals, colors, triangles, triangleObjects);
    return model;
  }
  ModelBuilder builder(model);
  builder.beginObject(stemOf(name));
  model.positions = std::move(positions);
  model.normals = std::move(normals);
  model.colors = std::move(colors);
  model.indices = std::move(triangles);
  builder.endObject();
  return model;
}

}  // namespace

Result<Model> readPly(const std::string& path, const PlyReadOptions& options) {
  Result<PlyReader> reader = PlyReader::open(path, options);
  if (!reader) return reader.status();
  return readAll(*reader, path, options.warnings);
}

Result<Model> readPlyFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                const PlyReadOptions& options) {
  Result<PlyReader> reader = PlyReader::fromMemory(bytes, name, options);
  if (!reader) return reader.status();
  return readAll(*reader, name, options.warnings);
}

}  // namespace lodforge
