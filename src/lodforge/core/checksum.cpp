#include "lodforge/core/checksum.h"

#include <xxhash.h>

namespace lodforge {

struct Checksum64::State {
  XXH3_state_t* xxh = XXH3_createState();
  ~State() { XXH3_freeState(xxh); }
};

std::uint64_t checksum64(std::span<const std::byte> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

Checksum64::Checksum64() : state_(std::make_unique<State>()) {
  XXH3_64bits_reset(state_->xxh);
}
Checksum64::~Checksum64() = default;
void Checksum64::update(std::span<const std::byte> bytes) {
  XXH3_64bits_update(state_->xxh, bytes.data(), bytes.size());
}
std::uint64_t Checksum64::digest() const {
  return XXH3_64bits_digest(state_->xxh);
}

}  // namespace lodforge
