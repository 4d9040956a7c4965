// Point-wise LAZ items, version 1 (files from LASzip 1.x): simpler predictors than version 2 —
// the median of three differences, integer-coded intensity and angle, one GPS time sequence.
#include <cstring>

#include "lodforge/io/points/laz/laz_items.h"
#include "lodforge/io/points/laz/laz_point10.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

std::int32_t medianOfThree(const std::array<std::int32_t, 3>& v) {
  if (v[0] < v[1]) return v[1] < v[2] ? v[1] : v[0] < v[2] ? v[2] : v[0];
  return v[0] < v[2] ? v[0] : v[1] < v[2] ? v[2] : v[1];
}

// POINT10 v1: coordinates first (x and y from the median of the last three differences, z from
// the last z), then which other fields changed.
class Point10V1 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override {
    last_ = LazPoint10::unpack(first);
    xDiffs_ = yDiffs_ = {};
    ring_ = 0;
    for (LazIntegerDecoder* ic : {&dx_, &dy_, &z_, &intensity_, &scanAngle_, &pointSource_})
      ic->reset();
    changed_.reset();
    // Models made on first use are dropped: a new one is what a reset one would be.
    for (auto* models : {&flagModels_, &classModels_, &userModels_})
      for (auto& m : *models) m.reset();
  }

  void read(LazDecoder& dec, std::byte* out) override {
    const std::int32_t xDiff = dx_.decode(dec, medianOfThree(xDiffs_));
    last_.x = lazWrapAdd(last_.x, xDiff);
    std::uint32_t k = dx_.k();  // the corrector's size picks the next contexts
    const std::int32_t yDiff = dy_.decode(dec, medianOfThree(yDiffs_), k < 19 ? k : 19);
    last_.y = lazWrapAdd(last_.y, yDiff);
    k = (k + dy_.k()) / 2;
    last_.z = z_.decode(dec, last_.z, k < 19 ? k : 19);
    const std::uint32_t changed = dec.decodeSymbol(changed_);
    if (changed & 32)
      last_.intensity = static_cast<std::uint16_t>(intensity_.decode(dec, last_.intensity));
    if (changed & 16) last_.flags = lazDecodeByteByLast(dec, flagModels_, last_.flags);
    if (changed & 8)
      last_.classification = lazDecodeByteByLast(dec, classModels_, last_.classification);
    if (changed & 4)
      last_.scanAngle = static_cast<std::uint8_t>(scanAngle_.decode(dec, last_.scanAngle, k < 3));
    if (changed & 2) last_.userData = lazDecodeByteByLast(dec, userModels_, last_.userData);
    if (changed & 1)
      last_.pointSource = static_cast<std::uint16_t>(pointSource_.decode(dec, last_.pointSource));
    xDiffs_[ring_] = xDiff;
    yDiffs_[ring_] = yDiff;
    ring_ = ring_ == 2 ? 0 : ring_ + 1;
    last_.pack(out);
  }

 private:
  LazPoint10 last_;
  std::array<std::int32_t, 3> xDiffs_{}, yDiffs_{};
  std::size_t ring_ = 0;
  LazIntegerDecoder dx_{32}, dy_{32, 20}, z_{32, 20};
  LazIntegerDecoder intensity_{16}, scanAngle_{8, 2}, pointSource_{16};
  LazSymbolModel changed_{64};
  std::array<std::unique_ptr<LazSymbolModel>, 256> flagModels_, classModels_, userModels_;
};

// GPSTIME11 v1: one sequence; the time is the last plus a multiple of the last difference, a
// new difference, or a full 64-bit value.
class GpsTimeV1 final : public LazPointwiseItem {
 public:
  static constexpr std::uint32_t kMultiMax = 512;

  void start(const std::byte* first) override {
    time_ = loadField<std::uint64_t>(first);
    diff_ = 0;
    extremes_ = 0;
    multiModel_.reset();
    zeroDiffModel_.reset();
    ic_.reset();
  }

  void read(LazDecoder& dec, std::byte* out) override {
    if (diff_ == 0) {
      const std::uint32_t multi = dec.decodeSymbol(zeroDiffModel_);
      if (multi == 1) {
        diff_ = ic_.decode(dec, 0, 0);
        time_ += static_cast<std::uint64_t>(static_cast<std::int64_t>(diff_));
      } else if (multi == 2) {
        time_ = dec.readInt64();
      }
    } else {
      const std::uint32_t multi = dec.decodeSymbol(multiModel_);
      if (multi < kMultiMax - 2) {
        time_ += static_cast<std::uint64_t>(static_cast<std::int64_t>(multipleDiff(dec, multi)));
      } else if (multi < kMultiMax - 1) {
        time_ = dec.readInt64();
      }
    }
    std::memcpy(out, &time_, 8);
  }

