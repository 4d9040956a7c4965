#include "lodforge/core/output_claim.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <vector>

namespace lodforge {

namespace fs = std::filesystem;

namespace {

constexpr const char* kWorkMarker = ".lodforge-work";
constexpr const char* kWorkLock = ".lodforge-lock";

// `inner` is `outer` itself or lies below it (both resolved through links and "..").
bool isWithin(const std::string& inner, const std::string& outer) {
  std::error_code error;
  const fs::path a = fs::weakly_canonical(inner, error);
  if (error) return false;
  const fs::path b = fs::weakly_canonical(outer, error);
  if (error) return false;
  auto ia = a.begin();
  for (auto ib = b.begin(); ib != b.end(); ++ib, ++ia) {
    if (ib->empty()) continue;  // a trailing separator
    if (ia == a.end() || *ia != *ib) return false;
  }
  return true;
}

bool isEmpty(const std::string& path, bool directory) {
  std::error_code error;
  if (directory) return fs::is_empty(path, error) && !error;
  return fs::file_size(path, error) == 0 && !error;
}

Status refuseInputs(const std::string& output, const OutputKind& kind,
                    std::span<const std::string> inputs) {
  for (const std::string& input : inputs) {
    LODFORGE_TRY(checkInputPath(input));
    std::error_code error;
    if (fs::exists(output, error) && fs::equivalent(output, input, error))
      return Error{ErrorKind::kUsage,
                   fmt::format("{}: is the input; choose another output", output)};
    if (kind.directory && isWithin(input, output))
      return Error{
          ErrorKind::kUsage,
          fmt::format("{}: holds the input {}; choose another output directory", output, input)};
  }
  return {};
}

Status refuseForeign(const std::string& output, const OutputKind& kind) {
  std::error_code error;
  const fs::file_type type = fs::status(output, error).type();
  if (error || type == fs::file_type::not_found) return {};
  const bool directory = type == fs::file_type::directory;
  if (kind.directory && !directory)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: exists and is not a directory; {} is written as a directory, so "
                             "choose another output",
                             output, kind.name)};
  if (!kind.directory && directory)
    return Error{ErrorKind::kUsage, fmt::format("{}: is a directory; give the name of {} to write",
                                                output, kind.name)};
  if (!kind.directory && type != fs::file_type::regular)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: exists and is not a regular file; not replacing it", output)};
  if (isEmpty(output, directory) || (kind.isOwn && kind.isOwn(output))) return {};
  return Error{ErrorKind::kUsage,
               fmt::format("{}: exists and is not {} that lodforge wrote; not replacing it (move "
                           "it away or choose another output)",
                           output, kind.name)};
}

Status checkWritableParent(const std::string& output) {
  fs::path parent = fs::path(output).parent_path();
  if (parent.empty()) parent = ".";
  std::error_code error;
  fs::create_directories(parent, error);
  if (error)
    return Error{ErrorKind::kIo, fmt::format("{}: cannot create the directory {}: {}", output,
                                             parent.string(), error.message())};
  if (!fs::is_directory(parent, error))
    return Error{ErrorKind::kIo, fmt::format("{}: {} is not a directory", output, parent.string())};
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    const int code = errno;
    return Error{ErrorKind::kIo, fmt::format("{}: cannot write in {}: {}", output, parent.string(),
                                             std::strerror(code))};
  }
  return {};
}

}  // namespace

Status checkInputPath(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return ioErrorFromErrno(path, "stat");
  return refuseDirectoryInput(path);
}

Status refuseDirectoryInput(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
    return Error{ErrorKind::kBadInput, fmt::format("{}: is a directory; give a file", path)};
  return {};
}

Status claimOutput(const std::string& output, const OutputKind& kind,
                   std::span<const std::string> inputs) {
  LODFORGE_TRY(refuseInputs(output, kind, inputs));
  LODFORGE_TRY(refuseForeign(output, kind));
  LODFORGE_TRY(checkWritableParent(output));
  removeDeadLeftovers(output);
  return {};
}

