// The one error type of lodforge. Caller bugs are asserts; bad input, I/O failures and
// cancellation travel as a Status (or a Result<T>) whose message names the file and position.
#pragma once

#include <cassert>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace lodforge {

enum class ErrorKind : std::uint8_t {
  kBadInput,     // the input is malformed or unsupported: exit code 2
  kUsage,        // the command line is wrong: exit code 2
  kIo,           // the system failed us (open, write, disk full): exit code 1
  kCancelled,    // the user interrupted: exit code 1
  kLimit,        // a memory or size limit would be exceeded: exit code 1
  kUnsupported,  // valid input this code path cannot take (callers may fall back): exit code 2
  kInternal,     // a bug we caught: exit code 1
};

struct Error {
  ErrorKind kind = ErrorKind::kInternal;
  std::string message;
};

// Thrown inside readers to unwind to their entry point, where it becomes a Status.
// Never crosses a public API boundary.
struct ErrorException {
  Error error;
};

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)) {}  // NOLINT: implicit on purpose

  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Error& error() const {
    assert(error_);
    return *error_;
  }
  ErrorKind kind() const { return error().kind; }
  const std::string& message() const { return error().message; }

 private:
  std::optional<Error> error_;
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}                             // NOLINT
  Result(Error error) : error_(std::move(error)) {}                         // NOLINT
  Result(Status status) : error_(status.error()) { assert(!status.ok()); }  // NOLINT

  bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  T& value() & {
    assert(value_);
    return *value_;
  }
  const T& value() const& {
    assert(value_);
    return *value_;
  }
  T&& value() && {
    assert(value_);
    return std::move(*value_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  const Error& error() const {
    assert(error_);
    return *error_;
  }
  Status status() const { return ok() ? Status() : Status(*error_); }

 private:
  std::optional<T> value_;
  std::optional<Error> error_;
};

// Bad input at a byte offset: "FILE: byte N: WHAT".
inline Error badInputAtByte(std::string_view file, std::uint64_t offset, std::string_view what) {
  return {ErrorKind::kBadInput, fmt::format("{}: byte {}: {}", file, offset, what)};
}
// Bad input at a line: "FILE:LINE: WHAT".
inline Error badInputAtLine(std::string_view file, std::uint64_t line, std::string_view what) {
  return {ErrorKind::kBadInput, fmt::format("{}:{}: {}", file, line, what)};
}
// Bad input where no finer position exists (a JSON path, an object): "FILE: WHAT".
inline Error badInput(std::string_view file, std::string_view what) {
  return {ErrorKind::kBadInput, fmt::format("{}: {}", file, what)};
}
inline Error ioError(std::string_view file, std::string_view what) {
  return {ErrorKind::kIo, fmt::format("{}: {}", file, what)};
}
Error ioErrorFromErrno(std::string_view file, std::string_view action);

// Exit code for the command line: 0 ok, 2 bad input or usage, 1 anything else.
int exitCodeFor(const Status& status);

}  // namespace lodforge

// Propagate a failed Status/Result from the current function. The variable gets a unique name
// so that uses nest (a lambda inside the expression may use it too).
#define LODFORGE_TRY(expr) \
  LODFORGE_TRY_NAMED_(expr, LODFORGE_CONCAT_(lodforge_status_, __COUNTER__))
#define LODFORGE_CONCAT_(a, b) LODFORGE_CONCAT2_(a, b)
#define LODFORGE_CONCAT2_(a, b) a##b
#define LODFORGE_TRY_NAMED_(expr, name)                                        \
  do {                                                                         \
    if (auto name = (expr); !name.ok()) return lodforge::Status(name.error()); \
  } while (false)
