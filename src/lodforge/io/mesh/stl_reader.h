// STL reader, ascii and binary (detected from the size and the first bytes). STL stores a
// triangle soup; the reader welds bit-identical positions so the Model is an indexed mesh.
// Every ascii `solid` becomes an object; a binary file is one object.
#pragma once

#include <span>
#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

Result<Model> readStl(const std::string& path);
Result<Model> readStlFromMemory(std::span<const std::byte> bytes, const std::string& name);

}  // namespace lodforge
