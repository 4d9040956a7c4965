#include "lodforge/io/points/point_extras.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "lodforge/io/points/las_format.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

// The Extra Bytes descriptor (LAS 1.4 R15, Table 24): where each field lies in its 192 bytes.
using las::kExtraDescriptor;
constexpr std::size_t kTypeAt = 2, kOptionsAt = 3, kNameAt = 4, kNoDataAt = 40, kScaleAt = 112,
                      kOffsetAt = 136, kDescriptionAt = 160;
constexpr std::uint8_t kHasNoData = 1, kHasScale = 8, kHasOffset = 16;

// Data types 1–10 in LAS order; 11–20 and 21–30 are two- and three-element arrays of them.
constexpr std::array<ExtraType, 10> kLasTypes = {
    ExtraType::kUint8,   ExtraType::kInt8,   ExtraType::kUint16, ExtraType::kInt16,
    ExtraType::kUint32,  ExtraType::kInt32,  ExtraType::kUint64, ExtraType::kInt64,
    ExtraType::kFloat32, ExtraType::kFloat64};

// Every scalar type's names and size, in ExtraType order.
struct TypeRow {
  const char* name;
  std::string_view plyName;
  std::size_t size;
};
constexpr std::array<TypeRow, 10> kTypes = {{{"int8", "char", 1},
                                             {"uint8", "uchar", 1},
                                             {"int16", "short", 2},
                                             {"uint16", "ushort", 2},
                                             {"int32", "int", 4},
                                             {"uint32", "uint", 4},
                                             {"int64", "", 8},
                                             {"uint64", "", 8},
                                             {"float32", "float", 4},
                                             {"float64", "double", 8}}};

bool isFloat(ExtraType type) {
  return type == ExtraType::kFloat32 || type == ExtraType::kFloat64;
}
bool isSigned(ExtraType type) {
  return type == ExtraType::kInt8 || type == ExtraType::kInt16 || type == ExtraType::kInt32 ||
         type == ExtraType::kInt64;
}

// An "anytype" slot: 8 bytes read as the field's widest kind (LAS's no_data, min and max).
double anyValue(const std::byte* at, ExtraType type) {
  if (isFloat(type)) return loadField<double>(at);
  if (isSigned(type)) return static_cast<double>(loadField<std::int64_t>(at));
  return static_cast<double>(loadField<std::uint64_t>(at));
}

}  // namespace

std::size_t extraTypeSize(ExtraType type) {
  return kTypes[static_cast<std::size_t>(type)].size;
}

const char* extraTypeName(ExtraType type) {
  return kTypes[static_cast<std::size_t>(type)].name;
}

std::string_view extraTypePlyName(ExtraType type) {
  return kTypes[static_cast<std::size_t>(type)].plyName;
}

bool fitsExtraType(double v, ExtraType type) {
  if (!std::isfinite(v)) return false;
  if (isFloat(type)) return type == ExtraType::kFloat64 || std::isfinite(static_cast<float>(v));
  if (v != std::floor(v)) return false;
  const std::size_t bits = 8 * extraTypeSize(type);
  const double top = std::ldexp(1.0, static_cast<int>(isSigned(type) ? bits - 1 : bits));
  return isSigned(type) ? v >= -top && v < top : v >= 0 && v < top;
}

std::string printableText(std::string text) {
  for (char& c : text)
    if (c < 0x20 || c > 0x7E) c = '?';
  return text;
}

double extraRaw(const std::byte* point, const ExtraField& field) {
  const std::byte* at = point + field.offset;
  switch (field.type) {
    case ExtraType::kInt8:
      return loadField<std::int8_t>(at);
    case ExtraType::kUint8:
      return loadField<std::uint8_t>(at);
    case ExtraType::kInt16:
      return loadField<std::int16_t>(at);
    case ExtraType::kUint16:
      return loadField<std::uint16_t>(at);
    case ExtraType::kInt32:
      return loadField<std::int32_t>(at);
    case ExtraType::kUint32:
      return loadField<std::uint32_t>(at);
    case ExtraType::kInt64:
      return static_cast<double>(loadField<std::int64_t>(at));
    case ExtraType::kUint64:
      return static_cast<double>(loadField<std::uint64_t>(at));
    case ExtraType::kFloat32:
      return loadField<float>(at);
    case ExtraType::kFloat64:
      return loadField<double>(at);
  }
  return 0;
}

