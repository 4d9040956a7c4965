// Layered LAZ items, version 3 (LASzip 3.x, compressor 3: LAS 1.4 point formats 6–10). Each field
// group lives in a layer of its own, so a reader can skip what it does not need; every item keeps
// four sets of models, one per scanner channel, switched by the POINT14 item.
#include <cstring>

#include "lodforge/io/points/laz/laz_items.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

// The 30-byte POINT14 record's fields (LAS 1.4 R15, Table 17).
struct Point14 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint32_t returnNumber = 0, numberOfReturns = 0;  // 4 bits each
  std::uint32_t classFlags = 0, scannerChannel = 0, scanDirection = 0, edge = 0;
  std::uint8_t classification = 0, userData = 0;
  std::int16_t scanAngle = 0;
  std::uint16_t pointSource = 0;
  std::uint64_t gpsTime = 0;    // the double's bits
  bool gpsTimeChanged = false;  // of the codec, not the record: did this point's time change

  static Point14 unpack(const std::byte* r) {
    Point14 p;
    p.x = loadField<std::int32_t>(r);
    p.y = loadField<std::int32_t>(r + 4);
    p.z = loadField<std::int32_t>(r + 8);
    p.intensity = loadField<std::uint16_t>(r + 12);
    const auto returns = static_cast<std::uint32_t>(r[14]),
               flags = static_cast<std::uint32_t>(r[15]);
    p.returnNumber = returns & 15;
    p.numberOfReturns = returns >> 4;
    p.classFlags = flags & 15;
    p.scannerChannel = (flags >> 4) & 3;
    p.scanDirection = (flags >> 6) & 1;
    p.edge = flags >> 7;
    p.classification = static_cast<std::uint8_t>(r[16]);
    p.userData = static_cast<std::uint8_t>(r[17]);
    p.scanAngle = loadField<std::int16_t>(r + 18);
    p.pointSource = loadField<std::uint16_t>(r + 20);
    p.gpsTime = loadField<std::uint64_t>(r + 22);
    return p;
  }
  void pack(std::byte* r) const {
    std::memcpy(r, &x, 4);
    std::memcpy(r + 4, &y, 4);
    std::memcpy(r + 8, &z, 4);
    std::memcpy(r + 12, &intensity, 2);
    r[14] = static_cast<std::byte>(returnNumber | (numberOfReturns << 4));
    r[15] = static_cast<std::byte>(classFlags | (scannerChannel << 4) | (scanDirection << 6) |
                                   (edge << 7));
    r[16] = static_cast<std::byte>(classification);
    r[17] = static_cast<std::byte>(userData);
    std::memcpy(r + 18, &scanAngle, 2);
    std::memcpy(r + 20, &pointSource, 2);
    std::memcpy(r + 22, &gpsTime, 8);
  }
};

