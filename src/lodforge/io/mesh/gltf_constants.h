// The numbers glTF 2.0 names: accessor component types (the OpenGL enums), buffer view targets,
// and the GLB header's magic and chunk types. One table for the reader, the writer and the tiles.
#pragma once

#include <cstdint>

namespace lodforge::gltf {

constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
              kUnsignedInt = 5125, kFloat = 5126;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr std::uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

}  // namespace lodforge::gltf
