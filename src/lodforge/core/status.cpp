#include "lodforge/core/status.h"

#include <cerrno>
#include <cstring>

namespace lodforge {

Error ioErrorFromErrno(std::string_view file, std::string_view action) {
  const int code = errno;
  return {ErrorKind::kIo, fmt::format("{}: cannot {}: {}", file, action, std::strerror(code))};
}

int exitCodeFor(const Status& status) {
  if (status.ok()) return 0;
  switch (status.kind()) {
    case ErrorKind::kBadInput:
    case ErrorKind::kUsage:
    case ErrorKind::kUnsupported:
      return 2;
    default:
      return 1;
  }
}

}  // namespace lodforge
