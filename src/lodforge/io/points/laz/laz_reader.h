// LAZ point records, decoded in file order: chunks are fetched and decoded a batch at a time, in
// parallel (as many as the thread limit allows), and handed out as plain LAS records.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/io/points/laz/laz_chunks.h"

namespace lodforge {

class LazPointStream {
 public:
  // `path` names the file to read, or is empty and `memory` holds the whole file.
  static Result<LazPointStream> open(const std::string& path, std::span<const std::byte> memory,
                                     const LazLayout& layout, const LazInfo& laz);
  LazPointStream(LazPointStream&&) noexcept;
  LazPointStream& operator=(LazPointStream&&) noexcept;
  ~LazPointStream();

  // From record `point` on (call before the first read; a peek may come before): the chunk that
  // holds it decoded, the records before it dropped. kUnsupported without a chunk table (its
  // chunks are found only by decoding them in turn).
  Status skipTo(std::uint64_t point);
  // The next `count` records into `out` (count × record length bytes).
  Status read(std::byte* out, std::uint64_t count);
  // The records decoded ahead and not read yet (a batch is decoded when none are): a look at the
  // first points without decoding them twice.
  Result<std::span<const std::byte>> peek();
  std::size_t chunkCount() const;

 private:
  struct State;
  explicit LazPointStream(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
