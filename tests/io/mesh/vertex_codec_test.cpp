#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include "lodforge/io/mesh/vertex_codec.h"

namespace lodforge {
namespace {

// Data that exercises each group encoding: noise (raw), small steps (2- and 4-bit with and
// without escapes), constant bytes (all-zero groups) and a running sum that wraps.
std::vector<unsigned char> elements(std::size_t count, std::size_t stride, int kind,
                                    std::mt19937& rng) {
  std::vector<unsigned char> bytes(count * stride);
  int sum = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    switch (kind) {
      case 0:
        bytes[i] = static_cast<unsigned char>(rng());
        break;
      case 1:
        bytes[i] = static_cast<unsigned char>(i / stride + rng() % 3);
        break;
      case 2:
        bytes[i] = i % 4 == 0 ? static_cast<unsigned char>(rng() % 20) : 0;
        break;
      default:
        sum += static_cast<int>(rng() % 17) - 8;
        bytes[i] = static_cast<unsigned char>(sum);
    }
  }
  return bytes;
}

std::vector<unsigned char> encode(const std::vector<unsigned char>& bytes, std::size_t count,
                                  std::size_t stride) {
  // Not zeros: the writer's buffer is uninitialised, so every byte must be written.
  std::vector<std::byte> out(vertexAttributesBound(count, stride), std::byte{0xcd});
  out.resize(encodeVertexAttributes(out, bytes.data(), count, stride));
  std::vector<unsigned char> stream(out.size());
  std::memcpy(stream.data(), out.data(), out.size());
  return stream;
}

// meshoptimizer's decoder (the reference implementation of the extension) reads back every
// element; and since each group takes the smallest encoding, as meshoptimizer's encoder picks,
// the streams are the same bytes.
TEST(VertexCodec, MeshoptimizersDecoderReadsBackWhatItWrites) {
  std::mt19937 rng(7);
  int identical = 0;
  int cases = 0;
  for (const std::size_t stride : {4, 8, 12, 16, 20, 32, 64, 128, 256}) {
    for (const std::size_t count : {0, 1, 2, 15, 16, 17, 31, 255, 256, 257, 1000, 5000}) {
      for (int kind = 0; kind < 4; ++kind) {
        SCOPED_TRACE(testing::Message()
                     << "stride " << stride << ", " << count << " elements, kind " << kind);
        const std::vector<unsigned char> bytes = elements(count, stride, kind, rng);
        const std::vector<unsigned char> stream = encode(bytes, count, stride);
        ASSERT_LE(stream.size(), vertexAttributesBound(count, stride));
        std::vector<unsigned char> decoded(count * stride + 1, 0xcd);
        ASSERT_EQ(
            meshopt_decodeVertexBuffer(decoded.data(), count, stride, stream.data(), stream.size()),
            0);
        decoded.pop_back();
        ASSERT_EQ(decoded, bytes);
        std::vector<unsigned char> theirs(meshopt_encodeVertexBufferBound(count, stride));
        theirs.resize(
            meshopt_encodeVertexBuffer(theirs.data(), theirs.size(), bytes.data(), count, stride));
        EXPECT_LE(stream.size(), theirs.size());
        identical += stream == theirs ? 1 : 0;
        ++cases;
      }
    }
  }
  EXPECT_EQ(identical, cases);
}

// A damaged stream is refused by the decoder, so the test above would see a wrong one: one
// byte fewer, or not the attribute codec's header.
TEST(VertexCodec, TheDecoderRefusesAStreamCutShortOrWithoutItsHeader) {
  std::mt19937 rng(11);
  const std::vector<unsigned char> bytes = elements(300, 8, 3, rng);
  std::vector<unsigned char> stream = encode(bytes, 300, 8);
  std::vector<unsigned char> decoded(300 * 8);
  EXPECT_NE(meshopt_decodeVertexBuffer(decoded.data(), 300, 8, stream.data(), stream.size() - 1),
            0);
  stream[0] = 0x00;
  EXPECT_NE(meshopt_decodeVertexBuffer(decoded.data(), 300, 8, stream.data(), stream.size()), 0);
}

}  // namespace
}  // namespace lodforge
