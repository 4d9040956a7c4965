// Point-wise LAZ items, version 2 (LASzip 2.x, the common case for LAS 1.0–1.3 formats 0–5), and
// the predictors shared with the other versions.
#include <cstring>

#include "lodforge/io/points/laz/laz_items.h"
#include "lodforge/io/points/laz/laz_point10.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

void LazMedian5::add(std::int32_t v) {
  auto& s = values_;
  if (high_) {  // the last insertion went high: this one shifts the upper part up
    if (v < s[2]) {
      s[4] = s[3];
      s[3] = s[2];
      if (v < s[0]) {
        s[2] = s[1];
        s[1] = s[0];
        s[0] = v;
      } else if (v < s[1]) {
        s[2] = s[1];
        s[1] = v;
      } else {
        s[2] = v;
      }
    } else {
      if (v < s[3]) {
        s[4] = s[3];
        s[3] = v;
      } else {
        s[4] = v;
      }
      high_ = false;
    }
  } else {
    if (s[2] < v) {
      s[0] = s[1];
      s[1] = s[2];
      if (s[4] < v) {
        s[2] = s[3];
        s[3] = s[4];
        s[4] = v;
      } else if (s[3] < v) {
        s[2] = s[3];
        s[3] = v;
      } else {
        s[2] = v;
      }
    } else {
      if (s[1] < v) {
        s[0] = s[1];
        s[1] = v;
      } else {
        s[0] = v;
      }
      high_ = true;
    }
  }
}

