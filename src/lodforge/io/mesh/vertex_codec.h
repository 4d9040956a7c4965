// EXT_meshopt_compression's attribute bitstream (mode 0, the extension's Appendix A), written
// by our own encoder: meshoptimizer 0.18's `meshopt_encodeVertexBuffer` (Debian 12's) does the
// same at a third to a seventh of the speed, and point tiles are nearly all vertex data. Any
// conforming decoder reads what this writes (meshoptimizer's, CesiumJS's, three.js's).
#pragma once

#include <cstddef>
#include <span>

namespace lodforge {

// The most bytes encodeVertexAttributes writes for `count` elements of `stride` bytes.
std::size_t vertexAttributesBound(std::size_t count, std::size_t stride);

// Encodes `count` elements of `stride` bytes (a multiple of 4, at most 256) from `data` into
// `out` (at least vertexAttributesBound bytes); returns the bytes written. Each group of 16
// byte deltas takes the smallest of the four encodings, so the stream is never larger than
// meshoptimizer's.
std::size_t encodeVertexAttributes(std::span<std::byte> out, const void* data, std::size_t count,
                                   std::size_t stride);

}  // namespace lodforge
