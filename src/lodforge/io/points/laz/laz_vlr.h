// The LASzip record of a LAZ file (user "laszip encoded", record 22204): which compressor and
// coder wrote the point data, the items each point record is made of (type, size, version) and
// the chunking. Read from the LAZ specification's layout: compressor u16, coder u16, version
// u8.u8.u16, options u32, chunk size u32 (0xFFFFFFFF: variable), special EVLR count and offset
// i64, item count u16, then per item type u16, size u16, version u16.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/status.h"

namespace lodforge {

inline constexpr std::uint16_t kLazRecordId = 22204;
inline constexpr std::uint32_t kLazVariableChunks = 0xFFFFFFFFu;

enum class LazCompressor : std::uint16_t {
  kNone = 0,
  kPointwise = 1,
  kPointwiseChunked = 2,
  kLayeredChunked = 3
};

struct LazItem {
  std::uint16_t type = 0;  // 0 BYTE, 6 POINT10, 7 GPSTIME11, 8 RGB12, 9 WAVEPACKET13, 10 POINT14,
                           // 11 RGB14, 12 RGBNIR14, 13 WAVEPACKET14, 14 BYTE14
  std::uint16_t size = 0;  // bytes of the point record it covers
  std::uint16_t version = 0;
};

struct LazInfo {
  LazCompressor compressor = LazCompressor::kNone;
  std::uint16_t coder = 0;  // 0: arithmetic, the only one defined
  std::uint8_t versionMajor = 0, versionMinor = 0;
  std::uint16_t versionRevision = 0;
  std::uint32_t options = 0;
  std::uint32_t chunkSize = 0;  // points per chunk, or kLazVariableChunks
  std::int64_t specialEvlrCount = -1, specialEvlrOffset = -1;
  std::vector<LazItem> items;

  std::uint32_t recordBytes() const;  // the sum of the items' sizes
};

// The record's data as found at byte `at` of `file` (for messages); bad input when it is not the
// layout above or names an unknown compressor, coder or item.
Result<LazInfo> parseLazVlr(std::span<const std::byte> data, const std::string& file,
                            std::uint64_t at);

std::string lazItemName(std::uint16_t type);
// "point-wise chunked (50,000 points per chunk), arithmetic; items POINT10 v2, GPSTIME11 v2"
std::string describeLaz(const LazInfo& laz);

}  // namespace lodforge
