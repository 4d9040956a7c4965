// Work handed out through a directory every rank of a job sees (docs/distributed.md): one
// producer publishes numbered items, each a small file that appears whole; any number of
// consumers, threads of any rank, claim them, each item exactly once, since a claim is a rename
// (atomic on a POSIX file system). The producer closes the queue with the count it published,
// or as failed, so that no consumer waits for items that will never come.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "lodforge/core/status.h"

namespace lodforge {

class FileQueue {
 public:
  explicit FileQueue(std::string directory) : directory_(std::move(directory)) {}

  // The producer, before any consumer starts: a fresh queue (an earlier one's files removed).
  Status create() const;
  // Item `number` (numbered from 0 without gaps, from any thread of the producer).
  Status publish(std::uint64_t number, std::string_view item) const;
  // No item after the first `count`; `failed`: none after now either (consumers stop at once).
  Status close(std::uint64_t count, bool failed = false) const;

  // The next item no one has claimed, at or after `cursor` (a consumer's own, from 0), waiting
  // for the producer when there is none yet; nullopt once the queue is closed and every item is
  // claimed, or it was closed as failed. Fails as cancelled when the run is interrupted.
  Result<std::optional<std::string>> claim(std::uint64_t& cursor) const;

  const std::string& directory() const { return directory_; }

 private:
  std::string itemPath(std::uint64_t number) const;
  std::string takenPath(std::uint64_t number) const;
  std::string directory_;
};

}  // namespace lodforge
