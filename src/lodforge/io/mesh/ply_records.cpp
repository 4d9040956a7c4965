#include "lodforge/io/mesh/ply_records.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace lodforge {

namespace {

// An ascii element is one line, and a triangle strip is one element: 300 K six-digit indices
// take 2 MB. The bound keeps a file without line breaks from growing the line without end.
constexpr std::size_t kMaxAsciiLine = std::size_t{64} << 20;
constexpr std::uint64_t kMaxPolygon = 1 << 20;  // corners in one face; more is not a mesh

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

}  // namespace

void PlyRecords::readHeader(bool checkCounts) {
  header = parsePlyHeader(source, lineNumber);
  swap = header.format != PlyFormat::kAscii && (header.format == PlyFormat::kBinaryBigEndian) ==
                                                   (std::endian::native == std::endian::little);
  // Refused before allocating anything. (Salvaging reads what is there instead; readPly bounds
  // its reservations by the file size.)
  if (checkCounts && !options.salvageTruncated)
    checkPlyCountsFitFile(header, source.size(), source.name());
  roles = assignPlyRoles(header, source.name(), options.readExtras, options.objectIdProperties);
}

Error PlyRecords::positioned(std::string_view what) const {
  if (header.format == PlyFormat::kAscii) return badInputAtLine(source.name(), elementStart, what);
  return badInputAtByte(source.name(), elementStart, what);
}

void PlyRecords::fileEnds(std::string_view what) {
  if (!options.salvageTruncated) fail(fmt::format("{}{}", what, kPlySalvageHint));
  truncation = positioned(what).message;
  throw Truncated{};
}

std::string_view PlyRecords::nextToken(const PlyElement& e) {
  while (true) {
    while (linePos < line.size() && (line[linePos] == ' ' || line[linePos] == '\t')) ++linePos;
    if (linePos < line.size()) break;
    if (!source.readLine(line, kMaxAsciiLine)) {
      fileEnds(fmt::format("{} {}: file ends before the element is complete", e.name, elementDone));
    }
    ++lineNumber;
    linePos = 0;
  }
  const std::size_t start = linePos;
  while (linePos < line.size() && line[linePos] != ' ' && line[linePos] != '\t') ++linePos;
  return std::string_view(line).substr(start, linePos - start);
}

double PlyRecords::readNumber(const PlyElement& e, const PlyProperty& p, PlyType type) {
  if (header.format == PlyFormat::kAscii) {
    const std::string_view token = nextToken(e);
    double value = 0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size()) {
      fail(fmt::format("{} {}: expected a number for '{}', found '{}'", e.name, elementDone, p.name,
                       token.substr(0, 40)));
    }
    if (plyTypeIsIntegral(type) && value != std::floor(value)) {
      fail(fmt::format("{} {}: expected an integer for '{}', found '{}'", e.name, elementDone,
                       p.name, token.substr(0, 40)));
    }
    return value;
  }
  std::byte bytes[8];
  if (!source.read(bytes, plyTypeSize(type))) {
    fileEnds(fmt::format("{} {}: file ends inside property '{}' ({} of {} '{}' elements complete)",
                         e.name, elementDone, p.name, elementDone, e.count, e.name));
  }
  return decodeNumber(bytes, type);
}

