#include "lodforge/io/points/laz/laz_chunks.h"

#include <algorithm>
#include <cstring>

#include "lodforge/io/points/laz/laz_arith.h"
#include "lodforge/io/points/laz/laz_items.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

constexpr std::uint64_t kTableEntryBound = 24;  // coded bytes one table entry can take, at most

bool variableChunks(const LazInfo& laz) {
  return laz.chunkSize == kLazVariableChunks || laz.chunkSize == 0;
}

// Without a table the chunks follow one another; their starts are found while decoding.
Result<LazChunkTable> chunksWithoutTable(const LazLayout& layout, const LazInfo& laz,
                                         std::uint64_t firstChunk, std::string_view why) {
  if (variableChunks(laz))
    return badInputAtByte(layout.file, layout.pointOffset,
                          fmt::format("{}, and the chunks have variable sizes, so where they "
                                      "start cannot be known",
                                      why));
  LazChunkTable table;
  table.complete = false;
  for (std::uint64_t done = 0; done < layout.pointCount; done += laz.chunkSize)
    table.chunks.push_back({done == 0 ? firstChunk : 0, 0,
                            std::min<std::uint64_t>(laz.chunkSize, layout.pointCount - done)});
  return table;
}

// The entries: per chunk its point count (variable chunks only) and byte size, each coded as
// an integer predicted by the entry before (LAZ specification, chunk table).
Result<LazChunkTable> decodeTableEntries(const LazLayout& layout, const LazInfo& laz,
                                         std::uint64_t tableAt, std::uint32_t count,
                                         std::span<const std::byte> coded,
                                         std::uint64_t firstChunk) {
  LazDecoder dec;
  dec.start(coded);
  LazIntegerDecoder ic(32, 2);
  ic.reset();
  const bool variable = variableChunks(laz);
  LazChunkTable table;
  std::int32_t lastCount = 0, lastBytes = 0;
  std::uint64_t offset = firstChunk, points = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    LazChunk chunk;
    chunk.offset = offset;
    if (variable) lastCount = ic.decode(dec, lastCount, 0);
    lastBytes = ic.decode(dec, lastBytes, 1);
    chunk.points =
        variable ? static_cast<std::uint32_t>(lastCount)
                 : std::min<std::uint64_t>(laz.chunkSize,
                                           layout.pointCount - std::min(points, layout.pointCount));
    chunk.bytes = static_cast<std::uint32_t>(lastBytes);
    if (chunk.bytes == 0 || offset + chunk.bytes > tableAt)
      return badInputAtByte(layout.file, tableAt,
                            fmt::format("the chunk table says chunk {} of {} takes {} bytes from "
                                        "byte {}, past the table at byte {}",
                                        i + 1, count, chunk.bytes, offset, tableAt));
    offset += chunk.bytes;
    points += chunk.points;
    table.chunks.push_back(chunk);
  }
  if (dec.overrun() || dec.invalid())
    return badInputAtByte(layout.file, tableAt + 8, "the chunk table is damaged");
  if (points != layout.pointCount)
    return badInputAtByte(layout.file, tableAt,
                          fmt::format("the chunk table's {} chunks hold {} points but the header "
                                      "says {}",
                                      count, points, layout.pointCount));
  return table;
}

}  // namespace

