// Progress for long work and cooperative cancellation. Work that can take over a second reports
// through a Progress (a bar on a terminal, plain lines otherwise, nothing for the first second)
// and checks cancellation between batches, so Ctrl-C stops it cleanly with temporaries removed.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

#include "lodforge/core/status.h"

namespace lodforge {

// Ctrl-C (SIGINT) and SIGTERM request cancellation; a second Ctrl-C exits at once.
void installInterruptHandler();
void requestCancel();
void clearCancel();
bool cancelRequested();
// An ErrorKind::kCancelled status when cancellation was requested, ok otherwise.
Status checkCancelled();
// Marks a step of resumable work done: `kind` is "node" (a tile node's summary), "run" (chunks
// reconstructed), "pointblock", "pointstaged", "pointnode" (a point block ranked, a node staged,
// placed) or "tile" (a point tile). LODFORGE_INTERRUPT_AFTER=KIND:N makes the N-th step of that
// kind request cancellation as Ctrl-C would (the resume tests stop a run at a known point); with
// KIND:N:kill the process dies there instead (SIGKILL), as a rank of a distributed job may.
void checkpointReached(std::string_view kind);

// Wall time since `start`, for the figures long work reports.
inline double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

enum class ProgressMode : std::uint8_t { kAuto, kBar, kLines, kOff };
// Process-wide choice (the CLI sets kOff for -q); kAuto picks a bar when stderr is a terminal.
void setProgressMode(ProgressMode mode);

// One with no label shows nothing: a share of work that another bar shows (a job's, JobProgress).
class Progress {
 public:
  enum class Unit : std::uint8_t { kCount, kBytes };
  Progress(std::string label, std::uint64_t total, Unit unit = Unit::kCount);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Thread-safe; redraws at most a few times a second.
  void advance(std::uint64_t amount);
  void finish();

 private:
  void draw(bool final);

  std::string label_;
  std::uint64_t total_;
  Unit unit_;
  ProgressMode mode_;
  std::atomic<std::uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::atomic<std::int64_t> nextDrawMs_{0};
  std::mutex drawMutex_;
  bool drawn_ = false;
  bool finished_ = false;
};

}  // namespace lodforge
