// Sizes and counts on the command line: "2G", "512M", "1.5K", "100M". Byte sizes use binary
// multiples (K = 1024); counts use decimal ones (K = 1000), as users write "100M triangles".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace lodforge {

// "512M", "2GiB", "1.5K" (binary multiples, rounded to the byte).
std::optional<std::uint64_t> parseByteSize(std::string_view text);
// "10K", "2.5M", "1000" (decimal multiples); a value that is not whole ("1.5") is refused.
std::optional<std::uint64_t> parseCount(std::string_view text);

// "1.5 GiB", "312 KiB", "17 B".
std::string formatBytes(std::uint64_t bytes);
// "1,234,567".
std::string formatCount(std::uint64_t count);

}  // namespace lodforge
