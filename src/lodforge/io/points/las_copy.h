// A LAS or LAZ file's points written as plain LAS: the header, the variable length records (the
// coordinate system among them) and LAS 1.4's extended records kept, the point records byte for
// byte as decoded and in file order. LASzip's record and COPC's records are dropped: they
// describe a compressed layout the copy no longer has.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"

namespace lodforge {

struct LasCopyReport {
  std::uint64_t points = 0;
  std::uint32_t recordsKept = 0, recordsDropped = 0;  // VLRs and EVLRs
};

// Writes `output` under a temporary name, renamed when complete; Ctrl-C stops it with nothing
// left.
Result<LasCopyReport> writeUncompressedLas(const std::string& input, const std::string& output);

}  // namespace lodforge
