// What every reader promises on any input: either a consistent Model, or a bad-input error
// whose message starts with the file name. Anything else (a crash, a hang, an internal error,
// an inconsistent model) is a finding.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge::fuzz {

// A reader's error must be bad input whose message starts with `prefix` (the file's name).
inline void checkError(const Error& error, const std::string& prefix) {
  if (error.kind != ErrorKind::kBadInput || error.message.rfind(prefix, 0) != 0) {
    std::fprintf(stderr, "unexpected error (kind %d): %s\n", static_cast<int>(error.kind),
                 error.message.c_str());
    std::abort();
  }
}

inline void check(const Result<Model>& result, const std::string& name) {
  if (result.ok()) {
    std::string why;
    if (!isConsistent(*result, &why)) {
      std::fprintf(stderr, "inconsistent model: %s\n", why.c_str());
      std::abort();
    }
    return;
  }
  const Error& error = result.error();
  if (error.kind != ErrorKind::kBadInput || error.message.rfind(name, 0) != 0) {
    std::fprintf(stderr, "unexpected error (kind %d): %s\n", static_cast<int>(error.kind),
                 error.message.c_str());
    std::abort();
  }
}

}  // namespace lodforge::fuzz
