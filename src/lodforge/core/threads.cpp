#include "lodforge/core/threads.h"

#include <sched.h>

#include <thread>

#include <tbb/global_control.h>

namespace lodforge {

struct ThreadLimit::Control {
  tbb::global_control control;
};

unsigned hardwareThreads() {
  // The cores this process may run on: mpirun binds each rank to its own, and TBB will not
  // start more workers than that.
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0)
    return static_cast<unsigned>(CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

ThreadLimit::ThreadLimit(unsigned threads) : threads_(threads ? threads : hardwareThreads()) {
  control_ = std::make_unique<Control>(
      Control{tbb::global_control(tbb::global_control::max_allowed_parallelism, threads_)});
}

ThreadLimit::~ThreadLimit() = default;

}  // namespace lodforge
