// Checksums for our file formats (XXH3-64): fast enough to verify a package as it is read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace lodforge {

std::uint64_t checksum64(std::span<const std::byte> bytes);

// Incremental form, for data written or read in pieces.
class Checksum64 {
 public:
  Checksum64();
  ~Checksum64();
  Checksum64(const Checksum64&) = delete;
  Checksum64& operator=(const Checksum64&) = delete;
  void update(std::span<const std::byte> bytes);
  void update(const void* data, std::size_t size) {
    update({static_cast<const std::byte*>(data), size});
  }
  std::uint64_t digest() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
