#include "lodforge/io/cad/step_names.h"

#include <cstdio>
#include <vector>

#include <fmt/format.h>

#include "lodforge/core/file.h"

namespace lodforge {

namespace {

bool isHigh(unsigned char c) {
  return c >= 0x80;
}

// Valid UTF-8: each lead byte followed by its continuation bytes, no overlong two-byte form.
bool isUtf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t more = 0;
    if (c >= 0xC2 && c < 0xE0)
      more = 1;
    else if (c >= 0xE0 && c < 0xF0)
      more = 2;
    else if (c >= 0xF0 && c < 0xF5)
      more = 3;
    else if (c >= 0x80)
      return false;
    if (more > s.size() - i - 1) return false;
    for (std::size_t k = 1; k <= more; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += more + 1;
  }
  return true;
}

// Counts over the strings that are not UTF-8, for the guess.
struct HighBytes {
  std::uint64_t total = 0;    // bytes 0x80 and above
  std::uint64_t inRuns = 0;   // of which in runs of three or more (words of a non-Latin script)
  std::uint64_t letters = 0;  // of which letters in both CP1251 and CP1252 (0xC0-0xFF, Ё ё)
};

void countHighBytes(std::string_view s, HighBytes& high) {
  for (std::size_t i = 0; i < s.size();) {
    if (!isHigh(static_cast<unsigned char>(s[i]))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < s.size() && isHigh(static_cast<unsigned char>(s[end]))) ++end;
    high.total += end - i;
    if (end - i >= 3) high.inRuns += end - i;
    for (std::size_t k = i; k < end; ++k) {
      const auto c = static_cast<unsigned char>(s[k]);
      if (c >= 0xC0 || c == 0xA8 || c == 0xB8) ++high.letters;
    }
    i = end;
  }
}

// Cyrillic names are whole words of high bytes (CP1251); Western names have an accented letter
// here and there between ASCII ones (CP1252). Anything else is not clear enough to guess.
std::string guessCodePage(const HighBytes& high) {
  if (high.total == 0 || high.letters * 10 < high.total * 9) return {};
  if (high.inRuns * 10 >= high.total * 6) return "CP1251";
  if (high.inRuns == 0) return "CP1252";
  return {};
}

std::string shown(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 60)) {
    const auto u = static_cast<unsigned char>(c);
    out += u >= 0x20 && u < 0x7F ? std::string(1, c) : fmt::format("\\x{:02X}", u);
  }
  return out;
}

// The strings of a STEP file fed in pieces: '…' with '' for a quote, outside comments.
class Scanner {
 public:
  void feed(std::string_view bytes) {
    for (const char c : bytes) step(c);
  }
  StepStrings finish() {
    result_.guess = guessCodePage(high_);
    return result_;
  }

 private:
  void step(char c) {
    if (comment_) {
      comment_ = !(previous_ == '*' && c == '/');
    } else if (inString_) {
      if (quotePending_ && c != '\'') {
        endString();
        inString_ = false;
      } else if (quotePending_) {
        text_ += '\'';
        quotePending_ = false;
        previous_ = 0;
        return;
      } else if (c == '\'') {
        quotePending_ = true;
      } else {
        text_ += c;
      }
    } else if (c == '\'') {
      inString_ = true;
    } else if (previous_ == '/' && c == '*') {
      comment_ = true;
      c = 0;  // "/*/" does not close it
    }
    previous_ = c;
  }
  void endString() {
    ++result_.strings;
    quotePending_ = false;
    if (!isUtf8(text_)) {
      if (result_.notUtf8++ == 0) result_.example = shown(text_);
      countHighBytes(text_, high_);
    }
    text_.clear();
  }

  StepStrings result_;
  HighBytes high_;
  std::string text_;
  bool inString_ = false, quotePending_ = false, comment_ = false;
  char previous_ = 0;
};

}  // namespace

StepStrings scanStepText(std::string_view text) {
  Scanner scanner;
  scanner.feed(text);
  scanner.feed(" ");  // a string closed by the last byte ends
  return scanner.finish();
}

Result<StepStrings> scanStepStrings(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return ioErrorFromErrno(path, "open");
  Scanner scanner;
  std::vector<char> block(1 << 20);
  std::size_t got = 0;
  while ((got = std::fread(block.data(), 1, block.size(), file)) > 0)
    scanner.feed(std::string_view(block.data(), got));
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return ioError(path, "read failed");
  scanner.feed(" ");
  return scanner.finish();
}

}  // namespace lodforge
