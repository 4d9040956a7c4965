// Never destroy what is not ours: before any work, a command claims its output path. An existing
// output is replaced only when it is what this command itself would write there; a path that is
// an input, a directory holding anything else, or a file of another kind is refused (usage error,
// exit 2), and a place that cannot be written is an I/O error (exit 1) — all before any work.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "lodforge/core/status.h"

namespace lodforge {

// What a command writes at its output path.
struct OutputKind {
  std::string name;        // for messages: "a lodforge tileset", "a PLY file"
  bool directory = false;  // the output is a directory (a tileset, a folder of frames)
  // Whether the existing path holds this kind's own earlier output, which may be replaced.
  // Empty files and directories are always replaceable (nothing in them can be lost).
  std::function<bool(const std::string& path)> isOwn;
};

// An input the command will read: it must exist (kIo otherwise, as the system reports it) and be
// a file, not a directory (kBadInput: "PATH: is a directory").
Status checkInputPath(const std::string& path);
// Only the directory half of checkInputPath: a path that does not exist passes (the reader says
// so), so a command can name an unknown format before it complains about a missing file.
Status refuseDirectoryInput(const std::string& path);

// Checks `output` against `kind` and the `inputs` (each checked with checkInputPath), creates its
// missing parent directories and checks that the parent can be written.
Status claimOutput(const std::string& output, const OutputKind& kind,
                   std::span<const std::string> inputs);

// The leftovers of an earlier run at `output` killed before it could clean up (SIGKILL, a power
// cut): the names lodforge gives its temporaries there ("OUTPUT.tmp-PID-N…", and
// "OUTPUT.work.tmp-PID-N…" for work directories) whose process PID no longer runs. Removes them
// (claimOutput does) and returns how many; anything else, and a running process's, is left.
std::size_t removeDeadLeftovers(const std::string& output);
// The PID in a temporary's `name` made for `output` (a file name, no folder), if it is one.
std::optional<int> leftoverProcess(std::string_view name, std::string_view output);

// Work directories with stable names (kept for --resume) carry a marker file; one without it is
// the user's and is refused. Creates the directory (with its marker) when it does not exist.
Status claimWorkDirectory(const std::string& path);
bool isWorkDirectory(const std::string& path);

// Held while a run writes into its work directory (an advisory lock on a file in it), so that a
// second run on the same output, another job or the same command started twice, is refused
// instead of mixing its files with the first one's. Released when destroyed.
class WorkLock {
 public:
  WorkLock() = default;
  explicit WorkLock(int fd) : fd_(fd) {}
  WorkLock(WorkLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  WorkLock& operator=(WorkLock&& other) noexcept;
  WorkLock(const WorkLock&) = delete;
  WorkLock& operator=(const WorkLock&) = delete;
  ~WorkLock();

 private:
  int fd_ = -1;
};
// Locks the work directory `path` (claimed first), or says which process holds it.
Result<WorkLock> lockWorkDirectory(const std::string& path);
// Whether a run holds the lock of work directory `path` now (creates nothing).
bool workDirectoryLocked(const std::string& path);

// Recognisers the kinds are made of.
bool fileStartsWith(const std::string& path, std::string_view prefix);
// Every entry below `directory` (recursively, by its path relative to it, '/'-separated) is
// accepted by `accept`; `isDirectory` tells what the entry is.
bool directoryHoldsOnly(
    const std::string& directory,
    const std::function<bool(const std::string& relative, bool isDirectory)>& accept);

}  // namespace lodforge