std::uint32_t lazReturnMap(std::uint32_t n, std::uint32_t r) {
  // Single, first, intermediate and last returns of up to 5 get their own contexts; the rest
  // share the outer ones (the LAZ specification's table).
  static constexpr std::uint8_t kMap[8][8] = {
      {15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
      {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
      {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
      {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
  return kMap[n & 7][r & 7];
}

void LazRgbModels::reset() {
  used.reset();
  for (LazSymbolModel& m : diff) m.reset();
}

void lazDecodeRgb(LazDecoder& dec, LazRgbModels& models, const std::uint16_t* last,
                  std::uint16_t* out) {
  const std::uint32_t used = dec.decodeSymbol(models.used);
  auto byteOf = [&](std::size_t model, std::int32_t predicted) {
    return static_cast<std::uint16_t>(
        lazFold(static_cast<std::int32_t>(dec.decodeSymbol(models.diff[model])) + predicted));
  };
  const std::int32_t lastLow[3] = {last[0] & 0xFF, last[1] & 0xFF, last[2] & 0xFF};
  const std::int32_t lastHigh[3] = {last[0] >> 8, last[1] >> 8, last[2] >> 8};
  std::uint16_t red = (used & 1) ? byteOf(0, lastLow[0]) : static_cast<std::uint16_t>(lastLow[0]);
  red |= static_cast<std::uint16_t>(((used & 2) ? byteOf(1, lastHigh[0]) : lastHigh[0]) << 8);
  out[0] = red;
  if (!(used & (1 << 6))) {  // grey: green and blue equal red
    out[1] = out[2] = red;
    return;
  }
  // Green and blue predicted from red's change (low bytes, then high bytes).
  std::int32_t diff = (red & 0xFF) - lastLow[0];
  std::uint16_t green = (used & 4) ? byteOf(2, lazClampByte(diff + lastLow[1]))
                                   : static_cast<std::uint16_t>(lastLow[1]);
  std::uint16_t blue = static_cast<std::uint16_t>(lastLow[2]);
  if (used & 16) {
    diff = (diff + ((green & 0xFF) - lastLow[1])) / 2;
    blue = byteOf(4, lazClampByte(diff + lastLow[2]));
  }
  diff = (red >> 8) - lastHigh[0];
  const std::int32_t greenHigh =
      (used & 8) ? byteOf(3, lazClampByte(diff + lastHigh[1])) : lastHigh[1];
  green = static_cast<std::uint16_t>(green | (greenHigh << 8));
  std::int32_t blueHigh = lastHigh[2];
  if (used & 32) {
    diff = (diff + (greenHigh - lastHigh[1])) / 2;
    blueHigh = byteOf(5, lazClampByte(diff + lastHigh[2]));
  }
  out[1] = green;
  out[2] = static_cast<std::uint16_t>(blue | (blueHigh << 8));
}

namespace {

// POINT10 v2: which fields changed (one symbol), each changed one from its own context, then x
// and y as differences predicted by the median of the last five per return context, z by the
// last z of the same return level.
class Point10V2 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override {
    last_ = LazPoint10::unpack(first);
    last_.intensity = 0;  // the codec starts intensities from zero
    for (std::size_t i = 0; i < 16; ++i) {
      xDiffs_[i].reset();
      yDiffs_[i].reset();
      lastIntensity_[i] = 0;
      lastHeight_[i / 2] = 0;
    }
    changed_.reset();
    intensity_.reset();
    scanAngle_[0].reset();
    scanAngle_[1].reset();
    pointSource_.reset();
    // Models made on first use are dropped: a new one is what a reset one would be.
    for (auto* models : {&flagModels_, &classModels_, &userModels_})
      for (auto& m : *models) m.reset();
    dx_.reset();
    dy_.reset();
    z_.reset();
  }

  void read(LazDecoder& dec, std::byte* out) override {
    const std::uint32_t changed = dec.decodeSymbol(changed_);
    if (changed & 32) last_.flags = lazDecodeByteByLast(dec, flagModels_, last_.flags);
    const std::uint32_t r = last_.returnNumber(), n = last_.numberOfReturns();
    const std::uint32_t m = lazReturnMap(n, r), l = lazReturnLevel(n, r);
    if (changed & 16) {
      last_.intensity =
          static_cast<std::uint16_t>(intensity_.decode(dec, lastIntensity_[m], m < 3 ? m : 3));
      lastIntensity_[m] = last_.intensity;
    } else {
      last_.intensity = lastIntensity_[m];
    }
    if (changed & 8)
      last_.classification = lazDecodeByteByLast(dec, classModels_, last_.classification);
    if (changed & 4) {
      const std::uint32_t delta = dec.decodeSymbol(scanAngle_[last_.scanDirection()]);
      last_.scanAngle = lazFold(static_cast<std::int32_t>(delta + last_.scanAngle));
    }
    if (changed & 2) last_.userData = lazDecodeByteByLast(dec, userModels_, last_.userData);
    if (changed & 1)
      last_.pointSource = static_cast<std::uint16_t>(pointSource_.decode(dec, last_.pointSource));
    readCoordinates(dec, m, l, n);
    last_.pack(out);
  }

 private:
  void readCoordinates(LazDecoder& dec, std::uint32_t m, std::uint32_t l, std::uint32_t n) {
    const std::uint32_t single = n == 1 ? 1 : 0;
    std::int32_t diff = dx_.decode(dec, xDiffs_[m].get(), single);
    last_.x = lazWrapAdd(last_.x, diff);
    xDiffs_[m].add(diff);
    std::uint32_t k = dx_.k();
    diff = dy_.decode(dec, yDiffs_[m].get(), single + (k < 20 ? (k & ~1u) : 20));
    last_.y = lazWrapAdd(last_.y, diff);
    yDiffs_[m].add(diff);
    k = (dx_.k() + dy_.k()) / 2;
    last_.z = z_.decode(dec, lastHeight_[l], single + (k < 18 ? (k & ~1u) : 18));
    lastHeight_[l] = last_.z;
  }

  LazPoint10 last_;
  std::array<LazMedian5, 16> xDiffs_, yDiffs_;
  std::array<std::uint16_t, 16> lastIntensity_{};
  std::array<std::int32_t, 8> lastHeight_{};
  LazSymbolModel changed_{64};
  LazIntegerDecoder intensity_{16, 4};
  std::array<LazSymbolModel, 2> scanAngle_{LazSymbolModel(256), LazSymbolModel(256)};
  LazIntegerDecoder pointSource_{16};
  std::array<std::unique_ptr<LazSymbolModel>, 256> flagModels_, classModels_, userModels_;
  LazIntegerDecoder dx_{32, 2}, dy_{32, 22}, z_{32, 20};
};

}  // namespace

// GPSTIME11 v2 (and, with its codes shifted, POINT14 v3's GPS time layer): up to four time
// sequences (multi-return pulses interleave); each time is its sequence's last plus a multiple
// of its last difference, a new difference, or a full value.
namespace {
constexpr std::int32_t kMulti = 500, kMultiMinus = -10;
constexpr std::uint32_t kUnchanged = kMulti - kMultiMinus + 1;  // 511
constexpr std::uint32_t kCodeFull = kMulti - kMultiMinus + 2;   // 512 (511 in v3)
}  // namespace

LazGpsTimeCodec::LazGpsTimeCodec(bool layered)
    : layered_(layered),
      multiModel_(layered ? kCodeFull + 3 : kCodeFull + 4),
      zeroDiffModel_(layered ? 5 : 6) {}

void LazGpsTimeCodec::reset(std::uint64_t first) {
  last_ = next_ = 0;
  times_ = {first, 0, 0, 0};
  diffs_ = {};
  extremes_ = {};
  multiModel_.reset();
  zeroDiffModel_.reset();
  ic_.reset();
}

std::uint64_t LazGpsTimeCodec::decode(LazDecoder& dec) {
  // A switch to another sequence is followed by that sequence's own code; a damaged stream
  // could switch forever, so the switches are bounded.
  for (int switches = 0; switches < 4 && decodeOne(dec); ++switches) {
  }
  return times_[last_];
}

// One code; true when it only switched sequence. Version 3 drops version 2's "unchanged" codes
// (it stores whether the time changed elsewhere), so its symbols are mapped onto version 2's.
bool LazGpsTimeCodec::decodeOne(LazDecoder& dec) {
  if (diffs_[last_] == 0) {
    const std::uint32_t multi = dec.decodeSymbol(zeroDiffModel_) + (layered_ ? 1 : 0);
    if (multi == 1) {  // a 32-bit difference
      diffs_[last_] = ic_.decode(dec, 0, 0);
      times_[last_] += static_cast<std::uint64_t>(static_cast<std::int64_t>(diffs_[last_]));
      extremes_[last_] = 0;
    } else if (multi == 2) {
      readFull(dec);
    } else if (multi > 2) {
      last_ = (last_ + multi - 2) & 3;
      return true;
    }
    return false;
  }
  std::uint32_t multi = dec.decodeSymbol(multiModel_);
  if (layered_ && multi >= kUnchanged) ++multi;
  if (multi == 1) {
    times_[last_] +=
        static_cast<std::uint64_t>(static_cast<std::int64_t>(ic_.decode(dec, diffs_[last_], 1)));
    extremes_[last_] = 0;
  } else if (multi < kUnchanged) {
    times_[last_] +=
        static_cast<std::uint64_t>(static_cast<std::int64_t>(multipleDiff(dec, multi)));
  } else if (multi == kCodeFull) {
    readFull(dec);
  } else if (multi > kCodeFull) {
    last_ = (last_ + multi - kCodeFull) & 3;
    return true;
  }
  return false;
}

std::int32_t LazGpsTimeCodec::multipleDiff(LazDecoder& dec, std::uint32_t multi) {
  std::int32_t& diff = diffs_[last_];
  std::int32_t value = 0;
  bool extreme = false;
  if (multi == 0) {
    value = ic_.decode(dec, 0, 7);
    extreme = true;
  } else if (multi < static_cast<std::uint32_t>(kMulti)) {
    value = ic_.decode(dec, lazWrapMul(static_cast<std::int32_t>(multi), diff), multi < 10 ? 2 : 3);
  } else if (multi == static_cast<std::uint32_t>(kMulti)) {
    value = ic_.decode(dec, lazWrapMul(kMulti, diff), 4);
    extreme = true;
  } else {
    const std::int32_t negative = kMulti - static_cast<std::int32_t>(multi);
    if (negative > kMultiMinus) {
      value = ic_.decode(dec, lazWrapMul(negative, diff), 5);
    } else {
      value = ic_.decode(dec, lazWrapMul(kMultiMinus, diff), 6);
      extreme = true;
    }
  }
  // Extreme multiples replace the sequence's difference after they repeat.
  if (extreme && ++extremes_[last_] > 3) {
    diff = value;
    extremes_[last_] = 0;
  }
  return value;
}

void LazGpsTimeCodec::readFull(LazDecoder& dec) {
  next_ = (next_ + 1) & 3;
  const auto high = static_cast<std::uint32_t>(
      ic_.decode(dec, static_cast<std::int32_t>(times_[last_] >> 32), 8));
  times_[next_] = (std::uint64_t{high} << 32) | dec.readInt();
  last_ = next_;
  diffs_[last_] = 0;
  extremes_[last_] = 0;
}

namespace {

class GpsTimeV2 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override { codec_.reset(loadField<std::uint64_t>(first)); }
  void read(LazDecoder& dec, std::byte* out) override {
    const std::uint64_t time = codec_.decode(dec);
    std::memcpy(out, &time, 8);
  }

 private:
  LazGpsTimeCodec codec_{false};
};

class Rgb12V2 final : public LazPointwiseItem {
 public:
  void start(const std::byte* first) override {
    std::memcpy(last_, first, 6);
    models_.reset();
  }
  void read(LazDecoder& dec, std::byte* out) override {
    std::uint16_t rgb[3];
    lazDecodeRgb(dec, models_, last_, rgb);
    std::memcpy(last_, rgb, 6);
    std::memcpy(out, rgb, 6);
  }

 private:
  std::uint16_t last_[3] = {};
  LazRgbModels models_;
};

// BYTE v2 (extra bytes): each byte as a difference to the last, one model per byte position.
class ByteV2 final : public LazPointwiseItem {
 public:
  explicit ByteV2(std::size_t count) : last_(count) {
    models_.reserve(count);
    for (std::size_t i = 0; i < count; ++i) models_.emplace_back(256);
  }
  void start(const std::byte* first) override {
    std::memcpy(last_.data(), first, last_.size());
    for (LazSymbolModel& m : models_) m.reset();
  }
  void read(LazDecoder& dec, std::byte* out) override {
    for (std::size_t i = 0; i < last_.size(); ++i) {
      last_[i] = lazFold(static_cast<std::int32_t>(last_[i] + dec.decodeSymbol(models_[i])));
      out[i] = static_cast<std::byte>(last_[i]);
    }
  }

 private:
  std::vector<std::uint8_t> last_;
  std::vector<LazSymbolModel> models_;
};

}  // namespace

std::unique_ptr<LazPointwiseItem> makePointwiseItemV2(const LazItem& item) {
  if (item.version != 2) return nullptr;
  switch (item.type) {
    case 6:
      return std::make_unique<Point10V2>();
    case 7:
      return std::make_unique<GpsTimeV2>();
    case 8:
      return std::make_unique<Rgb12V2>();
    case 0:
      return std::make_unique<ByteV2>(item.size);
    default:
      return nullptr;
  }
}

}  // namespace lodforge
