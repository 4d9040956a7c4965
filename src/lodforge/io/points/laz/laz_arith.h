// The entropy coder of LAZ (LASzip), decoding side: an adaptive arithmetic (range) decoder after
// Said's "Introduction to Arithmetic Coding" as the LAZ specification prescribes it, its adaptive
// bit and symbol models, and the integer decompressor that every LAZ item builds on (a symbol for
// the corrector's bit count k, then k bits: part modelled, part raw). Every constant and update
// rule here is part of the format: the decoder must adapt exactly as the encoder did.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lodforge {

class LazBitModel {
 public:
  LazBitModel() { reset(); }
  void reset();

 private:
  friend class LazDecoder;
  void update();
  std::uint32_t bit0Count_ = 0, bitCount_ = 0, bit0Probability_ = 0;
  std::uint32_t updateCycle_ = 0, untilUpdate_ = 0;
};

class LazSymbolModel {
 public:
  explicit LazSymbolModel(std::uint32_t symbols);
  void reset();
  std::uint32_t symbols() const { return symbols_; }

 private:
  friend class LazDecoder;
  void update();
  std::uint32_t symbols_, lastSymbol_;
  std::uint32_t tableShift_ = 0;  // models of more than 16 symbols search a table first
  std::uint32_t totalCount_ = 0, updateCycle_ = 0, untilUpdate_ = 0;
  std::vector<std::uint32_t> distribution_, counts_, table_;
};

// Decodes one arithmetic-coded byte stream. Reading past its end yields zeros and marks the
// stream overrun; a raw value out of its range marks it invalid: the caller reports either as a
// damaged chunk (the coder itself cannot tell good data from bad).
class LazDecoder {
 public:
  // Starts on `bytes`, reading the first four as the initial value.
  void start(std::span<const std::byte> bytes);
  std::uint32_t decodeBit(LazBitModel& m);
  std::uint32_t decodeSymbol(LazSymbolModel& m);
  std::uint32_t readBits(std::uint32_t bits);  // 1..32 raw bits
  std::uint32_t readShort();
  std::uint32_t readInt();
  std::uint64_t readInt64();

  bool overrun() const { return overrun_; }
  bool invalid() const { return invalid_; }
  std::size_t consumed() const { return static_cast<std::size_t>(at_ - begin_); }

 private:
  std::uint32_t nextByte();
  void renormalize();
  std::uint32_t readRaw(std::uint32_t bits);  // bits <= 16

  const std::byte* begin_ = nullptr;
  const std::byte* at_ = nullptr;
  const std::byte* end_ = nullptr;
  std::uint32_t value_ = 0, length_ = 0;
  bool overrun_ = false, invalid_ = false;
};

// LASzip's IntegerCompressor, decoding: a value is predicted, and the corrector (real − predicted,
// folded into the value's range) is coded as its bit count k (one model per context) and then k
// bits. getK() is the last k, which items use to pick the next contexts.
class LazIntegerDecoder {
 public:
  explicit LazIntegerDecoder(std::uint32_t bits = 16, std::uint32_t contexts = 1,
                             std::uint32_t bitsHigh = 8, std::uint32_t range = 0);
  void reset();
  std::int32_t decode(LazDecoder& dec, std::int32_t predicted, std::uint32_t context = 0);
  std::uint32_t k() const { return k_; }

 private:
  std::int32_t readCorrector(LazDecoder& dec, LazSymbolModel& bitsModel);

  std::uint32_t bitsHigh_, correctorBits_ = 0, correctorRange_ = 0;
  std::int32_t correctorMin_ = 0;
  std::uint32_t k_ = 0;
  std::vector<LazSymbolModel> kModels_;          // one per context: which k
  LazBitModel zeroOrOne_;                        // k = 0: the corrector is 0 or 1
  std::vector<LazSymbolModel> correctorModels_;  // k = 1..bits: the corrector's high bits
};

}  // namespace lodforge
