// LAZ item codecs: each decodes one part of a point record (POINT10, GPSTIME11, RGB12, …) from
// the arithmetic-coded stream, predicting from the records before it. Point-wise items (versions
// 1 and 2, LASzip's compressors 1 and 2) share one stream per chunk and decode field after field;
// layered items (version 3, compressor 3, LAS 1.4 formats 6–10) keep each field group in a layer
// of its own, and switch their contexts with the point's scanner channel.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lodforge/io/points/laz/laz_arith.h"
#include "lodforge/io/points/laz/laz_vlr.h"

namespace lodforge {

class LazPointwiseItem {
 public:
  virtual ~LazPointwiseItem() = default;
  // A chunk begins: models are reset and `first` (the chunk's first record, stored raw) is the
  // prediction for the second.
  virtual void start(const std::byte* first) = 0;
  virtual void read(LazDecoder& dec, std::byte* out) = 0;
};

// A layered item's chunk: its layers' sizes follow the chunk's first record, then their bytes.
class LazLayeredItem {
 public:
  virtual ~LazLayeredItem() = default;
  virtual std::size_t layerCount() const = 0;
  // `layers` holds this item's layers (an empty span: the field does not change in the chunk).
  // The POINT14 item sets `context` (the scanner channel); the others follow it.
  virtual void start(const std::byte* first, std::span<const std::span<const std::byte>> layers,
                     std::uint32_t& context) = 0;
  virtual void read(std::byte* out, std::uint32_t& context) = 0;
  virtual bool damaged() const = 0;  // a layer ran past its bytes or decoded a value out of range
};

// Null when the item's type and version are not a point-wise codec.
std::unique_ptr<LazPointwiseItem> makePointwiseItemV1(const LazItem& item);
std::unique_ptr<LazPointwiseItem> makePointwiseItemV2(const LazItem& item);
std::unique_ptr<LazLayeredItem> makeLayeredItem(const LazItem& item);

// Shared by the item codecs --------------------------------------------------------------------

// The median of the last five values, kept sorted incrementally (LAZ's x/y difference predictor).
class LazMedian5 {
 public:
  void reset() {
    values_ = {};
    high_ = true;
  }
  void add(std::int32_t v);
  std::int32_t get() const { return values_[2]; }

 private:
  std::array<std::int32_t, 5> values_{};
  bool high_ = true;
};

// Contexts from return r of n returns, for the POINT10 codec (8×8: some writers start counting at
// 0 or swap r and n, so every pair has a context).
std::uint32_t lazReturnMap(std::uint32_t n, std::uint32_t r);
inline std::uint32_t lazReturnLevel(std::uint32_t n, std::uint32_t r) {
  return n > r ? n - r : r - n;
}

// The RGB prediction shared by RGB12 v2 and RGB14 v3: which bytes changed (a 128-symbol model),
// then each changed byte as a difference folded to a byte, green and blue predicted from red's
// change.
struct LazRgbModels {
  LazSymbolModel used{128};
  std::array<LazSymbolModel, 6> diff{LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256),
                                     LazSymbolModel(256), LazSymbolModel(256), LazSymbolModel(256)};
  void reset();
};
void lazDecodeRgb(LazDecoder& dec, LazRgbModels& models, const std::uint16_t* last,
                  std::uint16_t* out);

// A model made on first use (LASzip makes context models lazily; a new one is what a reset one
// would be, so dropping them resets them).
inline LazSymbolModel& lazModelOnUse(std::unique_ptr<LazSymbolModel>& model,
                                     std::uint32_t symbols) {
  if (!model) model = std::make_unique<LazSymbolModel>(symbols);
  return *model;
}
// A byte coded with a 256-symbol model chosen by its previous value (POINT10's flags, class and
// user data in versions 1 and 2).
inline std::uint8_t lazDecodeByteByLast(LazDecoder& dec,
                                        std::array<std::unique_ptr<LazSymbolModel>, 256>& models,
                                        std::uint8_t last) {
  return static_cast<std::uint8_t>(dec.decodeSymbol(lazModelOnUse(models[last], 256)));
}

inline std::uint8_t lazFold(std::int32_t v) {
  return static_cast<std::uint8_t>(v);  // the format's U8_FOLD: modulo 256
}
inline std::int32_t lazClampByte(std::int32_t v) {
  return v < 0 ? 0 : v > 255 ? 255 : v;
}
inline std::int32_t lazWrapAdd(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}
inline std::int32_t lazWrapMul(std::int32_t a, std::int32_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) * static_cast<std::uint32_t>(b));
}

}  // namespace lodforge

namespace lodforge {

// The GPS time codec of GPSTIME11 v2 and of POINT14 v3's time layer (`layered`).
class LazGpsTimeCodec {
 public:
  explicit LazGpsTimeCodec(bool layered);
  void reset(std::uint64_t first);  // the first record's time, as bits
  std::uint64_t decode(LazDecoder& dec);

 private:
  bool decodeOne(LazDecoder& dec);
  std::int32_t multipleDiff(LazDecoder& dec, std::uint32_t multi);
  void readFull(LazDecoder& dec);

  bool layered_;
  std::uint32_t last_ = 0, next_ = 0;
  std::array<std::uint64_t, 4> times_{};  // the doubles' bits, added to as integers
  std::array<std::int32_t, 4> diffs_{}, extremes_{};
  LazSymbolModel multiModel_, zeroDiffModel_;
  LazIntegerDecoder ic_{32, 9};
};

// WAVEPACKET13 v1 and WAVEPACKET14 v3: the descriptor index, the data offset (same, after the
// last packet, a 32-bit step or in full), then size, return point and x/y/z each from the last.
// `last` is the previous record after its index byte (28 bytes), updated.
struct LazWavePacketCodec {
  std::int32_t lastOffsetDiff = 0;
  std::uint32_t offsetCase = 0;
  LazSymbolModel packetIndex{256};
  std::array<LazSymbolModel, 4> offsetCases{LazSymbolModel(4), LazSymbolModel(4), LazSymbolModel(4),
                                            LazSymbolModel(4)};
  LazIntegerDecoder offsetDiff{32}, packetSize{32}, returnPoint{32}, xyz{32, 3};

  void reset();
  void decode(LazDecoder& dec, std::uint8_t* last, std::byte* out);
};

}  // namespace lodforge