namespace {

// One descriptor `e` (at byte `where` of the file): its fields from byte `offset` of a point's
// extra bytes on, appended to `extras`; `offset` moves past them.
Status takeDescriptor(const std::byte* e, std::uint64_t where, std::uint32_t& offset,
                      std::uint32_t available, const std::string& file, PointExtras& extras) {
  const auto dataType = static_cast<std::size_t>(e[kTypeAt]);
  const auto options = static_cast<std::uint8_t>(e[kOptionsAt]);
  const std::string name = printableText(loadText(e + kNameAt, 32));
  if (dataType > 30)
    return badInputAtByte(
        file, where + kTypeAt,
        fmt::format("extra bytes \"{}\": data type {} is not one of 0 to 30", name, dataType));
  // Undocumented bytes: `options` says how many; they are carried but not named.
  const ExtraType base = kLasTypes[dataType == 0 ? 0 : (dataType - 1) % 10];
  const std::size_t elements = dataType == 0 ? 0 : 1 + (dataType - 1) / 10;
  const std::uint32_t bytes = dataType == 0
                                  ? std::uint32_t{options}
                                  : static_cast<std::uint32_t>(elements * extraTypeSize(base));
  if (offset + bytes > available)
    return badInputAtByte(file, where,
                          fmt::format("extra bytes \"{}\" end at byte {} of a point's extra "
                                      "bytes, but the records have {}",
                                      name, offset + bytes, available));
  for (std::size_t k = 0; k < elements; ++k) {
    ExtraField field;
    field.name = elements == 1 ? name : fmt::format("{}[{}]", name, k);
    field.description = printableText(loadText(e + kDescriptionAt, 32));
    field.type = base;
    field.offset = offset + static_cast<std::uint32_t>(k * extraTypeSize(base));
    if ((options & kHasScale) != 0) field.scale = loadField<double>(e + kScaleAt + 8 * k);
    if ((options & kHasOffset) != 0) field.add = loadField<double>(e + kOffsetAt + 8 * k);
    // A no-data value the type cannot hold matches no point: dropped. A float's is taken as
    // the float it would be stored as, so that it matches.
    if ((options & kHasNoData) != 0) {
      const double noData = anyValue(e + kNoDataAt + 8 * k, base);
      if (fitsExtraType(noData, base))
        field.noData = base == ExtraType::kFloat32 ? static_cast<float>(noData) : noData;
    }
    if (!std::isfinite(field.scale) || field.scale == 0 || !std::isfinite(field.add))
      return badInputAtByte(file, where + kScaleAt,
                            fmt::format("extra bytes \"{}\": scale {} and offset {} are not "
                                        "finite (a zero scale neither)",
                                        field.name, field.scale, field.add));
    extras.fields.push_back(std::move(field));
  }
  offset += bytes;
  return {};
}

}  // namespace

Result<PointExtras> parseLasExtraBytes(std::span<const LasExtraRecord> records,
                                       std::uint32_t available, const std::string& file) {
  PointExtras extras;
  extras.stride = available;
  std::uint32_t offset = 0;  // where the next descriptor's bytes start in a point's extra bytes
  for (const LasExtraRecord& record : records) {
    if (record.data.size() % kExtraDescriptor != 0)
      return badInputAtByte(file, record.at,
                            fmt::format("the Extra Bytes record holds {} bytes, not a whole "
                                        "number of {}-byte descriptors",
                                        record.data.size(), kExtraDescriptor));
    for (std::size_t d = 0; d < record.data.size() / kExtraDescriptor; ++d)
      LODFORGE_TRY(takeDescriptor(record.data.data() + d * kExtraDescriptor,
                                  record.at + d * kExtraDescriptor, offset, available, file,
                                  extras));
  }
  return extras;
}

Result<PointExtras> parseLasExtraBytes(std::span<const std::byte> record, std::uint32_t available,
                                       const std::string& file, std::uint64_t at) {
  const LasExtraRecord one{record, at};
  return parseLasExtraBytes(std::span(&one, 1), available, file);
}

std::vector<std::byte> lasExtraBytesDescriptor(const ExtraField& field) {
  std::vector<std::byte> d(kExtraDescriptor);
  std::size_t type = 0;
  while (kLasTypes[type] != field.type) ++type;
  d[kTypeAt] = static_cast<std::byte>(type + 1);
  std::uint8_t options = 0;
  if (field.scale != 1) options |= kHasScale;
  if (field.add != 0) options |= kHasOffset;
  if (field.noData) {
    options |= kHasNoData;
    if (isFloat(field.type)) {
      std::memcpy(d.data() + kNoDataAt, &*field.noData, 8);
    } else if (isSigned(field.type)) {
      const auto v = static_cast<std::int64_t>(*field.noData);
      std::memcpy(d.data() + kNoDataAt, &v, 8);
    } else {
      const auto v = static_cast<std::uint64_t>(*field.noData);
      std::memcpy(d.data() + kNoDataAt, &v, 8);
    }
  }
  d[kOptionsAt] = static_cast<std::byte>(options);
  std::memcpy(d.data() + kNameAt, field.name.data(), std::min<std::size_t>(field.name.size(), 32));
  std::memcpy(d.data() + kScaleAt, &field.scale, 8);
  std::memcpy(d.data() + kOffsetAt, &field.add, 8);
  std::memcpy(d.data() + kDescriptionAt, field.description.data(),
              std::min<std::size_t>(field.description.size(), 32));
  return d;
}

}  // namespace lodforge