Result<LazChunkTable> readLazChunkTable(const LazLayout& layout, const LazInfo& laz,
                                        const LazByteReader& read) {
  if (laz.compressor == LazCompressor::kPointwise) {  // one chunk, no table
    LazChunkTable table;
    if (layout.pointCount > 0)
      table.chunks.push_back({layout.pointOffset, 0, layout.pointCount});  // its end: decoded
    return table;
  }
  Result<std::vector<std::byte>> pointer = read(layout.pointOffset, 8);
  if (!pointer) return pointer.status();
  const std::uint64_t firstChunk = layout.pointOffset + 8;
  auto tableAt = loadField<std::int64_t>(pointer->data());
  if (tableAt == -1) {  // written to a stream: the pointer is the file's last 8 bytes
    Result<std::vector<std::byte>> tail = read(layout.fileSize - 8, 8);
    if (!tail) return tail.status();
    tableAt = loadField<std::int64_t>(tail->data());
  }
  if (static_cast<std::uint64_t>(tableAt) + 8 == firstChunk)
    return chunksWithoutTable(layout, laz, firstChunk, "the writer never wrote the chunk table");
  if (static_cast<std::uint64_t>(tableAt) == layout.dataEnd)
    return chunksWithoutTable(layout, laz, firstChunk, "the chunk table is missing");
  if (tableAt < static_cast<std::int64_t>(firstChunk) ||
      static_cast<std::uint64_t>(tableAt) + 8 > layout.dataEnd)
    return badInputAtByte(layout.file, layout.pointOffset,
                          fmt::format("the chunk table is said to be at byte {}, outside the "
                                      "point data (bytes {} to {})",
                                      tableAt, firstChunk, layout.dataEnd));
  const auto at = static_cast<std::uint64_t>(tableAt);
  Result<std::vector<std::byte>> head = read(at, 8);
  if (!head) return head.status();
  const auto version = loadField<std::uint32_t>(head->data());
  const auto count = loadField<std::uint32_t>(head->data() + 4);
  if (version != 0)
    return badInputAtByte(layout.file, at, fmt::format("chunk table version {} is not 0", version));
  const std::uint64_t expected =
      variableChunks(laz) ? count : (layout.pointCount + laz.chunkSize - 1) / laz.chunkSize;
  if (count != expected || count > layout.dataEnd - firstChunk)
    return badInputAtByte(layout.file, at + 4,
                          fmt::format("the chunk table lists {} chunks but {} points in chunks "
                                      "of {} make {}",
                                      count, layout.pointCount, laz.chunkSize, expected));
  if (count == 0) return LazChunkTable{};
  const std::uint64_t codedBytes =
      std::min<std::uint64_t>(layout.dataEnd - at - 8, kTableEntryBound * count + 8);
  Result<std::vector<std::byte>> coded = read(at + 8, codedBytes);
  if (!coded) return coded.status();
  return decodeTableEntries(layout, laz, at, count, *coded, firstChunk);
}

struct LazChunkDecoder::State {
  std::string file;
  bool layered = false;
  std::vector<std::unique_ptr<LazPointwiseItem>> pointwise;
  std::vector<std::unique_ptr<LazLayeredItem>> layeredItems;
  std::vector<std::size_t> itemOffsets;  // where each item's bytes sit in the record
  std::size_t recordLength = 0;
  LazDecoder dec;

  Error damaged(std::uint64_t at, std::size_t index, std::size_t count,
                std::string_view what) const {
    return badInputAtByte(file, at, fmt::format("LAZ chunk {} of {}: {}", index + 1, count, what));
  }
  Result<std::uint64_t> decodePointwise(std::span<const std::byte> bytes, const LazChunk& chunk,
                                        std::size_t index, std::size_t count, std::byte* out);
  Result<std::uint64_t> decodeLayered(std::span<const std::byte> bytes, const LazChunk& chunk,
                                      std::size_t index, std::size_t count, std::byte* out);
};

LazChunkDecoder::LazChunkDecoder(std::unique_ptr<State> state) : state_(std::move(state)) {}
LazChunkDecoder::LazChunkDecoder(LazChunkDecoder&&) noexcept = default;
LazChunkDecoder& LazChunkDecoder::operator=(LazChunkDecoder&&) noexcept = default;
LazChunkDecoder::~LazChunkDecoder() = default;

Result<LazChunkDecoder> LazChunkDecoder::create(const LazInfo& laz, const std::string& file) {
  auto state = std::make_unique<State>();
  state->file = file;
  state->layered = laz.compressor == LazCompressor::kLayeredChunked;
  for (const LazItem& item : laz.items) {
    state->itemOffsets.push_back(state->recordLength);
    state->recordLength += item.size;
    bool made = false;
    if (state->layered) {
      state->layeredItems.push_back(makeLayeredItem(item));
      made = state->layeredItems.back() != nullptr;
    } else {
      state->pointwise.push_back(item.version == 1 ? makePointwiseItemV1(item)
                                                   : makePointwiseItemV2(item));
      made = state->pointwise.back() != nullptr;
    }
    if (!made)
      return badInput(file, fmt::format("LAZ item {} version {} is not known to the {} "
                                        "compressor",
                                        lazItemName(item.type), item.version,
                                        state->layered ? "layered" : "point-wise"));
  }
  return LazChunkDecoder(std::move(state));
}

Result<std::uint64_t> LazChunkDecoder::decode(std::span<const std::byte> bytes,
                                              const LazChunk& chunk, std::size_t index,
                                              std::size_t chunkCount, std::byte* out) {
  State& s = *state_;
  if (chunk.points == 0) return std::uint64_t{0};
  if (bytes.size() < s.recordLength)
    return s.damaged(chunk.offset, index, chunkCount,
                     fmt::format("{} bytes cannot hold the chunk's first point ({} bytes)",
                                 bytes.size(), s.recordLength));
  std::memcpy(out, bytes.data(), s.recordLength);  // the first point is stored as it is
  return s.layered ? s.decodeLayered(bytes, chunk, index, chunkCount, out)
                   : s.decodePointwise(bytes, chunk, index, chunkCount, out);
}

