// Helpers shared by the tests: where the real data lives, scratch folders, bytes from strings.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

namespace lodforge::test {

// The folders of the shared real models (../shared/data) and of tests/data, compiled into
// test_support.cpp alone: the checkout's path in a define would make every test's object differ
// from clone to clone, and the compiler cache could reuse none of them.
const char* sharedDataDir();
const char* testDataDir();

// A real model from ../shared/data; the test fails (never skips) when it is missing.
inline std::string dataPath(std::string_view relative) {
  std::string path = std::string(sharedDataDir()) + "/" + std::string(relative);
  EXPECT_TRUE(std::filesystem::exists(path)) << "missing shared test data: " << path;
  return path;
}

inline std::string testDataPath(std::string_view relative) {
  return std::string(testDataDir()) + "/" + std::string(relative);
}

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "test";
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ = std::filesystem::temp_directory_path() /
            ("lodforge-" + std::to_string(::getpid()) + "-" + name);
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(std::string_view name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::span<const std::byte> bytesOf(std::string_view text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

// Whether any of `lines` (warnings, say) contains `what`.
inline bool anyContains(const std::vector<std::string>& lines, std::string_view what) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& line) { return line.find(what) != std::string::npos; });
}

inline void writeFile(const std::string& path, std::string_view contents) {
  std::ofstream out(path, std::ios::binary);
  out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Files left in a folder (to check that failed writes leave nothing behind).
inline std::vector<std::string> listFolder(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());  // directory order is arbitrary
  return names;
}

}  // namespace lodforge::test
