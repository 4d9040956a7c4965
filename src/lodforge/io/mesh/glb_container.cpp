#include "lodforge/io/mesh/glb_container.h"

#include <cassert>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "lodforge/io/mesh/gltf_constants.h"

namespace lodforge {

Status checkGlbContainer(std::span<const std::byte> bytes, const std::string& name,
                         std::uint64_t& binOffset, std::uint64_t& binLength) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20)
    return badInputAtByte(name, bytes.size(), "GLB ends inside its 20-byte header");
  if (u32(4) != 2)
    return badInputAtByte(name, 4, fmt::format("GLB version {} (expected 2)", u32(4)));
  if (u32(8) != bytes.size())
    return badInputAtByte(
        name, 8, fmt::format("GLB header says {} bytes but the file has {}", u32(8), bytes.size()));
  const std::uint64_t jsonLength = u32(12);
  if (u32(16) != gltf::kChunkJson) return badInputAtByte(name, 16, "first GLB chunk is not JSON");
  if (20 + jsonLength > bytes.size())
    return badInputAtByte(
        name, 12, fmt::format("JSON chunk of {} bytes runs past the end of the file", jsonLength));
  binOffset = 20 + jsonLength + 8;
  binLength = 0;
  if (20 + jsonLength < bytes.size()) {
    if (bytes.size() - (20 + jsonLength) < 8)
      return badInputAtByte(name, 20 + jsonLength, "GLB ends inside a chunk header");
    const std::uint64_t length = u32(20 + jsonLength);
    if (length > bytes.size() - binOffset)
      return badInputAtByte(
          name, 20 + jsonLength,
          fmt::format("BIN chunk of {} bytes runs past the end of the file", length));
    if (u32(24 + jsonLength) == gltf::kChunkBin) binLength = length;
  }
  return {};
}

void padGlbJson(std::string& json) {
  while (json.size() % 4 != 0) json += ' ';
}

std::array<std::uint32_t, 5> glbHead(std::uint64_t jsonBytes, std::uint64_t afterBytes) {
  assert(jsonBytes % 4 == 0 &&
         20 + jsonBytes + afterBytes <= std::numeric_limits<std::uint32_t>::max());
  return {gltf::kGlbMagic, 2, static_cast<std::uint32_t>(20 + jsonBytes + afterBytes),
          static_cast<std::uint32_t>(jsonBytes), gltf::kChunkJson};
}

std::array<std::uint32_t, 2> binChunkHead(std::uint64_t bytes) {
  assert(bytes % 4 == 0 && bytes <= std::numeric_limits<std::uint32_t>::max());
  return {static_cast<std::uint32_t>(bytes), gltf::kChunkBin};
}

Result<std::string> glbWithJson(std::string json, std::initializer_list<std::string_view> chunks,
                                const std::string& name) {
  padGlbJson(json);
  std::uint64_t after = 0;
  for (const std::string_view piece : chunks) after += piece.size();
  // A rewrite may lengthen the JSON: nlohmann writes numbers its own way (1e2 as 100.0).
  if (20 + json.size() + after > std::numeric_limits<std::uint32_t>::max())
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: rewritten, the GLB would pass the 4 GiB GLB holds", name)};
  const std::array<std::uint32_t, 5> head = glbHead(json.size(), after);
  std::string out(reinterpret_cast<const char*>(head.data()), sizeof head);
  out.reserve(sizeof head + json.size() + after);
  out += json;
  for (const std::string_view piece : chunks) out += piece;
  return out;
}

}  // namespace lodforge
