#include "lodforge/core/file_queue.h"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"

namespace lodforge {

namespace fs = std::filesystem;

namespace {

constexpr const char* kClosed = "closed";
// How long a consumer sleeps when the producer has nothing new: short next to a block's work.
constexpr auto kPoll = std::chrono::milliseconds(2);

struct Closed {
  std::uint64_t count = 0;
  bool failed = false;
};

// The closing note, once the producer has written it.
Result<std::optional<Closed>> readClosed(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::optional<Closed>();
  Result<std::string> text = readFileToString(path, 64);
  if (!text) return text.status();
  Closed closed;
  const char* end = text->data() + text->size();
  const auto [rest, code] = std::from_chars(text->data(), end, closed.count);
  if (code != std::errc{}) return ioError(path, "is not a queue's closing note");
  closed.failed =
      std::string_view(rest, static_cast<std::size_t>(end - rest)).starts_with(" failed");
  return std::optional<Closed>(closed);
}

}  // namespace

std::string FileQueue::itemPath(std::uint64_t number) const {
  return fmt::format("{}/items/{:010}", directory_, number);
}

std::string FileQueue::takenPath(std::uint64_t number) const {
  return fmt::format("{}/taken/{:010}", directory_, number);
}

Status FileQueue::create() const {
  std::error_code error;
  fs::remove_all(directory_, error);
  if (!error) fs::create_directories(directory_ + "/items", error);
  if (!error) fs::create_directories(directory_ + "/taken", error);
  if (error) return ioError(directory_, fmt::format("cannot create: {}", error.message()));
  return {};
}

Status FileQueue::publish(std::uint64_t number, std::string_view item) const {
  return OutputFile::writeWhole(itemPath(number), item);  // written aside, renamed in whole
}

Status FileQueue::close(std::uint64_t count, bool failed) const {
  return OutputFile::writeWhole(directory_ + "/" + kClosed,
                                fmt::format("{}{}\n", count, failed ? " failed" : ""));
}

Result<std::optional<std::string>> FileQueue::claim(std::uint64_t& cursor) const {
  std::optional<Closed> closed;
  for (;;) {
    const std::string item = itemPath(cursor), taken = takenPath(cursor);
    if (std::rename(item.c_str(), taken.c_str()) == 0) {
      ++cursor;
      Result<std::string> bytes = readFileToString(taken, std::uint64_t{1} << 20);
      if (!bytes) return bytes.status();
      return std::optional<std::string>(std::move(*bytes));
    }
    if (errno != ENOENT) return ioErrorFromErrno(item, "claim");
    std::error_code error;
    if (fs::exists(taken, error)) {  // another consumer's
      ++cursor;
      continue;
    }
    if (closed) {
      if (closed->failed || cursor >= closed->count) return std::optional<std::string>();
      // Every item is in one of the two folders once the queue is closed (a rename moves it
      // whole), and it was closed before this try began.
      return ioError(item, "a queued item is missing");
    }
    Result<std::optional<Closed>> read = readClosed(directory_ + "/" + kClosed);
    if (!read) return read.status();
    closed = *read;
    if (closed) continue;  // item `cursor` may have come just before the closing note
    // Not published yet (or published since the rename: the next try takes it).
    LODFORGE_TRY(checkCancelled());
    std::this_thread::sleep_for(kPoll);
  }
}

}  // namespace lodforge
