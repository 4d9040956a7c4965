#include "lodforge/io/part21.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string_view>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/units.h"

namespace lodforge {

namespace {

constexpr std::string_view kStart = "ISO-10303-21;";
constexpr std::string_view kEnd = "END-ISO-10303-21;";
constexpr std::size_t kTail = 64 << 10;  // the end marker and the last entity lie in this

// `count` bytes of the file from `at`.
Result<std::string> readAt(std::FILE* file, const std::string& path, std::uint64_t at,
                           std::size_t count) {
  std::string bytes(count, '\0');
  if (std::fseek(file, static_cast<long>(at), SEEK_SET) != 0 ||
      std::fread(bytes.data(), 1, count, file) != count)
    return ioError(path, "read failed");
  return bytes;
}

// The text without trailing white space and comments ("/* … */").
std::string_view withoutTrailing(std::string_view text) {
  for (;;) {
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
      text.remove_suffix(1);
    if (!text.ends_with("*/")) return text;
    const std::size_t open = text.rfind("/*");
    if (open == std::string_view::npos) return text;
    text = text.substr(0, open);
  }
}

// The last "#123=" that starts a line's entity instance in `tail`.
std::string lastEntityIn(std::string_view tail) {
  for (std::size_t at = tail.rfind('#'); at != std::string_view::npos;
       at = at == 0 ? std::string_view::npos : tail.rfind('#', at - 1)) {
    std::size_t end = at + 1;
    while (end < tail.size() && std::isdigit(static_cast<unsigned char>(tail[end]))) ++end;
    std::size_t after = end;
    while (after < tail.size() && tail[after] == ' ') ++after;
    const bool starts = at == 0 || tail[at - 1] == '\n' || tail[at - 1] == ';';
    if (end > at + 1 && after < tail.size() && tail[after] == '=' && starts)
      return std::string(tail.substr(at, end - at));
  }
  return {};
}

}  // namespace

Result<std::optional<Part21Cut>> findPart21Cut(const std::string& path) {
  Result<std::uint64_t> size = fileSize(path);
  if (!size) return size.status();
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return ioErrorFromErrno(path, "open");
  const auto headCount = static_cast<std::size_t>(std::min<std::uint64_t>(*size, 256));
  const auto tailCount = static_cast<std::size_t>(std::min<std::uint64_t>(*size, kTail));
  Result<std::string> head = readAt(file, path, 0, headCount);
  Result<std::string> tail = head ? readAt(file, path, *size - tailCount, tailCount) : head;
  std::fclose(file);
  if (!tail) return tail.status();
  // A byte-order mark or white space may come first.
  std::string_view start = *head;
  if (start.starts_with("\xEF\xBB\xBF")) start.remove_prefix(3);
  while (!start.empty() && std::isspace(static_cast<unsigned char>(start.front())))
    start.remove_prefix(1);
  if (!start.starts_with(kStart)) return std::optional<Part21Cut>{};
  if (withoutTrailing(*tail).ends_with(kEnd)) return std::optional<Part21Cut>{};
  return std::optional<Part21Cut>{Part21Cut{*size, lastEntityIn(*tail)}};
}

Status checkPart21Whole(const std::string& path, bool salvage, std::vector<std::string>* warnings) {
  Result<std::optional<Part21Cut>> cut = findPart21Cut(path);
  if (!cut) return cut.status();
  if (!cut->has_value()) return {};
  const Part21Cut& at = **cut;
  const std::string where =
      at.lastEntity.empty() ? std::string() : fmt::format(", inside entity {}", at.lastEntity);
  if (!salvage)
    return badInputAtByte(path, at.bytes,
                          fmt::format("the file ends here{} without END-ISO-10303-21;: it is cut "
                                      "short (--salvage reads what it holds)",
                                      where));
  if (warnings)
    warnings->push_back(
        fmt::format("{}: cut short at byte {}{} (no END-ISO-10303-21;): read "
                    "the {} it holds; what came after is missing",
                    path, at.bytes, where, formatBytes(at.bytes)));
  return {};
}

}  // namespace lodforge