 private:
  std::int32_t multipleDiff(LazDecoder& dec, std::uint32_t multi) {
    const auto m = static_cast<std::int32_t>(multi);
    std::int32_t value = 0;
    bool extreme = false;
    if (multi == 1) {
      value = ic_.decode(dec, diff_, 1);
      diff_ = value;
      extremes_ = 0;
    } else if (multi == 0) {
      value = ic_.decode(dec, diff_ / 4, 2);
      extreme = true;
    } else if (multi < 10) {
      value = ic_.decode(dec, lazWrapMul(m, diff_), 3);
    } else if (multi < 50) {
      value = ic_.decode(dec, lazWrapMul(m, diff_), 4);
    } else {
      value = ic_.decode(dec, lazWrapMul(m, diff_), 5);
      extreme = multi == kMultiMax - 3;
    }
    if (extreme && ++extremes_ > 3) {  // repeated extremes become the new difference
      diff_ = value;
      extremes_ = 0;
    }
    return value;
  }

  std::uint64_t time_ = 0;  // the double's bits, added to as an integer
  std::int32_t diff_ = 0, extremes_ = 0;
  LazSymbolModel multiModel_{kMultiMax}, zeroDiffModel_{3};
  LazIntegerDecoder ic_{32, 6};
};

// RGB12 v1: which of the six bytes changed, each changed byte integer-coded from the last.
class Rgb12V1 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override {
    std::memcpy(last_, first, 6);
    used_.reset();
    ic_.reset();
  }
  void read(LazDecoder& dec, std::byte* out) override {
    const std::uint32_t used = dec.decodeSymbol(used_);
    for (std::uint32_t b = 0; b < 6; ++b) {
      if (used & (1u << b)) last_[b] = static_cast<std::uint8_t>(ic_.decode(dec, last_[b], b));
    }
    std::memcpy(out, last_, 6);
  }

 private:
  std::uint8_t last_[6] = {};  // little-endian: byte b is colour b/2, low byte first
  LazSymbolModel used_{64};
  LazIntegerDecoder ic_{8, 6};
};

class ByteV1 final : public LazPointwiseItem {
 public:
  explicit ByteV1(std::size_t count) : last_(count), ic_(8, static_cast<std::uint32_t>(count)) {}
  void start(const std::byte* first) override {
    std::memcpy(last_.data(), first, last_.size());
    ic_.reset();
  }
  void read(LazDecoder& dec, std::byte* out) override {
    for (std::size_t i = 0; i < last_.size(); ++i) {
      last_[i] =
          static_cast<std::uint8_t>(ic_.decode(dec, last_[i], static_cast<std::uint32_t>(i)));
      out[i] = static_cast<std::byte>(last_[i]);
    }
  }

 private:
  std::vector<std::uint8_t> last_;
  LazIntegerDecoder ic_;
};

class WavePacket13V1 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override {
    std::memcpy(last_, first + 1, sizeof last_);
    codec_.reset();
  }
  void read(LazDecoder& dec, std::byte* out) override { codec_.decode(dec, last_, out); }

 private:
  std::uint8_t last_[28] = {};
  LazWavePacketCodec codec_;
};

}  // namespace

void LazWavePacketCodec::reset() {
  lastOffsetDiff = 0;
  offsetCase = 0;
  packetIndex.reset();
  for (LazSymbolModel& m : offsetCases) m.reset();
  for (LazIntegerDecoder* ic : {&offsetDiff, &packetSize, &returnPoint, &xyz}) ic->reset();
}

void LazWavePacketCodec::decode(LazDecoder& dec, std::uint8_t* last, std::byte* out) {
  out[0] = static_cast<std::byte>(dec.decodeSymbol(packetIndex));
  const auto* l = reinterpret_cast<const std::byte*>(last);
  const auto lastOffset = loadField<std::uint64_t>(l);
  const auto lastSize = loadField<std::uint32_t>(l + 8);
  offsetCase = dec.decodeSymbol(offsetCases[offsetCase]);
  std::uint64_t offset = lastOffset;
  if (offsetCase == 1) {
    offset = lastOffset + lastSize;
  } else if (offsetCase == 2) {
    lastOffsetDiff = offsetDiff.decode(dec, lastOffsetDiff);
    offset = lastOffset + static_cast<std::uint64_t>(static_cast<std::int64_t>(lastOffsetDiff));
  } else if (offsetCase == 3) {
    offset = dec.readInt64();
  }
  const std::int32_t size = packetSize.decode(dec, static_cast<std::int32_t>(lastSize));
  std::int32_t fields[4];
  fields[0] = returnPoint.decode(dec, loadField<std::int32_t>(l + 12));
  for (std::uint32_t c = 0; c < 3; ++c)
    fields[1 + c] = xyz.decode(dec, loadField<std::int32_t>(l + 16 + 4 * c), c);
  std::memcpy(last, &offset, 8);
  std::memcpy(last + 8, &size, 4);
  std::memcpy(last + 12, fields, 16);
  std::memcpy(out + 1, last, 28);
}

std::unique_ptr<LazPointwiseItem> makePointwiseItemV1(const LazItem& item) {
  if (item.version != 1) return nullptr;
  switch (item.type) {
    case 6:
      return std::make_unique<Point10V1>();
    case 7:
      return std::make_unique<GpsTimeV1>();
    case 8:
      return std::make_unique<Rgb12V1>();
    case 9:
      return std::make_unique<WavePacket13V1>();
    case 0:
      return std::make_unique<ByteV1>(item.size);
    default:
      return nullptr;
  }
}

}  // namespace lodforge
