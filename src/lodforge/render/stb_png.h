// stb's PNG decoder and encoder (Debian's libstb-dev header), compiled in stb_png.cpp: the
// fuzzer's sanitizers then see inside the decoder, and nothing clashes with libstb's own copy.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace lodforge::stb {

// The header's size without decoding; false (with stb's reason) if it is not a readable PNG.
bool pngInfo(std::span<const std::byte> bytes, int& width, int& height, std::string& why);
// RGBA8 pixels; false (with stb's reason) on a decoding failure.
bool decodePng(std::span<const std::byte> bytes, int& width, int& height,
               std::vector<std::uint8_t>& rgba, std::string& why);
// Encoded bytes go to `sink` in pieces; false if encoding failed.
bool encodePng(const std::uint8_t* rgba, int width, int height,
               const std::function<void(const void*, int)>& sink);

}  // namespace lodforge::stb
