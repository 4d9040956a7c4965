// The text of a STEP file's strings (part names among them) is UTF-8 or STEP's own escapes;
// files from older CAD systems write a legacy 8-bit code page instead, which read as UTF-8
// turns every name into the same mojibake. This finds such strings and guesses the code page
// when their bytes make it clear.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "lodforge/core/status.h"

namespace lodforge {

struct StepStrings {
  std::uint64_t strings = 0;  // quoted strings in the file
  std::uint64_t notUtf8 = 0;  // of which are not valid UTF-8
  std::string example;        // the first of those, its bytes outside ASCII as \xNN
  std::string guess;          // OCCT's name of the code page they are in, or empty
};

// The file's strings, read once (a scan of its bytes, far quicker than OCCT's read).
Result<StepStrings> scanStepStrings(const std::string& path);
// The same over text in memory (tests).
StepStrings scanStepText(std::string_view text);

}  // namespace lodforge
