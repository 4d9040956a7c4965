// STEP and IFC files are ISO 10303-21 exchange structures: text that starts with
// "ISO-10303-21;" and ends with "END-ISO-10303-21;". A file without its end was cut short (a
// half download, a full disk); OCCT and assimp read such a file's first entities without a
// word, so the end is checked here before they read it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/status.h"

namespace lodforge {

// Where a cut file stops.
struct Part21Cut {
  std::uint64_t bytes = 0;  // the file's size: the cut is there
  std::string lastEntity;   // the last entity it begins ("#4521"), if one is found near the end
};

// The cut of an exchange structure without its end; nothing for a whole one, and for a file
// that is not an exchange structure at all (an IFC-XML or zipped IFC: its reader judges it).
Result<std::optional<Part21Cut>> findPart21Cut(const std::string& path);

// A cut file is bad input naming the file and the byte it stops at (exit 2); with `salvage`
// it is read with a warning saying so (appended to `warnings`).
Status checkPart21Whole(const std::string& path, bool salvage, std::vector<std::string>* warnings);

}  // namespace lodforge
