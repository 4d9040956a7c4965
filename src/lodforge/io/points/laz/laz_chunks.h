// LAZ point data as chunks: the chunk table (where each chunk starts and how many points it
// holds; LASzip writes it after the chunks, arithmetic-coded) and the decoding of one chunk into
// plain LAS point records. Chunks are independent, so they decode in parallel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/io/points/laz/laz_vlr.h"

namespace lodforge {

struct LazChunk {
  std::uint64_t offset = 0;  // file byte where the chunk starts
  std::uint64_t bytes = 0;   // its compressed size; 0 while unknown (no chunk table)
  std::uint64_t points = 0;
};

// Where the chunks lie, from the table or — when LASzip's writer never wrote one, which LASzip
// itself tolerates — as far as can be known before decoding (`complete` false: each chunk's end
// is found by decoding it). `read(offset, size)` fetches bytes of the file.
struct LazChunkTable {
  std::vector<LazChunk> chunks;
  bool complete = true;
};

struct LazLayout {
  std::string file;  // for messages
  std::uint64_t fileSize = 0;
  std::uint64_t pointOffset = 0;  // where the point data (and the table's pointer) start
  std::uint64_t dataEnd = 0;      // where the point data must end (EVLRs or the file's end)
  std::uint64_t pointCount = 0;
  std::uint16_t recordLength = 0;
};

using LazByteReader =
    std::function<Result<std::vector<std::byte>>(std::uint64_t offset, std::uint64_t size)>;

Result<LazChunkTable> readLazChunkTable(const LazLayout& layout, const LazInfo& laz,
                                        const LazByteReader& read);

// Decodes chunks with the items a LASzip record names; one per thread.
class LazChunkDecoder {
 public:
  // Bad input when an item's type and version have no codec, or do not fit the compressor.
  static Result<LazChunkDecoder> create(const LazInfo& laz, const std::string& file);
  LazChunkDecoder(LazChunkDecoder&&) noexcept;
  LazChunkDecoder& operator=(LazChunkDecoder&&) noexcept;
  ~LazChunkDecoder();

  // Decodes `chunk.points` records from `bytes` (the chunk's bytes, starting at chunk.offset)
  // into `out`; returns how many bytes the chunk took. Damage is bad input naming the file,
  // chunk `index` and the byte.
  Result<std::uint64_t> decode(std::span<const std::byte> bytes, const LazChunk& chunk,
                               std::size_t index, std::size_t chunkCount, std::byte* out);

 private:
  struct State;
  explicit LazChunkDecoder(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
