// Giving a run's disk space back while it goes on: holes punched in the parts of a work file no
// step reads again, and finished work files removed, on a thread of the release's own. Freeing
// written blocks waits on the disk (on this project's VMs, whose file system is mounted with
// `discard`, about 0.8 s a GB); done at the end of a run, it was 5 % of a 100 M-point run's wall
// time, and the run's peak disk use is lower when the space comes back early.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace lodforge {

struct ByteRange {
  std::uint64_t offset = 0, length = 0;
};
// The whole blocks of `blockSize` bytes inside [offset, offset + length): {first byte, length},
// length 0 when none.
ByteRange wholeBlocksInside(std::uint64_t offset, std::uint64_t length, std::uint64_t blockSize);

class SpaceRelease {
 public:
  SpaceRelease();
  ~SpaceRelease();  // finish()
  SpaceRelease(const SpaceRelease&) = delete;
  SpaceRelease& operator=(const SpaceRelease&) = delete;

  // Bytes [offset, offset + length) of `path` will not be read again: the whole file-system
  // blocks inside the range, with those it completes with ranges given before, become a hole
  // (reading zeros); the bytes around them stay. Ranges given while a hole is being punched are
  // punched together where they touch (a hole costs about 3 ms whatever its size).
  void punch(const std::string& path, std::uint64_t offset, std::uint64_t length);
  // `path` will not be read again: removed.
  void remove(const std::string& path);
  // Does everything asked so far, then stops the thread (a later request is done at once, on the
  // caller's thread). What could not be freed (a file system without holes, a failed allocation)
  // is freed with the file: a missed release costs disk space until then, never a byte of a range
  // still to read. Called by the owner alone (not from two threads at once).
  void finish();
  // Bytes of the holes punched (a range punched again counts again) and of the files removed
  // (their sizes): what the tests check.
  std::uint64_t bytesReleased() const;

 private:
  struct Request {
    std::string path;
    std::uint64_t offset = 0, length = 0;
    bool remove = false;
  };
  void ask(Request request);
  void serve();
  // Holes for the punches of `batch`, then its removals.
  void release(std::vector<Request> batch);
  std::uint64_t punchAll(const std::string& path, std::vector<ByteRange> ranges);

  std::mutex releasing_;  // one release at a time (the thread's, or a caller's after finish())
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Request> queue_;
  bool stopping_ = false;
  std::uint64_t released_ = 0;
  // Per path, the ranges given so far, merged: [first byte, end) (under releasing_).
  std::map<std::string, std::map<std::uint64_t, std::uint64_t>> given_;
  std::thread thread_;
};

}  // namespace lodforge
