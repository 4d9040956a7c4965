#include "lodforge/io/points/laz/laz_vlr.h"

#include <cstring>

#include <fmt/format.h>

#include "lodforge/core/units.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

constexpr std::size_t kFixedBytes = 34;  // everything before the items
constexpr std::size_t kItemBytes = 6;

const char* compressorName(LazCompressor compressor) {
  switch (compressor) {
    case LazCompressor::kNone:
      return "none";
    case LazCompressor::kPointwise:
      return "point-wise";
    case LazCompressor::kPointwiseChunked:
      return "point-wise chunked";
    case LazCompressor::kLayeredChunked:
      return "layered chunked";
  }
  return "unknown";
}

}  // namespace

std::uint32_t LazInfo::recordBytes() const {
  std::uint32_t bytes = 0;
  for (const LazItem& item : items) bytes += item.size;
  return bytes;
}

std::string lazItemName(std::uint16_t type) {
  static constexpr const char* kNames[] = {"BYTE",     "SHORT",        "INT",     "LONG",
                                           "FLOAT",    "DOUBLE",       "POINT10", "GPSTIME11",
                                           "RGB12",    "WAVEPACKET13", "POINT14", "RGB14",
                                           "RGBNIR14", "WAVEPACKET14", "BYTE14"};
  if (type < std::size(kNames)) return kNames[type];
  return fmt::format("item type {}", type);
}

Result<LazInfo> parseLazVlr(std::span<const std::byte> data, const std::string& file,
                            std::uint64_t at) {
  const auto bad = [&](std::uint64_t offset, std::string_view what) -> Error {
    return badInputAtByte(file, at + offset, fmt::format("LASzip record: {}", what));
  };
  if (data.size() < kFixedBytes)
    return bad(
        0, fmt::format("{} bytes, fewer than the {} its fields take", data.size(), kFixedBytes));
  LazInfo laz;
  const std::uint16_t compressor = loadField<std::uint16_t>(data.data());
  if (compressor > 3) return bad(0, fmt::format("unknown compressor {}", compressor));
  laz.compressor = static_cast<LazCompressor>(compressor);
  laz.coder = loadField<std::uint16_t>(data.data() + 2);
  if (laz.coder != 0)
    return bad(2, fmt::format("unknown coder {} (0, arithmetic, is defined)", laz.coder));
  laz.versionMajor = static_cast<std::uint8_t>(data[4]);
  laz.versionMinor = static_cast<std::uint8_t>(data[5]);
  laz.versionRevision = loadField<std::uint16_t>(data.data() + 6);
  laz.options = loadField<std::uint32_t>(data.data() + 8);
  laz.chunkSize = loadField<std::uint32_t>(data.data() + 12);
  laz.specialEvlrCount = loadField<std::int64_t>(data.data() + 16);
  laz.specialEvlrOffset = loadField<std::int64_t>(data.data() + 24);
  const std::uint16_t count = loadField<std::uint16_t>(data.data() + 32);
  if (data.size() != kFixedBytes + kItemBytes * count)
    return bad(32, fmt::format("{} items need {} bytes, the record has {}", count,
                               kFixedBytes + kItemBytes * count, data.size()));
  if (count == 0) return bad(32, "no items");
  for (std::uint16_t i = 0; i < count; ++i) {
    const std::byte* item = data.data() + kFixedBytes + kItemBytes * i;
    LazItem entry{loadField<std::uint16_t>(item), loadField<std::uint16_t>(item + 2),
                  loadField<std::uint16_t>(item + 4)};
    if (entry.type > 14 || (entry.type >= 1 && entry.type <= 5))
      return bad(kFixedBytes + kItemBytes * i, fmt::format("unknown item type {}", entry.type));
    laz.items.push_back(entry);
  }
  return laz;
}

std::string describeLaz(const LazInfo& laz) {
  std::string chunks;
  if (laz.compressor == LazCompressor::kPointwiseChunked ||
      laz.compressor == LazCompressor::kLayeredChunked)
    chunks = laz.chunkSize == kLazVariableChunks
                 ? " (variable chunks)"
                 : fmt::format(" ({} points per chunk)", formatCount(laz.chunkSize));
  std::string items;
  for (const LazItem& item : laz.items) {
    if (!items.empty()) items += ", ";
    items += fmt::format("{} v{}", lazItemName(item.type), item.version);
    if (item.type == 0 || item.type == 14) items += fmt::format(" ({} bytes)", item.size);
  }
  return fmt::format("{}{}, LASzip {}.{}r{}; items {}", compressorName(laz.compressor), chunks,
                     laz.versionMajor, laz.versionMinor, laz.versionRevision, items);
}

}  // namespace lodforge
