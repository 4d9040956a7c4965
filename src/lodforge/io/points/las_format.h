// Sizes the LAS specification fixes (LAS 1.4 R15, §2.5–2.6), shared by the reader, the copier,
// the writer and the extra-bytes table.
#pragma once

#include <cstddef>

namespace lodforge::las {

constexpr std::size_t kVlrHeader = 54;         // a variable-length record's header
constexpr std::size_t kEvlrHeader = 60;        // an extended one's
constexpr std::size_t kExtraDescriptor = 192;  // one field's entry in the Extra Bytes record

}  // namespace lodforge::las