// Contexts from return r of n (16×16, LAS 1.4's 4-bit counts): six for x and y.
std::uint32_t returnMap6(std::uint32_t n, std::uint32_t r) {
  static constexpr std::uint8_t kMap[16][16] = {{0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5},
                                                {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
                                                {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3},
                                                {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
                                                {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
                                                {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5},
                                                {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
  return kMap[n & 15][r & 15];
}

// Eight z and intensity levels: |n − r|, capped.
std::uint32_t returnLevel8(std::uint32_t n, std::uint32_t r) {
  const std::uint32_t level = lazReturnLevel(n, r);
  return level < 7 ? level : 7;
}

// One layer's decoder: `present` is false when the layer is empty (the field is constant in the
// chunk), and then nothing is decoded from it. A layer decodes from exactly its bytes, as
// LASzip's encoder wrote them; any other length means damage.
struct Layer {
  LazDecoder dec;
  bool present = false;
  std::size_t size = 0;
  void start(std::span<const std::byte> bytes) {
    present = !bytes.empty();
    size = bytes.size();
    if (present) dec.start(bytes);
  }
  bool damaged() const {
    return present && (dec.overrun() || dec.invalid() || dec.consumed() != size);
  }
};

class Point14V3 final : public LazLayeredItem {
 public:
  enum LayerIndex { kXY, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kSource, kGps };
  std::size_t layerCount() const override { return 9; }

  void start(const std::byte* first, std::span<const std::span<const std::byte>> layers,
             std::uint32_t& context) override {
    for (std::size_t i = 0; i < 9; ++i) layers_[i].start(layers[i]);
    // The x/y layer is decoded for every point, so it is started even when empty (and then
    // reports itself overrun, as LASzip does).
    layers_[kXY].present = true;
    layers_[kXY].dec.start(layers[kXY]);
    for (auto& c : contexts_) c.unused = true;
    const Point14 point = Point14::unpack(first);
    current_ = point.scannerChannel;
    context = current_;
    startContext(current_, point);
  }

  void read(std::byte* out, std::uint32_t& context) override {
    LazDecoder& xy = layers_[kXY].dec;
    Context* c = &contexts_[current_];
    std::uint32_t lastPoint = (c->last.returnNumber == 1 ? 1u : 0u) +
                              (c->last.returnNumber >= c->last.numberOfReturns ? 2u : 0u) +
                              (c->last.gpsTimeChanged ? 4u : 0u);
    const std::uint32_t changed = xy.decodeSymbol(c->models->changed[lastPoint]);
    if (changed & (1 << 6)) {  // another scanner channel: its own contexts
      const std::uint32_t channel = (current_ + xy.decodeSymbol(c->models->channel) + 1) % 4;
      if (contexts_[channel].unused) startContext(channel, c->last);
      current_ = channel;
      context = current_;
      c = &contexts_[current_];
      c->last.scannerChannel = channel;
    }
    const bool gpsChanged = (changed & (1 << 4)) != 0;
    decodeReturns(*c, changed, gpsChanged);
    decodeXYZ(*c, gpsChanged);
    decodeAttributes(*c, changed, gpsChanged);
    c->last.pack(out);
    c->last.gpsTimeChanged = gpsChanged;
  }

  bool damaged() const override {
    for (const Layer& l : layers_)
      if (l.damaged()) return true;
    return false;
  }

 private:
  struct Models {
    std::array<LazSymbolModel, 8> changed{
        LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128),
        LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128), LazSymbolModel(128)};
    LazSymbolModel channel{3};
    std::array<std::unique_ptr<LazSymbolModel>, 16> numberOfReturns, returnNumber;
    LazSymbolModel returnNumberGpsSame{13};
    LazIntegerDecoder dx{32, 2}, dy{32, 22}, z{32, 20};
    std::array<std::unique_ptr<LazSymbolModel>, 64> classification, flags, userData;
    LazIntegerDecoder intensity{16, 4}, scanAngle{16, 2}, pointSource{16};
    LazGpsTimeCodec gps{true};
  };
  struct Context {
    bool unused = true;
    Point14 last;
    std::array<std::uint16_t, 8> lastIntensity{};
    std::array<LazMedian5, 12> xDiffs, yDiffs;
    std::array<std::int32_t, 8> lastZ{};
    std::unique_ptr<Models> models;
  };

  // A scanner channel's contexts start from the point before (its first, or the last of the
  // channel it switched from).
  void startContext(std::uint32_t channel, const Point14& from) {
    Context& c = contexts_[channel];
    if (!c.models) c.models = std::make_unique<Models>();
    Models& m = *c.models;
    for (LazSymbolModel& s : m.changed) s.reset();
    m.channel.reset();
    m.returnNumberGpsSame.reset();
    // Models made on first use are dropped: a new one is what a reset one would be.
    for (auto* table : {&m.numberOfReturns, &m.returnNumber})
      for (auto& s : *table) s.reset();
    for (auto* table : {&m.classification, &m.flags, &m.userData})
      for (auto& s : *table) s.reset();
    for (LazIntegerDecoder* ic : {&m.dx, &m.dy, &m.z, &m.intensity, &m.scanAngle, &m.pointSource})
      ic->reset();
    m.gps.reset(from.gpsTime);
    for (auto& d : c.xDiffs) d.reset();
    for (auto& d : c.yDiffs) d.reset();
    c.lastZ.fill(from.z);
    c.lastIntensity.fill(from.intensity);
    c.last = from;
    c.last.gpsTimeChanged = false;
    c.unused = false;
  }

  // Number of returns and return number, from the x/y layer.
  void decodeReturns(Context& c, std::uint32_t changed, bool gpsChanged) {
    LazDecoder& xy = layers_[kXY].dec;
    Models& m = *c.models;
    const std::uint32_t lastN = c.last.numberOfReturns, lastR = c.last.returnNumber;
    if (changed & (1 << 2))
      c.last.numberOfReturns = xy.decodeSymbol(lazModelOnUse(m.numberOfReturns[lastN], 16));
    switch (changed & 3) {
      case 0:
        break;
      case 1:
        c.last.returnNumber = (lastR + 1) % 16;
        break;
      case 2:
        c.last.returnNumber = (lastR + 15) % 16;
        break;
      default:
        if (gpsChanged) {
          c.last.returnNumber = xy.decodeSymbol(lazModelOnUse(m.returnNumber[lastR], 16));
        } else {
          c.last.returnNumber = (lastR + xy.decodeSymbol(m.returnNumberGpsSame) + 2) % 16;
        }
    }
  }

  void decodeXYZ(Context& c, bool gpsChanged) {
    LazDecoder& xy = layers_[kXY].dec;
    Models& m = *c.models;
    const std::uint32_t n = c.last.numberOfReturns, r = c.last.returnNumber;
    const std::uint32_t single = n == 1 ? 1 : 0;
    const std::uint32_t slot = (returnMap6(n, r) << 1) | (gpsChanged ? 1 : 0);
    std::int32_t diff = m.dx.decode(xy, c.xDiffs[slot].get(), single);
    c.last.x = lazWrapAdd(c.last.x, diff);
    c.xDiffs[slot].add(diff);
    std::uint32_t k = m.dx.k();
    diff = m.dy.decode(xy, c.yDiffs[slot].get(), single + (k < 20 ? (k & ~1u) : 20));
    c.last.y = lazWrapAdd(c.last.y, diff);
    c.yDiffs[slot].add(diff);
    if (layers_[kZ].present) {
      k = (m.dx.k() + m.dy.k()) / 2;
      const std::uint32_t l = returnLevel8(n, r);
      c.last.z = m.z.decode(layers_[kZ].dec, c.lastZ[l], single + (k < 18 ? (k & ~1u) : 18));
      c.lastZ[l] = c.last.z;
    }
  }

  void decodeAttributes(Context& c, std::uint32_t changed, bool gpsChanged) {
    Models& m = *c.models;
    Point14& p = c.last;
    const std::uint32_t n = p.numberOfReturns, r = p.returnNumber;
    const std::uint32_t returnKind = (r == 1 ? 2u : 0u) + (r >= n ? 1u : 0u);  // first 2, last 1
    if (layers_[kClass].present) {
      const std::uint32_t slot = ((p.classification & 0x1Fu) << 1) + (returnKind == 3 ? 1 : 0);
      p.classification = static_cast<std::uint8_t>(
          layers_[kClass].dec.decodeSymbol(lazModelOnUse(m.classification[slot], 256)));
    }
    if (layers_[kFlags].present) {
      const std::uint32_t last = (p.edge << 5) | (p.scanDirection << 4) | p.classFlags;
      const std::uint32_t flags =
          layers_[kFlags].dec.decodeSymbol(lazModelOnUse(m.flags[last], 64));
      p.edge = (flags >> 5) & 1;
      p.scanDirection = (flags >> 4) & 1;
      p.classFlags = flags & 15;
    }
    if (layers_[kIntensity].present) {
      const std::uint32_t slot = (returnKind << 1) | (gpsChanged ? 1 : 0);
      p.intensity = static_cast<std::uint16_t>(
          m.intensity.decode(layers_[kIntensity].dec, c.lastIntensity[slot], returnKind));
      c.lastIntensity[slot] = p.intensity;
    }
    if (layers_[kScanAngle].present && (changed & (1 << 3)))
      p.scanAngle = static_cast<std::int16_t>(
          m.scanAngle.decode(layers_[kScanAngle].dec, p.scanAngle, gpsChanged ? 1 : 0));
    if (layers_[kUserData].present)
      p.userData = static_cast<std::uint8_t>(
          layers_[kUserData].dec.decodeSymbol(lazModelOnUse(m.userData[p.userData / 4], 256)));
    if (layers_[kSource].present && (changed & (1 << 5)))
      p.pointSource =
          static_cast<std::uint16_t>(m.pointSource.decode(layers_[kSource].dec, p.pointSource));
    if (layers_[kGps].present && gpsChanged) p.gpsTime = m.gps.decode(layers_[kGps].dec);
  }

  std::array<Layer, 9> layers_;
  std::array<Context, 4> contexts_;
  std::uint32_t current_ = 0;
};

// The items after POINT14 follow its scanner channel. On a switch to a channel already in use,
// LASzip predicts from (and updates) the previous channel's last record with the new channel's
// models; the encoder does the same, so the decoder must too.
template <class Models>
class FollowerItem : public LazLayeredItem {
 public:
  explicit FollowerItem(std::size_t lastBytes) {
    for (auto& c : contexts_) c.last.resize(lastBytes);
  }
  void read(std::byte* out, std::uint32_t& context) override {
    std::uint8_t* last = contexts_[current_].last.data();
    if (current_ != context) {
      current_ = context;
      if (!contexts_[current_].used) {
        startContext(current_, last);
        last = contexts_[current_].last.data();
      }
    }
    decode(*contexts_[current_].models, last, out);
  }

 protected:
  virtual void resetModels(Models& models) = 0;
  virtual void decode(Models& models, std::uint8_t* last, std::byte* out) = 0;

  void startFollowing(const std::byte* first, std::uint32_t context) {
    for (auto& c : contexts_) c.used = false;
    current_ = context;
    startContext(current_, reinterpret_cast<const std::uint8_t*>(first));
  }

 private:
  // A channel's context starts from the record before (the chunk's first, or the last of the
  // channel switched from).
  void startContext(std::uint32_t channel, const std::uint8_t* from) {
    auto& c = contexts_[channel];
    if (!c.models) c.models = std::make_unique<Models>();
    resetModels(*c.models);
    std::memmove(c.last.data(), from, c.last.size());
    c.used = true;
  }

  struct Context {
    bool used = false;
    std::vector<std::uint8_t> last;
    std::unique_ptr<Models> models;
  };
  std::uint32_t current_ = 0;
  std::array<Context, 4> contexts_;
};

struct RgbNirModels {
  LazRgbModels rgb;
  LazSymbolModel nirUsed{4};
  std::array<LazSymbolModel, 2> nirDiff{LazSymbolModel(256), LazSymbolModel(256)};
};

// RGB14 and RGBNIR14 v3: the RGB layer as RGB12 v2 codes it; NIR in a layer of its own.
class Rgb14V3 final : public FollowerItem<RgbNirModels> {
 public:
  explicit Rgb14V3(bool nir) : FollowerItem(nir ? 8 : 6), nir_(nir) {}
  std::size_t layerCount() const override { return nir_ ? 2 : 1; }
  void start(const std::byte* first, std::span<const std::span<const std::byte>> layers,
             std::uint32_t& context) override {
    rgb_.start(layers[0]);
    if (nir_) nirLayer_.start(layers[1]);
    startFollowing(first, context);
  }
  bool damaged() const override { return rgb_.damaged() || nirLayer_.damaged(); }

 private:
  void resetModels(RgbNirModels& m) override {
    m.rgb.reset();
    m.nirUsed.reset();
    for (LazSymbolModel& d : m.nirDiff) d.reset();
  }

  void decode(RgbNirModels& m, std::uint8_t* last, std::byte* out) override {
    const std::size_t bytes = nir_ ? 8 : 6;
    std::uint16_t values[4] = {};
    std::memcpy(values, last, bytes);
    if (rgb_.present) {
      std::uint16_t previous[3];
      std::memcpy(previous, last, 6);
      lazDecodeRgb(rgb_.dec, m.rgb, previous, values);
    }
    if (nir_ && nirLayer_.present) {  // NIR: low and high byte, each from the last
      LazDecoder& dec = nirLayer_.dec;
      const std::uint32_t used = dec.decodeSymbol(m.nirUsed);
      std::int32_t low = values[3] & 0xFF, high = values[3] >> 8;
      if (used & 1) low = lazFold(static_cast<std::int32_t>(dec.decodeSymbol(m.nirDiff[0])) + low);
      if (used & 2)
        high = lazFold(static_cast<std::int32_t>(dec.decodeSymbol(m.nirDiff[1])) + high);
      values[3] = static_cast<std::uint16_t>(low | (high << 8));
    }
    std::memcpy(last, values, bytes);
    std::memcpy(out, values, bytes);
  }

  bool nir_;
  Layer rgb_, nirLayer_;
};

// BYTE14 v3 (extra bytes): one layer per byte, each byte a difference to the last.
class Byte14V3 final : public FollowerItem<std::vector<LazSymbolModel>> {
 public:
  explicit Byte14V3(std::size_t count) : FollowerItem(count), layers_(count) {}
  std::size_t layerCount() const override { return layers_.size(); }
  void start(const std::byte* first, std::span<const std::span<const std::byte>> layers,
             std::uint32_t& context) override {
    for (std::size_t i = 0; i < layers_.size(); ++i) layers_[i].start(layers[i]);
    startFollowing(first, context);
  }
  bool damaged() const override {
    for (const Layer& l : layers_)
      if (l.damaged()) return true;
    return false;
  }

 private:
  void resetModels(std::vector<LazSymbolModel>& models) override {
    if (models.empty())
      for (std::size_t i = 0; i < layers_.size(); ++i) models.emplace_back(256);
    for (LazSymbolModel& m : models) m.reset();
  }
  void decode(std::vector<LazSymbolModel>& models, std::uint8_t* last, std::byte* out) override {
    for (std::size_t i = 0; i < layers_.size(); ++i) {
      if (layers_[i].present)
        last[i] =
            lazFold(static_cast<std::int32_t>(last[i] + layers_[i].dec.decodeSymbol(models[i])));
      out[i] = static_cast<std::byte>(last[i]);
    }
  }

  std::vector<Layer> layers_;
};

// WAVEPACKET14 v3: WAVEPACKET13's codec per channel, in one layer.
class WavePacket14V3 final : public FollowerItem<LazWavePacketCodec> {
 public:
  WavePacket14V3() : FollowerItem(29) {}
  std::size_t layerCount() const override { return 1; }
  void start(const std::byte* first, std::span<const std::span<const std::byte>> layers,
             std::uint32_t& context) override {
    layer_.start(layers[0]);
    startFollowing(first, context);
  }
  bool damaged() const override { return layer_.damaged(); }

 private:
  void resetModels(LazWavePacketCodec& codec) override { codec.reset(); }
  void decode(LazWavePacketCodec& codec, std::uint8_t* last, std::byte* out) override {
    if (layer_.present) {
      codec.decode(layer_.dec, last + 1, out);
      last[0] = static_cast<std::uint8_t>(out[0]);
    } else {
      std::memcpy(out, last, 29);
    }
  }

  Layer layer_;
};

}  // namespace

std::unique_ptr<LazLayeredItem> makeLayeredItem(const LazItem& item) {
  // Version 2 of POINT14 and friends came from a prototype and codes the same as version 3.
  if (item.version != 3 && item.version != 2) return nullptr;
  switch (item.type) {
    case 10:
      return std::make_unique<Point14V3>();
    case 11:
      return std::make_unique<Rgb14V3>(false);
    case 12:
      return std::make_unique<Rgb14V3>(true);
    case 13:
      return std::make_unique<WavePacket14V3>();
    case 14:
      return std::make_unique<Byte14V3>(item.size);
    default:
      return nullptr;
  }
}

}  // namespace lodforge
