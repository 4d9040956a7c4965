#include "lodforge/core/threads.h"

#include <thread>

#include <tbb/global_control.h>

namespace lodforge {

struct ThreadLimit::Control {
  tbb::global_control control;
};

unsigned hardwareThreads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

ThreadLimit::ThreadLimit(unsigned threads) : threads_(threads ? threads : hardwareThreads()) {
  control_ = std::make_unique<Control>(
      Control{tbb::global_control(tbb::global_control::max_allowed_parallelism, threads_)});
}

ThreadLimit::~ThreadLimit() = default;

}  // namespace lodforge
