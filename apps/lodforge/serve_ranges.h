// What `lodforge serve` answers to a Range request (RFC 9110 §14): the byte ranges of a file of a
// given size that can be served, each clamped to the file, or that none can (416).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace lodforge::cli {

// As cpp-httplib parses a Range header: (first, last) with -1 for a missing end, so (-1, n) is
// the last n bytes and (n, -1) everything from n.
using RequestedRange = std::pair<std::int64_t, std::int64_t>;

struct ServedRanges {
  bool satisfiable = true;
  // Absolute and inclusive, each inside [0, size): what goes out. Empty when satisfiable with
  // no range asked for (the whole file).
  std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges;
};

// A range whose first byte is past the end is dropped; a last byte past the end is clamped to
// it; a suffix longer than the file is the whole file. Nothing left: not satisfiable (416).
ServedRanges serveRanges(const std::vector<RequestedRange>& requested, std::uint64_t size);

}  // namespace lodforge::cli
