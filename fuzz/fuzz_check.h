// What every reader promises on any input: either a consistent Model, or a bad-input error
// whose message starts with the file name. Anything else (a crash, a hang, an internal error,
// an inconsistent model) is a finding.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/point_batch.h"

namespace lodforge::fuzz {

// A reader's error must be bad input, or valid input it cannot take (both exit 2), whose message
// starts with `prefix` (the file's name).
inline void checkError(const Error& error, const std::string& prefix) {
  const bool refused = error.kind == ErrorKind::kBadInput || error.kind == ErrorKind::kUnsupported;
  if (!refused || error.message.rfind(prefix, 0) != 0) {
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
  checkError(result.error(), name);
}

// Reads a point reader to its end: every batch with matching attribute arrays, finite positions
// and unit normals, and `check(batch)` for what the reader promises besides; an error must be
// bad input whose message starts with `prefix`.
template <class Reader, class Check>
void readPoints(Reader& reader, const std::string& prefix, const Check& check) {
  PointBatch points;
  while (true) {
    Result<bool> more = reader.next(points);
    if (!more) return checkError(more.error(), prefix);
    if (!*more) return;
    if (!points.colors.empty() && points.colors.size() != points.size()) std::abort();
    if (!points.normals.empty() && points.normals.size() != points.size()) std::abort();
    for (const Vec3d& p : points.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
    for (const Vec3f& n : points.normals)
      if (std::abs(length(n) - 1) > 1e-3f) std::abort();
    check(points);
  }
}

}  // namespace lodforge::fuzz
