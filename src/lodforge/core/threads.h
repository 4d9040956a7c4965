// Thread limits: every parallel algorithm runs on TBB, and a ThreadLimit caps how many threads
// TBB may use while it lives (the --threads option).
#pragma once

#include <memory>

namespace lodforge {

class ThreadLimit {
 public:
  // 0 means all hardware threads.
  explicit ThreadLimit(unsigned threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;
  unsigned threads() const { return threads_; }

 private:
  struct Control;
  std::unique_ptr<Control> control_;
  unsigned threads_;
};

// The cores this process may run on (its affinity: all of the machine unless bound).
unsigned hardwareThreads();

}  // namespace lodforge
