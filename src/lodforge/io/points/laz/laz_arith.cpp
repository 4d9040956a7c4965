#include "lodforge/io/points/laz/laz_arith.h"

#include <cassert>

namespace lodforge {

namespace {

// The coder's constants (LAZ specification, arithmetic coder section).
constexpr std::uint32_t kMinLength = 0x01000000u;  // renormalize below this interval length
constexpr std::uint32_t kMaxLength = 0xFFFFFFFFu;
constexpr std::uint32_t kBitLengthShift = 13;  // bit models: length bits dropped before multiply
constexpr std::uint32_t kBitMaxCount = 1u << kBitLengthShift;
constexpr std::uint32_t kSymbolLengthShift = 15;  // symbol models likewise
constexpr std::uint32_t kSymbolMaxCount = 1u << kSymbolLengthShift;

}  // namespace

void LazBitModel::reset() {
  bit0Count_ = 1;
  bitCount_ = 2;
  bit0Probability_ = 1u << (kBitLengthShift - 1);
  updateCycle_ = untilUpdate_ = 4;  // adapt often at first
}

void LazBitModel::update() {
  if ((bitCount_ += updateCycle_) > kBitMaxCount) {  // halve the counts at the threshold
    bitCount_ = (bitCount_ + 1) >> 1;
    bit0Count_ = (bit0Count_ + 1) >> 1;
    if (bit0Count_ == bitCount_) ++bitCount_;
  }
  const std::uint32_t scale = 0x80000000u / bitCount_;
  bit0Probability_ = (bit0Count_ * scale) >> (31 - kBitLengthShift);
  updateCycle_ = (5 * updateCycle_) >> 2;
  if (updateCycle_ > 64) updateCycle_ = 64;
  untilUpdate_ = updateCycle_;
}

LazSymbolModel::LazSymbolModel(std::uint32_t symbols)
    : symbols_(symbols), lastSymbol_(symbols - 1), distribution_(symbols), counts_(symbols) {
  assert(symbols >= 2 && symbols <= (1u << 11));
  if (symbols > 16) {
    std::uint32_t tableBits = 3;
    while (symbols > (1u << (tableBits + 2))) ++tableBits;
    tableShift_ = kSymbolLengthShift - tableBits;
    table_.resize((std::size_t{1} << tableBits) + 2);
  }
  reset();
}

void LazSymbolModel::reset() {
  totalCount_ = 0;
  updateCycle_ = symbols_;
  for (std::uint32_t& c : counts_) c = 1;
  update();
  untilUpdate_ = updateCycle_ = (symbols_ + 6) >> 1;
}

// The cumulative distribution (and the decoder's search table) from the counts.
void LazSymbolModel::update() {
  if ((totalCount_ += updateCycle_) > kSymbolMaxCount) {  // halve the counts at the threshold
    totalCount_ = 0;
    for (std::uint32_t& c : counts_) totalCount_ += (c = (c + 1) >> 1);
  }
  const std::uint32_t scale = 0x80000000u / totalCount_;
  std::uint32_t sum = 0, filled = 0;
  for (std::uint32_t k = 0; k < symbols_; ++k) {
    distribution_[k] = (scale * sum) >> (31 - kSymbolLengthShift);
    sum += counts_[k];
    if (table_.empty()) continue;
    const std::uint32_t w = distribution_[k] >> tableShift_;
    while (filled < w) table_[++filled] = k - 1;
  }
  if (!table_.empty()) {
    table_[0] = 0;
    const std::uint32_t tableSize = static_cast<std::uint32_t>(table_.size()) - 2;
    while (filled <= tableSize) table_[++filled] = symbols_ - 1;
  }
  updateCycle_ = (5 * updateCycle_) >> 2;
  const std::uint32_t maxCycle = (symbols_ + 6) << 3;
  if (updateCycle_ > maxCycle) updateCycle_ = maxCycle;
  untilUpdate_ = updateCycle_;
}

void LazDecoder::start(std::span<const std::byte> bytes) {
  begin_ = at_ = bytes.data();
  end_ = bytes.data() + bytes.size();
  overrun_ = invalid_ = false;
  length_ = kMaxLength;
  value_ = 0;
  for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | nextByte();
}

std::uint32_t LazDecoder::nextByte() {
  if (at_ == end_) {
    overrun_ = true;
    return 0;
  }
  return static_cast<std::uint32_t>(*at_++);
}

void LazDecoder::renormalize() {
  if (length_ == 0) {  // only damaged data gets here; keep the loop finite
    invalid_ = true;
    length_ = kMaxLength;
    return;
  }
  do {
    value_ = (value_ << 8) | nextByte();
  } while ((length_ <<= 8) < kMinLength);
}

std::uint32_t LazDecoder::decodeBit(LazBitModel& m) {
  const std::uint32_t x = m.bit0Probability_ * (length_ >> kBitLengthShift);
  const std::uint32_t bit = value_ >= x ? 1 : 0;
  if (bit == 0) {
    length_ = x;
    ++m.bit0Count_;
  } else {
    value_ -= x;
    length_ -= x;
  }
  if (length_ < kMinLength) renormalize();
  if (--m.untilUpdate_ == 0) m.update();
  return bit;
}

std::uint32_t LazDecoder::decodeSymbol(LazSymbolModel& m) {
  std::uint32_t symbol = 0, x = 0, y = length_;
  length_ >>= kSymbolLengthShift;
  if (!m.table_.empty()) {
    // The table narrows the search to a few symbols; bisection finishes it.
    const std::uint32_t scaled = value_ / length_;
    std::uint32_t t = scaled >> m.tableShift_;
    const std::uint32_t tableSize = static_cast<std::uint32_t>(m.table_.size()) - 2;
    if (t > tableSize) {  // a value past the interval: damaged data
      invalid_ = true;
      t = tableSize;
    }
    symbol = m.table_[t];
    std::uint32_t n = m.table_[t + 1] + 1;
    while (n > symbol + 1) {
      const std::uint32_t k = (symbol + n) >> 1;
      if (m.distribution_[k] > scaled) {
        n = k;
      } else {
        symbol = k;
      }
    }
    x = m.distribution_[symbol] * length_;
    if (symbol != m.lastSymbol_) y = m.distribution_[symbol + 1] * length_;
  } else {
    // Small alphabets: bisection with multiplications only.
    std::uint32_t n = m.symbols_, k = n >> 1;
    do {
      const std::uint32_t z = length_ * m.distribution_[k];
      if (z > value_) {
        n = k;
        y = z;
      } else {
        symbol = k;
        x = z;
      }
    } while ((k = (symbol + n) >> 1) != symbol);
  }
  value_ -= x;
  length_ = y - x;
  if (length_ < kMinLength) renormalize();
  ++m.counts_[symbol];
  if (--m.untilUpdate_ == 0) m.update();
  return symbol;
}

std::uint32_t LazDecoder::readRaw(std::uint32_t bits) {
  length_ >>= bits;
  const std::uint32_t value = value_ / length_;
  value_ -= length_ * value;
  if (length_ < kMinLength) renormalize();
  if (value >= (1u << bits)) invalid_ = true;
  return value;
}

std::uint32_t LazDecoder::readBits(std::uint32_t bits) {
  assert(bits >= 1 && bits <= 32);
  if (bits > 19) {  // the low 16 bits first, then the rest
    const std::uint32_t low = readRaw(16);
    return (readBits(bits - 16) << 16) | low;
  }
  return readRaw(bits);
}

std::uint32_t LazDecoder::readShort() {
  return readRaw(16);
}

std::uint32_t LazDecoder::readInt() {
  const std::uint32_t low = readShort();
  return (readShort() << 16) | low;
}

std::uint64_t LazDecoder::readInt64() {
  const std::uint64_t low = readInt();
  return (std::uint64_t{readInt()} << 32) | low;
}

LazIntegerDecoder::LazIntegerDecoder(std::uint32_t bits, std::uint32_t contexts,
                                     std::uint32_t bitsHigh, std::uint32_t range)
    : bitsHigh_(bitsHigh) {
  if (range != 0) {  // the corrector's bits from the value range
    correctorRange_ = range;
    while (range != 0) {
      range >>= 1;
      ++correctorBits_;
    }
    if (correctorRange_ == (1u << (correctorBits_ - 1))) --correctorBits_;
  } else if (bits != 0 && bits < 32) {
    correctorBits_ = bits;
    correctorRange_ = 1u << bits;
  } else {
    correctorBits_ = 32;
    correctorRange_ = 0;
  }
  correctorMin_ = correctorRange_ != 0 ? -static_cast<std::int32_t>(correctorRange_ / 2)
                                       : std::int32_t{-2147483647 - 1};
  kModels_.reserve(contexts);
  for (std::uint32_t c = 0; c < contexts; ++c) kModels_.emplace_back(correctorBits_ + 1);
  correctorModels_.reserve(correctorBits_);
  for (std::uint32_t i = 1; i <= correctorBits_; ++i)
    correctorModels_.emplace_back(i <= bitsHigh_ ? 1u << i : 1u << bitsHigh_);
}

void LazIntegerDecoder::reset() {
  for (LazSymbolModel& m : kModels_) m.reset();
  zeroOrOne_.reset();
  for (LazSymbolModel& m : correctorModels_) m.reset();
  k_ = 0;
}

std::int32_t LazIntegerDecoder::decode(LazDecoder& dec, std::int32_t predicted,
                                       std::uint32_t context) {
  assert(context < kModels_.size());
  // Unsigned sums wrap as the format's 32-bit arithmetic does.
  std::int32_t real =
      static_cast<std::int32_t>(static_cast<std::uint32_t>(predicted) +
                                static_cast<std::uint32_t>(readCorrector(dec, kModels_[context])));
  if (real < 0) {
    real = static_cast<std::int32_t>(static_cast<std::uint32_t>(real) + correctorRange_);
  } else if (static_cast<std::uint32_t>(real) >= correctorRange_) {
    real = static_cast<std::int32_t>(static_cast<std::uint32_t>(real) - correctorRange_);
  }
  return real;
}

std::int32_t LazIntegerDecoder::readCorrector(LazDecoder& dec, LazSymbolModel& bitsModel) {
  k_ = dec.decodeSymbol(bitsModel);
  if (k_ == 0) return static_cast<std::int32_t>(dec.decodeBit(zeroOrOne_));  // 0 or 1
  if (k_ >= 32) return correctorMin_;
  std::uint32_t c = dec.decodeSymbol(correctorModels_[k_ - 1]);
  if (k_ > bitsHigh_) {  // the high bits were modelled, the low ones come raw
    const std::uint32_t low = k_ - bitsHigh_;
    c = (c << low) | dec.readBits(low);
  }
  // [0, 2^(k-1)) stands for [-(2^k - 1), -2^(k-1)]; [2^(k-1), 2^k) for [2^(k-1) + 1, 2^k].
  if (c >= (1u << (k_ - 1))) {
    c += 1;
  } else {
    c -= (1u << k_) - 1;
  }
  return static_cast<std::int32_t>(c);
}

}  // namespace lodforge
