// EXT_meshopt_compression in a GLB, decoded before tinygltf reads the file: tinygltf (2.8) knows
// nothing of the extension and takes the fallback buffer, which has no data, for the BIN chunk.
// Each compressed buffer view is decoded with meshoptimizer's decoders (and its filters) into
// data appended to the BIN chunk, the views point there, and the fallback buffers go. Our point
// tiles are written this way by default, and so are gltfpack's files written with its -c option.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "lodforge/core/status.h"

namespace lodforge {

// The GLB `glb` (its container already checked: BIN chunk data at `binOffset`, `binLength`
// bytes) with every EXT_meshopt_compression view decoded; nothing when no view is compressed.
// A stream that does not decode, or that names bytes outside the BIN chunk, is bad input at its
// byte in the file.
Result<std::optional<std::string>> withMeshoptDecoded(std::span<const std::byte> glb,
                                                      const std::string& name,
                                                      std::uint64_t binOffset,
                                                      std::uint64_t binLength);

}  // namespace lodforge
