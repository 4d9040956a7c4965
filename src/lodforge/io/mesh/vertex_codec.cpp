#include "lodforge/io/mesh/vertex_codec.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <cstring>

namespace lodforge {
namespace {

constexpr std::size_t kGroup = 16;       // byte deltas per group
constexpr std::size_t kTailBytes = 32;   // the baseline element, padded to at least this
constexpr unsigned char kHeader = 0xa0;  // mode 0, version 0
constexpr std::size_t kMaxStride = 256;

// Sixteen bytes, one group's deltas: the compiler's vector type keeps the per-byte work in
// one register (SSE2 here) without intrinsics.
using Bytes16 = unsigned char __attribute__((vector_size(16)));
using Signed16 = signed char __attribute__((vector_size(16)));

// Elements per attribute block (Appendix A): min((8192 / byteStride) & ~15, 256).
std::size_t blockElements(std::size_t stride) {
  return std::min<std::size_t>((8192 / stride) & ~(kGroup - 1), 256);
}

// How many of the group's 16 bytes are at least `floor`: a compare gives 0xff per byte; one bit
// of each, summed by a multiply into the top byte of each half (no popcount instruction in the
// baseline x86-64 this builds for).
unsigned countAtLeast(Bytes16 deltas, unsigned char floor) {
  const Bytes16 at = reinterpret_cast<Bytes16>(deltas >= floor) & 1;
  std::array<std::uint64_t, 2> halves;
  std::memcpy(halves.data(), &at, sizeof at);
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  return static_cast<unsigned>((halves[0] * kOnes >> 56) + (halves[1] * kOnes >> 56));
}

// Bytes 0, 2, 4 and 6 of `x` as one 32-bit value, in order.
std::uint32_t evenBytes(std::uint64_t x) {
  x = (x | x >> 8) & 0x0000ffff0000ffffull;
  return static_cast<std::uint32_t>(x | x >> 16);
}

// `Bits`-bit deltas packed most significant first, each at most the sentinel, then the bytes of
// those at the sentinel in order (Appendix A, "sentinel encoding"). The packing merges
// neighbouring bytes within 64-bit words.
template <int Bits>
unsigned char* packGroup(Bytes16 v, const unsigned char* deltas, unsigned escapes,
                         unsigned char* out) {
  constexpr unsigned char kSentinel = (1u << Bits) - 1;
  const Bytes16 capped = v < kSentinel ? v : kSentinel;
  std::array<std::uint64_t, 2> half;
  std::memcpy(half.data(), &capped, sizeof capped);
  for (std::uint64_t& x : half) x = (x << Bits | x >> 8) & 0x00ff00ff00ff00ffull;
  if constexpr (Bits == 4) {
    const std::array<std::uint32_t, 2> packed = {evenBytes(half[0]), evenBytes(half[1])};
    std::memcpy(out, packed.data(), 8);
  } else {
    for (std::uint64_t& x : half) x = (x << 4 | x >> 16) & 0x000000ff000000ffull;
    const std::array<unsigned char, 4> packed = {
        static_cast<unsigned char>(half[0]), static_cast<unsigned char>(half[0] >> 32),
        static_cast<unsigned char>(half[1]), static_cast<unsigned char>(half[1] >> 32)};
    std::memcpy(out, packed.data(), 4);
  }
  out += 2 * Bits;
  if (escapes == 0) return out;
  for (std::size_t i = 0; i < kGroup; ++i) {
    *out = deltas[i];
    out += deltas[i] >= kSentinel ? 1 : 0;
  }
  return out;
}

// One group: the smallest of all-zero (0 bytes), 2-bit (4 + escapes), 4-bit (8 + escapes) and
// raw (16); returns the end of what it wrote and sets `mode` to the header's 0–3.
unsigned char* encodeGroup(const unsigned char* deltas, unsigned char* out, unsigned& mode) {
  Bytes16 v;
  std::memcpy(&v, deltas, kGroup);
  const unsigned nonZero = countAtLeast(v, 1);
  if (nonZero == 0) {
    mode = 0;
    return out;
  }
  const unsigned twoBit = 4 + countAtLeast(v, 3);
  const unsigned fourBit = 8 + countAtLeast(v, 15);
  if (twoBit <= fourBit && twoBit < kGroup) {
    mode = 1;
    return packGroup<2>(v, deltas, twoBit - 4, out);
  }
  if (fourBit < kGroup) {
    mode = 2;
    return packGroup<4>(v, deltas, fourBit - 8, out);
  }
  mode = 3;
  std::memcpy(out, deltas, kGroup);
  return out + kGroup;
}

unsigned char zigzag(unsigned char delta) {
  const auto d = static_cast<signed char>(delta);
  return static_cast<unsigned char>((d * 2) ^ (d >> 7));
}

// Zigzag-coded byte deltas of a block against the element before each (the first against
// `last`), in element order: bytes[j] - bytes[j - stride], contiguous, so whole vectors at once.
void blockDeltas(const unsigned char* block, std::size_t bytes, std::size_t stride,
                 const unsigned char* last, unsigned char* deltas) {
  std::size_t j = 0;
  for (; j < std::min(stride, bytes); ++j)
    deltas[j] = zigzag(static_cast<unsigned char>(block[j] - last[j]));
  for (; j + kGroup <= bytes; j += kGroup) {
    Bytes16 now;
    Bytes16 before;
    std::memcpy(&now, block + j, kGroup);
    std::memcpy(&before, block + j - stride, kGroup);
    // Unsigned arithmetic wraps; the signed view only says which deltas are negative.
    const Bytes16 d = now - before;
    const Bytes16 negative = reinterpret_cast<Bytes16>(reinterpret_cast<Signed16>(d) < 0);
    const Bytes16 zigzag = (d + d) ^ negative;
    std::memcpy(deltas + j, &zigzag, kGroup);
  }
  for (; j < bytes; ++j)
    deltas[j] = zigzag(static_cast<unsigned char>(block[j] - block[j - stride]));
}

// Sixteen elements' bytes regrouped by byte: word `w` of each element (4 of its bytes) to lanes
// 4w … 4w + 3, 16 bytes each. Interleaving the 64 bytes' halves rotates each byte's address
// (element e, byte j: 4e + j) left by a bit; four times makes it 16j + e. SSE2 does each
// interleave in one instruction (it has no byte shuffle).
void transposeWords(const unsigned char* group, std::size_t stride, std::size_t w,
                    std::size_t laneBytes, unsigned char* lanes) {
  std::array<unsigned char, 4 * kGroup> words;
  for (std::size_t e = 0; e < kGroup; ++e)
    std::memcpy(words.data() + 4 * e, group + e * stride + 4 * w, 4);
  std::array<Bytes16, 4> v;
  std::memcpy(v.data(), words.data(), words.size());
  // The interleaves of two vectors' low and high halves (punpcklbw, punpckhbw); GCC 12 and
  // clang both take __builtin_shufflevector.
  const auto low = [](Bytes16 a, Bytes16 b) {
    return __builtin_shufflevector(a, b, 0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  };
  const auto high = [](Bytes16 a, Bytes16 b) {
    return __builtin_shufflevector(a, b, 8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15,
                                   31);
  };
  for (int stage = 0; stage < 4; ++stage)
    v = {low(v[0], v[2]), high(v[0], v[2]), low(v[1], v[3]), high(v[1], v[3])};
  for (std::size_t j = 0; j < 4; ++j) std::memcpy(lanes + (4 * w + j) * laneBytes, &v[j], kGroup);
}

// One attribute block: for each byte of the element, its header bits (2 per group, 4 groups a
// byte, least significant first) and then the groups.
unsigned char* encodeBlock(const unsigned char* block, std::size_t elements, std::size_t stride,
                           const unsigned char* last, unsigned char* out) {
  constexpr std::size_t kBlockBytes = 8192;  // at most, Appendix A's block size times the stride
  std::array<unsigned char, kBlockBytes> deltas;
  std::array<unsigned char, kBlockBytes> lanes;
  const std::size_t groups = (elements + kGroup - 1) / kGroup;
  const std::size_t laneBytes = groups * kGroup;
  blockDeltas(block, elements * stride, stride, last, deltas.data());
  // The last group's missing elements encode as zero deltas.
  std::memset(deltas.data() + elements * stride, 0, (laneBytes - elements) * stride);
  for (std::size_t g = 0; g < groups; ++g)
    for (std::size_t w = 0; w < stride / 4; ++w)
      transposeWords(deltas.data() + g * kGroup * stride, stride, w, laneBytes,
                     lanes.data() + g * kGroup);
  for (std::size_t k = 0; k < stride; ++k) {
    unsigned char* header = out;
    std::memset(header, 0, (groups + 3) / 4);
    out += (groups + 3) / 4;
    for (std::size_t g = 0; g < groups; ++g) {
      unsigned mode = 0;
      out = encodeGroup(lanes.data() + k * laneBytes + g * kGroup, out, mode);
      header[g / 4] = static_cast<unsigned char>(header[g / 4] | mode << (2 * (g % 4)));
    }
  }
  return out;
}

}  // namespace

std::size_t vertexAttributesBound(std::size_t count, std::size_t stride) {
  assert(stride > 0 && stride % 4 == 0 && stride <= kMaxStride);
  const std::size_t perBlock = blockElements(stride);
  const std::size_t blocks = (count + perBlock - 1) / perBlock;
  const std::size_t groups = (perBlock + kGroup - 1) / kGroup;
  const std::size_t blockBytes = stride * ((groups + 3) / 4 + groups * kGroup);
  return 1 + blocks * blockBytes + std::max(kTailBytes, stride);
}

std::size_t encodeVertexAttributes(std::span<std::byte> out, const void* data, std::size_t count,
                                   std::size_t stride) {
  assert(stride > 0 && stride % 4 == 0 && stride <= kMaxStride);
  assert(out.size() >= vertexAttributesBound(count, stride));
  const auto* bytes = static_cast<const unsigned char*>(data);
  auto* begin = reinterpret_cast<unsigned char*>(out.data());
  unsigned char* at = begin;
  *at++ = kHeader;
  // The baseline is the first element, so the first delta is zero.
  std::array<unsigned char, kMaxStride> baseline{};
  if (count > 0) std::memcpy(baseline.data(), bytes, stride);
  const std::size_t perBlock = blockElements(stride);
  const unsigned char* last = baseline.data();
  for (std::size_t first = 0; first < count; first += perBlock) {
    const std::size_t elements = std::min(perBlock, count - first);
    at = encodeBlock(bytes + first * stride, elements, stride, last, at);
    last = bytes + (first + elements - 1) * stride;
  }
  // The tail: padding, then the baseline in the stream's last `stride` bytes.
  const std::size_t tail = std::max(kTailBytes, stride);
  std::memset(at, 0, tail - stride);
  std::memcpy(at + tail - stride, baseline.data(), stride);
  at += tail;
  assert(static_cast<std::size_t>(at - begin) <= out.size());
  return static_cast<std::size_t>(at - begin);
}

}  // namespace lodforge
