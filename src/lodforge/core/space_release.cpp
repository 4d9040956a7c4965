#include "lodforge/core/space_release.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <filesystem>
#include <iterator>

namespace lodforge {

ByteRange wholeBlocksInside(std::uint64_t offset, std::uint64_t length, std::uint64_t blockSize) {
  assert(blockSize > 0);
  const std::uint64_t begin = (offset + blockSize - 1) / blockSize * blockSize;
  const std::uint64_t end = (offset + length) / blockSize * blockSize;
  if (end <= begin) return {};
  return {begin, end - begin};
}

SpaceRelease::SpaceRelease() : thread_([this] { serve(); }) {}

SpaceRelease::~SpaceRelease() {
  finish();
}

void SpaceRelease::punch(const std::string& path, std::uint64_t offset, std::uint64_t length) {
  if (length == 0) return;
  ask({path, offset, length, false});
}

void SpaceRelease::remove(const std::string& path) {
  ask({path, 0, 0, true});
}

void SpaceRelease::ask(Request request) {
  std::unique_lock lock(mutex_);
  if (stopping_) {  // the thread is gone (or going): this one does it
    lock.unlock();
    std::vector<Request> batch;
    batch.push_back(std::move(request));
    return release(std::move(batch));
  }
  queue_.push_back(std::move(request));
  wake_.notify_one();
}

void SpaceRelease::finish() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

std::uint64_t SpaceRelease::bytesReleased() const {
  const std::lock_guard lock(mutex_);
  return released_;
}

// Everything queued is taken at once: ranges given while the last holes were punched are
// neighbours more often than not (a tileset's blocks finish in their file order).
void SpaceRelease::serve() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and everything asked is done
    std::vector<Request> batch(std::make_move_iterator(queue_.begin()),
                               std::make_move_iterator(queue_.end()));
    queue_.clear();
    lock.unlock();
    try {
      release(std::move(batch));
    } catch (const std::exception&) {  // (an allocation): a missed release, as finish() says
    }
    lock.lock();
  }
}

void SpaceRelease::release(std::vector<Request> batch) {
  const std::lock_guard one(releasing_);
  std::map<std::string, std::vector<ByteRange>> punches;
  std::vector<std::string> removals;
  for (Request& r : batch) {
    if (r.remove) {
      removals.push_back(std::move(r.path));
    } else {
      punches[r.path].push_back({r.offset, r.length});
    }
  }
  std::uint64_t freed = 0;
  for (auto& [path, ranges] : punches) freed += punchAll(path, std::move(ranges));
  // Failures are not errors: the space comes back when the work directory is removed.
  for (const std::string& path : removals) {
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (std::filesystem::remove(path, error) && !error) freed += size;
    given_.erase(path);
  }
  const std::lock_guard lock(mutex_);
  released_ += freed;
}

namespace {

// Adds [begin, end) to the merged ranges `given`; the merged range that holds it.
ByteRange addRange(std::map<std::uint64_t, std::uint64_t>& given, std::uint64_t begin,
                   std::uint64_t end) {
  auto it = given.upper_bound(begin);
  if (it != given.begin() && std::prev(it)->second >= begin) --it;  // touches or overlaps
  while (it != given.end() && it->first <= end) {
    begin = std::min(begin, it->first);
    end = std::max(end, it->second);
    it = given.erase(it);
  }
  given.emplace(begin, end);
  return {begin, end - begin};
}

}  // namespace

// The new ranges merged where they touch; each one's hole reaches into the pages it shares with
// ranges given before when those are whole now.
std::uint64_t SpaceRelease::punchAll(const std::string& path, std::vector<ByteRange> ranges) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  struct stat info {};
  // Whole pages too: a hole drops its cached pages, and a partial one would be zeroed.
  const long fsBlock = ::fstat(fd, &info) == 0 ? static_cast<long>(info.st_blksize) : 0;
  const auto block = static_cast<std::uint64_t>(std::max(fsBlock, ::sysconf(_SC_PAGESIZE)));
  std::sort(ranges.begin(), ranges.end(),
            [](const ByteRange& a, const ByteRange& b) { return a.offset < b.offset; });
  std::map<std::uint64_t, std::uint64_t>& given = given_[path];
  std::uint64_t freed = 0;
  for (std::size_t i = 0; i < ranges.size();) {
    const std::uint64_t begin = ranges[i].offset;
    std::uint64_t end = begin + ranges[i].length;
    for (++i; i < ranges.size() && ranges[i].offset <= end; ++i)
      end = std::max(end, ranges[i].offset + ranges[i].length);
    const ByteRange merged = addRange(given, begin, end);
    const std::uint64_t from = std::max(merged.offset, begin / block * block);
    const std::uint64_t to =
        std::min(merged.offset + merged.length, (end + block - 1) / block * block);
    const ByteRange hole = wholeBlocksInside(from, to - from, block);
    if (hole.length > 0 &&
        ::fallocate(fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(hole.offset),
                    static_cast<off_t>(hole.length)) == 0)
      freed += hole.length;
  }
  ::close(fd);
  return freed;
}

}  // namespace lodforge
