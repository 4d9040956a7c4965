// A point's fields beyond the ones every stage knows (position, normal, colour, the LAS
// attributes): a LAS file's extra bytes, as its Extra Bytes record describes them (LAS 1.4 R15,
// §2.6, record 4 of "LASF_Spec"), or a PLY vertex's other scalar properties. Each point carries
// them as `stride` raw little-endian bytes; the fields say what lies where.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/status.h"

namespace lodforge {

enum class ExtraType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64
};
// From one table of every scalar type, for LAS extra bytes and PLY properties alike.
std::size_t extraTypeSize(ExtraType type);
const char* extraTypeName(ExtraType type);  // "uint16", …
// PLY's own name for the type ("ushort" for kUint16, …); empty for the 64-bit integers, which
// PLY has not.
std::string_view extraTypePlyName(ExtraType type);

struct ExtraField {
  std::string name;  // as the file names it
  std::string description;
  ExtraType type = ExtraType::kUint8;
  std::uint32_t offset = 0;      // within a point's extra bytes
  double scale = 1, add = 0;     // value = raw · scale + add
  std::optional<double> noData;  // raw value that means "none" (one the type can hold)
  bool scaled() const { return scale != 1 || add != 0; }
};

struct PointExtras {
  std::vector<ExtraField> fields;
  std::uint32_t stride = 0;  // bytes a point carries (0: none)
};

// Whether `v` is a value of `type` (whole and in range for the integers; finite for floats).
bool fitsExtraType(double v, ExtraType type);

// A file's text made safe to name a field by (bytes outside printable ASCII become '?').
std::string printableText(std::string text);

// A field's raw value of the point whose extra bytes start at `point`.
double extraRaw(const std::byte* point, const ExtraField& field);
// Its value: raw · scale + add.
inline double extraValue(const std::byte* point, const ExtraField& field) {
  return extraRaw(point, field) * field.scale + field.add;
}

// One Extra Bytes record's data (a VLR's or an EVLR's) and the byte of the file it starts at.
struct LasExtraRecord {
  std::span<const std::byte> data;
  std::uint64_t at = 0;
};

// The fields of a LAS file's Extra Bytes records (192-byte descriptors) over the `available`
// bytes each point record has past its point format's. A file may describe its extra bytes in
// several records (PDAL writes one per dimension): their descriptors, in file order, make up
// the layout. Undocumented bytes (type 0) are skipped over, LAS 1.3's two- and three-element
// types become a field per element ("name[1]"); bad input names the file, the byte of the
// record and the descriptor.
Result<PointExtras> parseLasExtraBytes(std::span<const LasExtraRecord> records,
                                       std::uint32_t available, const std::string& file);
// One record, starting at byte `at` of the file.
Result<PointExtras> parseLasExtraBytes(std::span<const std::byte> record, std::uint32_t available,
                                       const std::string& file, std::uint64_t at);

// One 192-byte descriptor, for writers and tests.
std::vector<std::byte> lasExtraBytesDescriptor(const ExtraField& field);

}  // namespace lodforge
