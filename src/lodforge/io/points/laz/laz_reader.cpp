#include "lodforge/io/points/laz/laz_reader.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <vector>

#include "lodforge/core/file.h"

namespace lodforge {

namespace {

// Bytes a chunk of unknown size may take at most: arithmetic coding of incompressible records
// stays within twice their size.
std::uint64_t chunkByteBound(const LazChunk& chunk, std::uint16_t recordLength) {
  return 2 * chunk.points * recordLength + 4096;
}

}  // namespace

struct LazPointStream::State {
  std::string path;
  std::span<const std::byte> memory;
  LazLayout layout;
  LazInfo laz;
  LazChunkTable table;
  std::size_t nextChunk = 0;
  std::vector<std::byte> decoded;  // records of the chunks decoded last, not yet handed out
  std::size_t handedOut = 0;       // bytes of `decoded` already read
  std::optional<tbb::enumerable_thread_specific<std::optional<LazChunkDecoder>>> decoders;

  Result<std::vector<std::byte>> readBytes(std::uint64_t offset, std::uint64_t size) const;
  Status decodeBatch();
  Status decodeOne(std::size_t index, std::byte* out);
};

Result<std::vector<std::byte>> LazPointStream::State::readBytes(std::uint64_t offset,
                                                                std::uint64_t size) const try {
  if (offset > layout.fileSize || size > layout.fileSize - offset)
    return badInputAtByte(layout.file, offset,
                          fmt::format("{} bytes from here run past the end of the file ({} bytes)",
                                      size, layout.fileSize));
  std::vector<std::byte> bytes(size);
  if (!path.empty()) {
    Result<ByteSource> source = ByteSource::openFile(path);
    if (!source) return source.status();
    if (!source->skip(offset) || !source->read(bytes.data(), bytes.size()))
      return badInputAtByte(layout.file, offset, "the file ends early");
  } else {
    std::memcpy(bytes.data(), memory.data() + offset, size);
  }
  return bytes;
} catch (const ErrorException& e) {
  return e.error;
}

Result<LazPointStream> LazPointStream::open(const std::string& path,
                                            std::span<const std::byte> memory,
                                            const LazLayout& layout, const LazInfo& laz) {
  auto state = std::make_unique<State>();
  state->path = path;
  state->memory = memory;
  state->layout = layout;
  state->laz = laz;
  // One decoder per thread, made on first use; the opening thread's is made here, so bad items
  // fail at open.
  Result<LazChunkDecoder> first = LazChunkDecoder::create(laz, layout.file);
  if (!first) return first.status();
  State* s = state.get();
  Result<LazChunkTable> table = readLazChunkTable(
      layout, laz,
      [s](std::uint64_t offset, std::uint64_t size) { return s->readBytes(offset, size); });
  if (!table) return table.status();
  state->table = std::move(*table);
  state->decoders.emplace();
  state->decoders->local().emplace(std::move(*first));
  return LazPointStream(std::move(state));
}

LazPointStream::LazPointStream(std::unique_ptr<State> state) : state_(std::move(state)) {}
LazPointStream::LazPointStream(LazPointStream&&) noexcept = default;
LazPointStream& LazPointStream::operator=(LazPointStream&&) noexcept = default;
LazPointStream::~LazPointStream() = default;

std::size_t LazPointStream::chunkCount() const {
  return state_->table.chunks.size();
}

// Decodes chunk `index` into `out`; without a table it also learns where the next one starts.
Status LazPointStream::State::decodeOne(std::size_t index, std::byte* out) {
  LazChunk& chunk = table.chunks[index];
  const std::uint64_t size =
      chunk.bytes != 0 ? chunk.bytes
                       : std::min(chunkByteBound(chunk, layout.recordLength),
                                  layout.dataEnd - std::min(chunk.offset, layout.dataEnd));
  Result<std::vector<std::byte>> bytes = readBytes(chunk.offset, size);
  if (!bytes) return bytes.status();
  std::optional<LazChunkDecoder>& decoder = decoders->local();
  if (!decoder) {
    Result<LazChunkDecoder> made = LazChunkDecoder::create(laz, layout.file);
    if (!made) return made.status();
    decoder.emplace(std::move(*made));
  }
  Result<std::uint64_t> used = decoder->decode(*bytes, chunk, index, table.chunks.size(), out);
  if (!used) return used.status();
  if (chunk.bytes == 0 && index + 1 < table.chunks.size())
    table.chunks[index + 1].offset = chunk.offset + *used;
  return {};
}

// The next chunks, as many as the threads can decode at once (one at a time without a table).
Status LazPointStream::State::decodeBatch() {
  const std::size_t threads =
      static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  const std::size_t batch =
      table.complete ? std::min(2 * threads, table.chunks.size() - nextChunk) : 1;
  std::vector<std::uint64_t> starts(batch + 1, 0);
  for (std::size_t i = 0; i < batch; ++i)
    starts[i + 1] = starts[i] + table.chunks[nextChunk + i].points * layout.recordLength;
  decoded.resize(starts[batch]);
  handedOut = 0;
  std::vector<Status> results(batch);
  tbb::parallel_for(std::size_t{0}, batch, [&](std::size_t i) {
    results[i] = decodeOne(nextChunk + i, decoded.data() + starts[i]);
  });
  nextChunk += batch;
  for (Status& status : results)  // the first damaged chunk in file order, whatever the timing
    if (!status) return status;
  return {};
}

Status LazPointStream::skipTo(std::uint64_t point) {
  State& s = *state_;
  if (point == 0) return {};
  if (!s.table.complete)
    return Error{ErrorKind::kUnsupported,
                 fmt::format("{}: a LAZ file without a chunk table is not read from a point on",
                             s.layout.file)};
  std::uint64_t start = 0;  // the first point of chunk k
  std::size_t k = 0;
  while (k < s.table.chunks.size() && start + s.table.chunks[k].points <= point)
    start += s.table.chunks[k++].points;
  s.nextChunk = k;
  s.decoded.clear();
  s.handedOut = 0;
  if (k == s.table.chunks.size()) return {};  // past the last point: nothing left to read
  LODFORGE_TRY(s.decodeBatch());
  s.handedOut = static_cast<std::size_t>((point - start) * s.layout.recordLength);
  return {};
}

Result<std::span<const std::byte>> LazPointStream::peek() {
  State& s = *state_;
  if (s.handedOut == s.decoded.size() && s.nextChunk < s.table.chunks.size())
    LODFORGE_TRY(s.decodeBatch());
  return std::span<const std::byte>(s.decoded).subspan(s.handedOut);
}

Status LazPointStream::read(std::byte* out, std::uint64_t count) {
  State& s = *state_;
  std::uint64_t wanted = count * s.layout.recordLength;
  while (wanted > 0) {
    if (s.handedOut == s.decoded.size()) {
      if (s.nextChunk == s.table.chunks.size())
        return badInput(s.layout.file, "the LAZ chunks hold fewer points than the header says");
      LODFORGE_TRY(s.decodeBatch());
    }
    const std::uint64_t take = std::min<std::uint64_t>(wanted, s.decoded.size() - s.handedOut);
    std::memcpy(out, s.decoded.data() + s.handedOut, take);
    out += take;
    s.handedOut += take;
    wanted -= take;
  }
  return {};
}

}  // namespace lodforge
