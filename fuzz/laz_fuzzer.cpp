// The LAZ chunk decoder on any bytes. The first byte picks the items (a point-wise v1, v2 or a
// layered v3 set), the next two the chunk's point count, the rest are the chunk: either a
// bad-input error naming the file, or records that used no more bytes than the chunk holds.
// (The count's top bit says whether the chunk's size is known, as a chunk table would give it.)
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "fuzz_check.h"
#include "lodforge/io/points/laz/laz_chunks.h"

namespace {

using namespace lodforge;

LazInfo itemSet(std::uint8_t which) {
  LazInfo laz;
  laz.chunkSize = 50000;
  switch (which % 7) {
    case 0:  // LASzip 1.x, format 3
      laz.compressor = LazCompressor::kPointwise;
      laz.items = {{6, 20, 1}, {7, 8, 1}, {8, 6, 1}, {0, 3, 1}};
      break;
    case 1:  // LASzip 2.x, format 3
      laz.compressor = LazCompressor::kPointwiseChunked;
      laz.items = {{6, 20, 2}, {7, 8, 2}, {8, 6, 2}};
      break;
    case 2:  // format 4: waveform packets
      laz.compressor = LazCompressor::kPointwiseChunked;
      laz.items = {{6, 20, 1}, {7, 8, 1}, {9, 29, 1}};
      break;
    case 3:  // LAS 1.4 format 7 (COPC's)
      laz.compressor = LazCompressor::kLayeredChunked;
      laz.items = {{10, 30, 3}, {11, 6, 3}};
      break;
    case 4:  // LAS 1.4 format 8 with extra bytes
      laz.compressor = LazCompressor::kLayeredChunked;
      laz.items = {{10, 30, 3}, {12, 8, 3}, {14, 2, 3}};
      break;
    case 5:  // format 1 with extra bytes
      laz.compressor = LazCompressor::kPointwiseChunked;
      laz.items = {{6, 20, 2}, {7, 8, 2}, {0, 4, 2}};
      break;
    default:  // LAS 1.4 format 9: waveform packets
      laz.compressor = LazCompressor::kLayeredChunked;
      laz.items = {{10, 30, 3}, {13, 29, 3}};
      break;
  }
  return laz;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const LazInfo laz = itemSet(data[0]);
  const std::uint32_t points = 1u + (static_cast<std::uint32_t>(data[1]) |
                                     (static_cast<std::uint32_t>(data[2] & 0x0F) << 8));
  const std::span<const std::byte> chunk(reinterpret_cast<const std::byte*>(data + 3), size - 3);
  Result<LazChunkDecoder> decoder = LazChunkDecoder::create(laz, "fuzz.laz");
  if (!decoder) std::abort();  // the sets above are all valid
  std::vector<std::byte> records(std::size_t{points} * laz.recordBytes());
  // With the count's top bit the chunk's size is known (as from a chunk table), else found.
  const LazChunk where{0, (data[2] & 0x80) != 0 ? chunk.size() : 0, points};
  Result<std::uint64_t> used = decoder->decode(chunk, where, 0, 1, records.data());
  if (!used) {
    fuzz::checkError(used.error(), "fuzz.laz");
  } else if (*used > chunk.size()) {
    std::abort();
  }
  return 0;
}