std::uint64_t PlyRecords::readListCount(const PlyElement& e, const PlyProperty& p, bool mustFit) {
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

void PlyRecords::skipProperty(const PlyElement& e, const PlyProperty& p) {
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

void PlyRecords::beginElement() {
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

void PlyRecords::planRecord(const PlyElement& e) {
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

void PlyRecords::readVertex(PlyBatch& batch) {
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
  if (header.hasUvs) {
    const double u = value(roles.u), v = 1.0 - value(roles.v);
    // (Checked in double: a float cast of a value beyond its range is undefined.)
    if (!(std::abs(u) < 1e30 && std::abs(v) < 1e30))
      fail(fmt::format("vertex {}: texture coordinate is not a finite number", elementDone));
    batch.uvs.push_back({static_cast<float>(u), static_cast<float>(v)});
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

void PlyRecords::readFace(PlyBatch& batch) {
  const PlyElement& e = header.elements[element];
  beginElement();
  std::uint32_t objectId = 0, texture = 0;
  faceUvs.clear();
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
      if (!(raw >= 0 && raw <= std::numeric_limits<std::uint32_t>::max()))  // NaN too
        fail(fmt::format("face {}: object id {} out of range", elementDone, raw));
      objectId = static_cast<std::uint32_t>(raw);
    } else if (static_cast<int>(i) == roles.faceTexcoords) {
      readFaceTexcoords(e, p);
    } else if (static_cast<int>(i) == roles.texnumber) {
      // -1: a face of no texture (MeshLab's way).
      const double raw = readNumber(e, p, p.type);
      if (!(raw >= -1 && raw < std::numeric_limits<std::uint32_t>::max()))  // NaN too
        fail(fmt::format("face {}: texnumber {} out of range", elementDone, raw));
      texture = raw < 0 ? ~0u : static_cast<std::uint32_t>(raw);
    } else {
      skipProperty(e, p);
    }
  }
  // Faces with fewer than 3 corners carry no area and yield no triangles.
  const std::size_t triangles = (batch.triangles.size() - firstCorner) / 3;
  if (header.hasObjectIds)
    batch.triangleObjects.insert(batch.triangleObjects.end(), triangles, objectId);
  if (header.hasTextureNumbers)
    batch.triangleTextures.insert(batch.triangleTextures.end(), triangles, texture);
  if (header.hasFaceUvs) addCornerUvs(batch, corners, triangles);
}

// A face's 'texcoord' list: 2 numbers per corner (checked against the corners once both are
// read, in addCornerUvs).
void PlyRecords::readFaceTexcoords(const PlyElement& e, const PlyProperty& p) {
  const std::uint64_t count = readListCount(e, p);
  if (count > 2 * kMaxPolygon)
    fail(fmt::format("face {}: {} texture coordinates", elementDone, count));
  for (std::uint64_t k = 0; k < count; ++k) {
    const double x = readNumber(e, p, p.type);
    if (!(std::abs(x) < 1e30))  // NaN and values past a float's range too
      fail(fmt::format("face {}: texture coordinate is not a finite number", elementDone));
    faceUvs.push_back(static_cast<float>(k % 2 == 0 ? x : 1.0 - x));
  }
}

// The face's corner coordinates fanned as its triangles are.
void PlyRecords::addCornerUvs(PlyBatch& batch, std::uint64_t corners, std::size_t triangles) {
  if (faceUvs.size() != 2 * corners)
    fail(fmt::format("face {}: {} texture coordinates for {} corners (2 each)", elementDone,
                     faceUvs.size(), corners));
  const auto uv = [&](std::size_t k) { return Vec2f{faceUvs[2 * k], faceUvs[2 * k + 1]}; };
  for (std::size_t t = 0; t < triangles; ++t)
    batch.cornerUvs.insert(batch.cornerUvs.end(), {uv(0), uv(t + 1), uv(t + 2)});
}

void PlyRecords::skipElement(const PlyElement& e) {
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

namespace {

[[noreturn]] void unsliceable(const std::string& name, std::string_view why) {
  throw ErrorException{
      Error{ErrorKind::kUnsupported,
            fmt::format("{}: cannot read a slice of its elements: {}", name, why)}};
}

}  // namespace

void PlyRecords::enterSlice(const PlyElement& e, const PlySlice& slice, bool faces) {
  if (header.format == PlyFormat::kAscii) unsliceable(source.name(), "an ascii file");
  if (faces && roles.stripElement >= 0) unsliceable(source.name(), "triangle strips");
  sliceElement = static_cast<int>(element);
  const std::uint64_t first = std::min(slice.first, e.count);
  sliceEnd = first + std::min(slice.count, e.count - first);
  std::uint64_t bytes = 0;
  if (!faces) {
    planRecord(e);
    if (recordOffsets.empty()) unsliceable(source.name(), "vertices with a list property");
    bytes = record.size();
  } else {
    // The first face's size, read without consuming it: every face is taken to have it.
    for (const PlyProperty& p : e.properties) {
      if (source.ensure(bytes + 8) < bytes + plyTypeSize(p.isList ? p.countType : p.type))
        fileEnds(fmt::format("file ends inside the first '{}' element", e.name));
      if (!p.isList) {
        bytes += plyTypeSize(p.type);
        continue;
      }
      const auto count =
          static_cast<std::uint64_t>(decodeNumber(source.data() + bytes, p.countType));
      bytes += plyTypeSize(p.countType) + count * plyTypeSize(p.type);
    }
    sliceFaceBytes = bytes;
  }
  if (first > 0 && !source.skip(first * bytes))
    fileEnds(fmt::format("file ends before '{}' element {}", e.name, first));
  elementDone = first;
}

void PlyRecords::checkSliceFace(std::uint64_t began) const {
  if (source.offset() - began != sliceFaceBytes)
    unsliceable(source.name(),
                fmt::format("face {} takes {} bytes, the first face {}: faces of different sizes "
                            "are found only by reading every one before them",
                            elementDone, source.offset() - began, sliceFaceBytes));
}

}  // namespace lodforge
