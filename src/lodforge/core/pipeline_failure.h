// The failure of a tbb::parallel_pipeline over the batches of a file, from any of its stages:
// the one nearest the start of the file is kept (the same message whatever the timing), and
// every stage stops once one is.
#pragma once

#include <atomic>
#include <cassert>
#include <cstdint>
#include <limits>
#include <mutex>
#include <utility>

#include <tbb/parallel_pipeline.h>

#include "lodforge/core/status.h"

namespace lodforge {

class PipelineFailure {
 public:
  // `position`: where in the file (a record, a byte); `control`, from the first stage, stops it.
  void fail(std::uint64_t position, Status status, tbb::flow_control* control = nullptr) {
    assert(position != std::numeric_limits<std::uint64_t>::max());  // max means none
    std::lock_guard lock(mutex_);
    if (status_.ok() || position < position_) status_ = std::move(status), position_ = position;
    if (control) control->stop();
  }
  bool failed() const { return position_ != std::numeric_limits<std::uint64_t>::max(); }
  // Whether a failure before `position` is kept: a stage skips work only then, so that a later
  // batch failing first cannot hide an earlier batch's failure.
  bool failedBefore(std::uint64_t position) const { return position_ < position; }
  // Read once the pipeline is over.
  const Status& status() const { return status_; }

 private:
  std::mutex mutex_;
  Status status_;
  std::atomic<std::uint64_t> position_ = std::numeric_limits<std::uint64_t>::max();
};

}  // namespace lodforge
