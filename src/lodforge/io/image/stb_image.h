// stb's PNG, BMP and TGA decoders and PNG encoder (Debian's libstb-dev header), compiled in
// stb_image.cpp (callers pick the format by its signature, a TGA by its name): the
// fuzzers' sanitizers then see inside the decoder, and nothing clashes with libstb's own copy.
// (Its JPEG decoder is left out: the fuzzer found it reading past a Huffman table; JPEG goes
// through libjpeg-turbo, image_codec.h.)
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace lodforge::stb {

// The header's size and channel count without decoding; false (with stb's reason) if it is not
// a PNG stb can read.
bool imageInfo(std::span<const std::byte> bytes, int& width, int& height, int& channels,
               std::string& why);
// RGBA8 pixels of a PNG; false (with stb's reason) on a decoding failure.
bool decodeImage(std::span<const std::byte> bytes, int& width, int& height,
                 std::vector<std::uint8_t>& rgba, std::string& why);
// Encoded bytes go to `sink` in pieces; false if encoding failed.
bool encodePng(const std::uint8_t* rgba, int width, int height,
               const std::function<void(const void*, int)>& sink);

}  // namespace lodforge::stb