Result<std::uint64_t> LazChunkDecoder::State::decodePointwise(std::span<const std::byte> bytes,
                                                              const LazChunk& chunk,
                                                              std::size_t index, std::size_t count,
                                                              std::byte* out) {
  for (std::size_t i = 0; i < pointwise.size(); ++i) pointwise[i]->start(out + itemOffsets[i]);
  dec.start(bytes.subspan(recordLength));
  std::uint64_t whole = chunk.points;  // points decoded before the bytes ran out
  for (std::uint64_t p = 1; p < chunk.points && whole == chunk.points; ++p) {
    std::byte* record = out + p * recordLength;
    for (std::size_t i = 0; i < pointwise.size(); ++i)
      pointwise[i]->read(dec, record + itemOffsets[i]);
    if (dec.overrun()) whole = p;
  }
  const std::uint64_t end = chunk.offset + recordLength + dec.consumed();
  if (dec.overrun())
    return damaged(end, index, count,
                   fmt::format("the compressed points end after {} of the chunk's {}: the chunk "
                               "is truncated or damaged, or the header's point count is wrong",
                               whole, chunk.points));
  if (dec.invalid()) return damaged(end, index, count, "the arithmetic-coded points are damaged");
  // LASzip's decoder ends exactly where the encoder did: a chunk that decodes to another length
  // is damaged (the coder itself cannot tell good bytes from bad).
  if (chunk.bytes != 0 && recordLength + dec.consumed() != chunk.bytes)
    return damaged(end, index, count,
                   fmt::format("the points decode from {} bytes but the chunk table gives the "
                               "chunk {}: the chunk is damaged",
                               recordLength + dec.consumed(), chunk.bytes));
  return recordLength + dec.consumed();
}

Result<std::uint64_t> LazChunkDecoder::State::decodeLayered(std::span<const std::byte> bytes,
                                                            const LazChunk& chunk,
                                                            std::size_t index, std::size_t count,
                                                            std::byte* out) {
  std::size_t layerCount = 0;
  for (const auto& item : layeredItems) layerCount += item->layerCount();
  std::uint64_t at = recordLength;
  if (bytes.size() < at + 4 + 4 * layerCount)
    return damaged(chunk.offset + at, index, count, "the chunk ends inside its layer sizes");
  const auto points = loadField<std::uint32_t>(bytes.data() + at);
  if (points != chunk.points)
    return damaged(
        chunk.offset + at, index, count,
        fmt::format("the chunk holds {} points but the chunk table says {}", points, chunk.points));
  at += 4;
  std::vector<std::uint32_t> sizes(layerCount);
  std::memcpy(sizes.data(), bytes.data() + at, 4 * layerCount);
  at += 4 * layerCount;
  std::vector<std::span<const std::byte>> layers;
  for (std::size_t l = 0; l < layerCount; ++l) {
    if (sizes[l] > bytes.size() - at)
      return damaged(chunk.offset + at, index, count,
                     fmt::format("layer {} of {} bytes runs past the chunk's end at byte {}", l + 1,
                                 sizes[l], chunk.offset + bytes.size()));
    layers.push_back(bytes.subspan(at, sizes[l]));
    at += sizes[l];
  }
  std::uint32_t context = 0;
  std::size_t firstLayer = 0;
  for (std::size_t i = 0; i < layeredItems.size(); ++i) {
    const std::size_t n = layeredItems[i]->layerCount();
    layeredItems[i]->start(out + itemOffsets[i], std::span(layers).subspan(firstLayer, n), context);
    firstLayer += n;
  }
  for (std::uint64_t p = 1; p < chunk.points; ++p) {
    // LASzip passes channel 0 to the items after POINT14 unless the channel changes at this very
    // point (its context starts at 0 per point); the encoder does the same, so the decoder must.
    context = 0;
    std::byte* record = out + p * recordLength;
    for (std::size_t i = 0; i < layeredItems.size(); ++i)
      layeredItems[i]->read(record + itemOffsets[i], context);
  }
  for (const auto& item : layeredItems)
    if (item->damaged())
      return damaged(chunk.offset, index, count,
                     "a layer's arithmetic-coded data is damaged or cut short");
  return at;
}

}  // namespace lodforge
