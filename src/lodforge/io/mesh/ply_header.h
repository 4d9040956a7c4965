// A PLY file's header: its format, its elements and their properties as the file declares them,
// and what lodforge reads from them (PlyHeader's counts and flags; PlyRoles, which property is
// x, nx or red, a face's indices, an object id). PlyReader (ply_reader.h) parses it first.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge {

enum class PlyFormat : std::uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
// The ExtraTypes (io/points/point_extras.h) PLY has, with their values, so that one table
// names and sizes both (PLY has no 64-bit integers).
enum class PlyType : std::uint8_t {
  kInt8 = static_cast<std::uint8_t>(ExtraType::kInt8),
  kUint8 = static_cast<std::uint8_t>(ExtraType::kUint8),
  kInt16 = static_cast<std::uint8_t>(ExtraType::kInt16),
  kUint16 = static_cast<std::uint8_t>(ExtraType::kUint16),
  kInt32 = static_cast<std::uint8_t>(ExtraType::kInt32),
  kUint32 = static_cast<std::uint8_t>(ExtraType::kUint32),
  kFloat32 = static_cast<std::uint8_t>(ExtraType::kFloat32),
  kFloat64 = static_cast<std::uint8_t>(ExtraType::kFloat64)
};
constexpr ExtraType extraTypeOf(PlyType type) {
  return static_cast<ExtraType>(type);
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type for lists
  bool isList = false;
  PlyType countType = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;
  std::uint64_t dataOffset = 0;  // byte where element data starts

  // What lodforge reads from it.
  std::uint64_t vertexCount = 0;
  // Faces, plus the triangles the strips make (0: no faces, a point cloud). Only reading strips
  // tells how many triangles they make (restarts, degenerate joins), so opening a file with
  // strips reads them once to count.
  std::uint64_t faceCount = 0;
  std::uint64_t stripCount = 0;  // strips in the 'tristrips' element
  bool hasNormals = false;
  bool hasColors = false;
  bool hasObjectIds = false;
  // Texture coordinates per vertex (s t, u v, texture_u texture_v) or per face corner (a
  // 'texcoord' list, 2 per corner), the face's texture (a 'texnumber' into textureFiles), and
  // the images MeshLab and OpenDroneMap name in "comment TextureFile NAME" lines, in order.
  bool hasUvs = false;
  bool hasFaceUvs = false;
  bool hasTextureNumbers = false;
  std::vector<std::string> textureFiles;
  bool doublePositions = false;  // x y z stored as double: keep the double origin
  bool floatPositions = false;   // x y z all stored as float: floats hold them exactly
  // The vertex's other scalar properties (label, segment_index, …), with readExtras.
  PointExtras extras;
};

std::string_view plyTypeName(PlyType type);  // PLY's own: "uchar", "float", …
std::size_t plyTypeSize(PlyType type);
std::string_view plyFormatName(PlyFormat format);
bool plyTypeIsIntegral(PlyType type);

// --- for PlyReader (ply_reader.cpp): bad input throws ErrorException -------------------------

// What a user whose file was cut short can do (every command that reads PLY takes it).
inline constexpr std::string_view kPlySalvageHint =
    "; --salvage reads the complete elements before the cut";

// Where each property lodforge understands sits in its element; -1 when absent.
struct PlyRoles {
  int vertexElement = -1, faceElement = -1;
  int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1;
  int red = -1, green = -1, blue = -1, alpha = -1;
  int faceIndices = -1, objectId = -1;
  int u = -1, v = -1;                        // vertex texture coordinates
  int faceTexcoords = -1, texnumber = -1;    // per-face corner coordinates, texture index
  int stripElement = -1, stripIndices = -1;  // 'tristrips' and its index list
  std::vector<int> extras;                   // vertex properties carried as extra fields
};

// The header from the start of `source`, which is left at the first byte of the data;
// `lineNumber` is then the header's last line (ascii data goes on counting from it).
PlyHeader parsePlyHeader(ByteSource& source, std::uint64_t& lineNumber);

// Refuses a header whose element counts cannot fit in the `fileSize` bytes, before anything is
// allocated.
void checkPlyCountsFitFile(const PlyHeader& header, std::uint64_t fileSize,
                           const std::string& name);

// Elements other than vertex, face and tristrips (edges, materials, a tool's own) are not read:
// a warning naming them with their counts ("x.ply: element not read: 'edge' (12)"), or nothing.
std::optional<std::string> unreadPlyElements(const PlyHeader& header, const std::string& name);

// Which property is what. Fills the header's counts and flags, and with `readExtras` its extras
// (the vertex's other scalar properties); a face's object id is the first scalar property named
// in `objectIdProperties`.
PlyRoles assignPlyRoles(PlyHeader& header, const std::string& name, bool readExtras,
                        std::span<const std::string> objectIdProperties);

}  // namespace lodforge
