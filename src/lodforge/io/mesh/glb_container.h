// The GLB container (glTF 2.0 §4.4, "Binary glTF Layout"): a 12-byte header, the JSON chunk, the
// BIN chunk. Checked before tinygltf reads a file (so errors carry byte offsets), and put
// together by the writer and by the reader's rewrites (meshopt views decoded, Draco indices
// dropped), from one definition of its headers.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

#include "lodforge/core/status.h"

namespace lodforge {

// Bad input at its byte unless `bytes` is a GLB whose header and chunk lengths agree with its
// size; then `binOffset` is where a BIN chunk's data starts and `binLength` its length (0 when
// there is no BIN chunk).
Status checkGlbContainer(std::span<const std::byte> bytes, const std::string& name,
                         std::uint64_t& binOffset, std::uint64_t& binLength);

// `json` padded with spaces to a multiple of 4 bytes, as a JSON chunk holds it.
void padGlbJson(std::string& json);

// A GLB's first 20 bytes (magic, version, length; the JSON chunk's length and type) for a padded
// JSON chunk of `jsonBytes` followed by `afterBytes` of further chunks (headers included). The
// caller checks that the whole fits the format's 4 GiB.
std::array<std::uint32_t, 5> glbHead(std::uint64_t jsonBytes, std::uint64_t afterBytes);

// A BIN chunk's 8-byte header for `bytes` of data (padded to a multiple of 4).
std::array<std::uint32_t, 2> binChunkHead(std::uint64_t bytes);

// A whole GLB in memory: `json` (padded here) and then the pieces of the further chunks, each
// copied once, as they are; kLimit (naming `name`) when it would pass the 4 GiB a GLB's
// lengths can say.
Result<std::string> glbWithJson(std::string json, std::initializer_list<std::string_view> chunks,
                                const std::string& name);

}  // namespace lodforge