std::optional<int> leftoverProcess(std::string_view name, std::string_view output) {
  if (!name.starts_with(output) || name.size() <= output.size() || name[output.size()] != '.')
    return std::nullopt;
  std::string_view rest = name.substr(output.size() + 1);
  if (rest.starts_with("work.")) rest.remove_prefix(5);
  if (!rest.starts_with("tmp-")) return std::nullopt;
  rest.remove_prefix(4);
  int pid = 0;
  const auto [afterPid, error] = std::from_chars(rest.data(), rest.data() + rest.size(), pid);
  if (error != std::errc() || pid <= 0 || afterPid == rest.data() + rest.size() || *afterPid != '-')
    return std::nullopt;
  const char* n = afterPid + 1;
  const char* end = rest.data() + rest.size();
  if (n == end || !std::isdigit(static_cast<unsigned char>(*n))) return std::nullopt;
  while (n != end && std::isdigit(static_cast<unsigned char>(*n))) ++n;
  if (n != end && *n != '.') return std::nullopt;
  return pid;
}

std::size_t removeDeadLeftovers(const std::string& output) {
  fs::path path(output);
  while (!path.empty() && path.filename().empty()) path = path.parent_path();  // "dir/"
  const std::string base = path.filename().string();
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code error;
  std::vector<fs::path> dead;
  for (fs::directory_iterator it(parent, error), end; !error && it != end; it.increment(error)) {
    const std::optional<int> pid = leftoverProcess(it->path().filename().string(), base);
    // kill(pid, 0) fails with ESRCH only when no such process runs (EPERM: it runs, not ours).
    if (pid && *pid != ::getpid() && ::kill(*pid, 0) != 0 && errno == ESRCH)
      dead.push_back(it->path());
  }
  std::size_t removed = 0;
  for (const fs::path& p : dead) removed += fs::remove_all(p, error) > 0 ? 1u : 0u;
  return removed;
}

bool isWorkDirectory(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(fs::path(path) / kWorkMarker, error);
}

Status claimWorkDirectory(const std::string& path) {
  std::error_code error;
  if (fs::exists(path, error)) {
    if (isWorkDirectory(path)) return {};
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: exists and is not a work directory of lodforge; not touching "
                             "it (move it away or choose another output)",
                             path)};
  }
  fs::create_directories(path, error);
  if (error) return ioError(path, fmt::format("cannot create: {}", error.message()));
  const std::string marker = (fs::path(path) / kWorkMarker).string();
  const int fd = ::open(marker.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return ioErrorFromErrno(marker, "create");
  ::close(fd);
  return {};
}

WorkLock& WorkLock::operator=(WorkLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

WorkLock::~WorkLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

Result<WorkLock> lockWorkDirectory(const std::string& path) {
  const std::string file = (fs::path(path) / kWorkLock).string();
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return ioErrorFromErrno(file, "create");
  WorkLock lock(fd);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    // A file system without locks (NFS without lockd, Lustre mounted noflock): nothing to
    // guard with, the run goes on as runs did before they locked.
    if (errno == ENOLCK || errno == ENOSYS || errno == EOPNOTSUPP || errno == EINVAL) return lock;
    if (errno != EWOULDBLOCK) return ioErrorFromErrno(file, "lock");
    std::string holder(256, '\0');
    const ssize_t got = ::pread(fd, holder.data(), holder.size(), 0);
    holder.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: another lodforge run ({}) is writing this output; wait for it "
                             "or choose another output",
                             path, holder.empty() ? "unknown process" : holder)};
  }
  std::string host(256, '\0');
  if (::gethostname(host.data(), host.size() - 1) != 0) host.clear();
  const std::string holder = fmt::format("pid {} on {}", ::getpid(), host.c_str());
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, holder.data(), holder.size(), 0) < 0)
    return ioErrorFromErrno(file, "write");
  return lock;
}

bool workDirectoryLocked(const std::string& path) {
  const std::string file = (fs::path(path) / kWorkLock).string();
  const int fd = ::open(file.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return locked;
}

bool fileStartsWith(const std::string& path, std::string_view prefix) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  std::string head(prefix.size(), '\0');
  const ssize_t got = ::read(fd, head.data(), head.size());
  ::close(fd);
  return got == static_cast<ssize_t>(prefix.size()) && head == prefix;
}

bool directoryHoldsOnly(
    const std::string& directory,
    const std::function<bool(const std::string& relative, bool isDirectory)>& accept) {
  std::error_code error;
  fs::recursive_directory_iterator it(directory, error), end;
  if (error) return false;
  for (; it != end; it.increment(error)) {
    if (error) return false;
    const bool isDirectory = it->is_directory(error) && !it->is_symlink(error);
    const std::string relative =
        fs::path(it->path()).lexically_relative(directory).generic_string();
    if (!accept(relative, isDirectory)) return false;
  }
  return !error;
}

}  // namespace lodforge
