#include "lodforge/tiles/texture_pyramid.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <list>
#include <mutex>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"

namespace lodforge {
namespace {

constexpr std::size_t kBlockBytes = std::size_t{kPyramidBlock} * kPyramidBlock * 4;

// sRGB <-> linear light, by table: averaging sRGB values directly darkens detail.
struct Srgb {
  std::array<float, 256> toLinear{};
  std::array<std::uint8_t, 4096> fromLinear{};
  Srgb() {
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      toLinear[static_cast<std::size_t>(i)] =
          static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    for (int i = 0; i < 4096; ++i) {
      const double l = i / 4095.0;
      const double c = l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
      fromLinear[static_cast<std::size_t>(i)] =
          static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255));
    }
  }
};
const Srgb& srgb() {
  static const Srgb table;
  return table;
}

struct Level {
  std::uint32_t width = 0, height = 0, blocksX = 0, blocksY = 0;
  std::uint64_t offset = 0;  // of its first block in the file
};

struct Pyramid {
  std::string path;
  int fd = -1;
  std::vector<Level> levels;
};

std::uint32_t blocksFor(std::uint32_t texels) {
  return (texels + kPyramidBlock - 1) / kPyramidBlock;
}

// The levels of an image of this size, and where each one's blocks start in its file.
std::vector<Level> levelsOf(std::uint32_t width, std::uint32_t height) {
  std::vector<Level> levels;
  std::uint64_t offset = 0;
  while (true) {
    const Level level{width, height, blocksFor(width), blocksFor(height), offset};
    levels.push_back(level);
    offset += std::uint64_t{level.blocksX} * level.blocksY * kBlockBytes;
    if (width == 1 && height == 1) break;
    width = std::max(1u, width / 2), height = std::max(1u, height / 2);
  }
  return levels;
}

// Builds the pyramid from the image's rows as they are decoded, as halveImage would level by
// level: each level holds a band of one block row, written out when full, and the row waiting
// for its pair to make a row of the level above. A few rows in memory, whatever the image.
class PyramidWriter {
 public:
  PyramidWriter(OutputFile& file, std::vector<Level> levels)
      : file_(file), levels_(std::move(levels)), state_(levels_.size()) {
    for (std::size_t l = 0; l < levels_.size(); ++l) {
      state_[l].band.resize(std::size_t{kPyramidBlock} * levels_[l].width * 4);
      state_[l].pending.resize(std::size_t{levels_[l].width} * 4);
    }
  }

  Status push(std::size_t l, const std::uint8_t* row) {
    const Level& level = levels_[l];
    LevelState& s = state_[l];
    const std::uint32_t y = s.rows++;
    std::copy_n(row, std::size_t{level.width} * 4,
                s.band.data() + std::size_t{y % kPyramidBlock} * level.width * 4);
    if (y % kPyramidBlock == kPyramidBlock - 1 || y + 1 == level.height)
      LODFORGE_TRY(writeBand(l, y / kPyramidBlock, y % kPyramidBlock + 1));
    if (l + 1 == levels_.size()) return {};
    // Rows 2k and 2k + 1 make row k above (a lone row makes it alone; an odd last row none).
    if (level.height == 1) return push(l + 1, halveRow(l, row, row));
    if (y % 2 == 0) {
      std::copy_n(row, std::size_t{level.width} * 4, s.pending.data());
      return {};
    }
    return push(l + 1, halveRow(l, s.pending.data(), row));
  }

  bool complete() const {
    for (std::size_t l = 0; l < levels_.size(); ++l)
      if (state_[l].rows != levels_[l].height) return false;
    return true;
  }

 private:
  struct LevelState {
    std::uint32_t rows = 0;
    std::vector<std::uint8_t> band, pending, half;
  };

  const std::uint8_t* halveRow(std::size_t l, const std::uint8_t* a, const std::uint8_t* b) {
    const Srgb& table = srgb();
    const std::uint32_t w = levels_[l].width, out = levels_[l + 1].width;
    std::vector<std::uint8_t>& half = state_[l].half;
    half.resize(std::size_t{out} * 4);
    for (std::uint32_t x = 0; x < out; ++x) {
      const std::size_t x0 = 4 * std::size_t{std::min(2 * x, w - 1)};
      const std::size_t x1 = 4 * std::size_t{std::min(2 * x + 1, w - 1)};
      const std::uint8_t* q[4] = {a + x0, a + x1, b + x0, b + x1};
      for (std::size_t c = 0; c < 3; ++c) {
        float sum = 0;
        for (const std::uint8_t* p : q) sum += table.toLinear[p[c]];
        half[4 * x + c] = table.fromLinear[static_cast<std::size_t>(std::lround(sum / 4 * 4095))];
      }
      half[4 * x + 3] = static_cast<std::uint8_t>((q[0][3] + q[1][3] + q[2][3] + q[3][3] + 2) / 4);
    }
    return half.data();
  }

  // A band of `rows` rows as a row of whole blocks (padded with the edge texels).
  Status writeBand(std::size_t l, std::uint32_t by, std::uint32_t rows) {
    const Level& level = levels_[l];
    const std::vector<std::uint8_t>& band = state_[l].band;
    block_.resize(kBlockBytes);
    for (std::uint32_t bx = 0; bx < level.blocksX; ++bx) {
      for (std::uint32_t y = 0; y < kPyramidBlock; ++y) {
        const std::uint32_t sy = std::min(y, rows - 1);
        for (std::uint32_t x = 0; x < kPyramidBlock; ++x) {
          const std::uint32_t sx = std::min(bx * kPyramidBlock + x, level.width - 1);
          std::memcpy(block_.data() + 4 * (std::size_t{y} * kPyramidBlock + x),
                      band.data() + 4 * (std::size_t{sy} * level.width + sx), 4);
        }
      }
      const std::uint64_t at =
          level.offset + (std::uint64_t{by} * level.blocksX + bx) * kBlockBytes;
      LODFORGE_TRY(file_.writeAt(at, block_.data(), block_.size()));
    }
    return {};
  }

  OutputFile& file_;
  std::vector<Level> levels_;
  std::vector<LevelState> state_;
  std::vector<std::uint8_t> block_;
};

Result<Pyramid> buildOne(const ImageSource& source, const std::string& path) {
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  Pyramid pyramid;
  pyramid.path = path;
  std::optional<PyramidWriter> writer;
  LODFORGE_TRY(decodeImageRows(
      source, kMaxTexturePixels,
      [&](std::uint32_t width, std::uint32_t height) -> Status {
        pyramid.levels = levelsOf(width, height);
        writer.emplace(*file, pyramid.levels);
        return {};
      },
      [&](const std::uint8_t* row) { return writer->push(0, row); }));
  if (!writer || !writer->complete())
    return Error{ErrorKind::kInternal, fmt::format("{}: the pyramid is incomplete", path)};
  writer.reset();
  LODFORGE_TRY(file->commit());
  pyramid.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (pyramid.fd < 0) return ioErrorFromErrno(path, "open");
  return pyramid;
}

// The pyramid an earlier run left at `path`, when its file has the full size; nothing otherwise.
std::optional<Pyramid> keptPyramid(const ImageSource& source, const std::string& path) {
  Pyramid pyramid;
  pyramid.path = path;
  pyramid.levels = levelsOf(source.width, source.height);
  const Level& last = pyramid.levels.back();
  const Result<std::uint64_t> size = fileSize(path);
  if (!size || *size != last.offset + std::uint64_t{last.blocksX} * last.blocksY * kBlockBytes)
    return std::nullopt;
  pyramid.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (pyramid.fd < 0) return std::nullopt;
  return pyramid;
}

}  // namespace

std::int64_t wrapTexel(std::int64_t x, std::int64_t size, TextureWrap wrap) {
  assert(size > 0);
  if (x >= 0 && x < size) return x;
  switch (wrap) {
    case TextureWrap::kClamp:
      return std::clamp<std::int64_t>(x, 0, size - 1);
    case TextureWrap::kMirror: {
      const std::int64_t period = 2 * size;
      const std::int64_t m = ((x % period) + period) % period;
      return m < size ? m : period - 1 - m;
    }
    case TextureWrap::kRepeat:
      break;
  }
  return ((x % size) + size) % size;
}

Image halveImage(const Image& image) {
  const Srgb& table = srgb();
  Image out(std::max(1u, image.width / 2), std::max(1u, image.height / 2));
  for (std::uint32_t y = 0; y < out.height; ++y) {
    const std::uint32_t y0 = std::min(2 * y, image.height - 1),
                        y1 = std::min(2 * y + 1, image.height - 1);
    for (std::uint32_t x = 0; x < out.width; ++x) {
      const std::uint32_t x0 = std::min(2 * x, image.width - 1),
                          x1 = std::min(2 * x + 1, image.width - 1);
      const std::uint8_t* q[4] = {&image.rgba[4 * (std::size_t{y0} * image.width + x0)],
                                  &image.rgba[4 * (std::size_t{y0} * image.width + x1)],
                                  &image.rgba[4 * (std::size_t{y1} * image.width + x0)],
                                  &image.rgba[4 * (std::size_t{y1} * image.width + x1)]};
      std::uint8_t* o = &out.rgba[4 * (std::size_t{y} * out.width + x)];
      for (std::size_t c = 0; c < 3; ++c) {
        float sum = 0;
        for (const std::uint8_t* p : q) sum += table.toLinear[p[c]];
        o[c] = table.fromLinear[static_cast<std::size_t>(std::lround(sum / 4 * 4095))];
      }
      o[3] = static_cast<std::uint8_t>((q[0][3] + q[1][3] + q[2][3] + q[3][3] + 2) / 4);
    }
  }
  return out;
}

struct TexturePyramid::State {
  std::vector<Pyramid> images;
  std::uint64_t cacheBytes = 0;
  // Blocks by (image, level, block index), most recently used first.
  mutable std::mutex mutex;
  mutable std::list<std::pair<std::uint64_t, std::vector<std::uint8_t>>> recent;
  mutable std::unordered_map<std::uint64_t, decltype(recent)::iterator> cached;

  ~State() {
    for (Pyramid& p : images) {
      if (p.fd >= 0) ::close(p.fd);
      ::unlink(p.path.c_str());
    }
  }

  // The block, from the cache or the file; the caller holds the mutex.
  Result<const std::uint8_t*> block(std::size_t image, std::uint32_t level, std::uint32_t bx,
                                    std::uint32_t by) const {
    const Pyramid& p = images[image];
    const Level& l = p.levels[level];
    const std::uint64_t index = std::uint64_t{by} * l.blocksX + bx;
    const std::uint64_t key = (std::uint64_t{image} << 48) | (std::uint64_t{level} << 40) | index;
    if (const auto found = cached.find(key); found != cached.end()) {
      recent.splice(recent.begin(), recent, found->second);
      return recent.front().second.data();
    }
    std::vector<std::uint8_t> bytes(kBlockBytes);
    const auto at = static_cast<off_t>(l.offset + index * kBlockBytes);
    if (::pread(p.fd, bytes.data(), kBlockBytes, at) != static_cast<ssize_t>(kBlockBytes))
      return ioErrorFromErrno(p.path, "read");
    recent.emplace_front(key, std::move(bytes));
    cached[key] = recent.begin();
    while (recent.size() > 1 && recent.size() * kBlockBytes > cacheBytes) {
      cached.erase(recent.back().first);
      recent.pop_back();
    }
    return recent.front().second.data();
  }
};

TexturePyramid::TexturePyramid(std::unique_ptr<State> state) : state_(std::move(state)) {}
TexturePyramid::TexturePyramid(TexturePyramid&&) noexcept = default;
TexturePyramid& TexturePyramid::operator=(TexturePyramid&&) noexcept = default;
TexturePyramid::~TexturePyramid() = default;

Result<TexturePyramid> TexturePyramid::build(std::span<const ImageSource> images,
                                             const std::string& directory, std::uint64_t cacheBytes,
                                             bool reuse) {
  auto state = std::make_unique<State>();
  state->cacheBytes = std::max<std::uint64_t>(cacheBytes, 4 * kBlockBytes);
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string path = fmt::format("{}/{}.pyr", directory, i);
    if (std::optional<Pyramid> kept = reuse ? keptPyramid(images[i], path) : std::nullopt) {
      state->images.push_back(std::move(*kept));
      continue;
    }
    Result<Pyramid> pyramid = buildOne(images[i], path);
    if (!pyramid) return pyramid.status();
    state->images.push_back(std::move(*pyramid));
  }
  return TexturePyramid(std::move(state));
}

std::size_t TexturePyramid::imageCount() const {
  return state_->images.size();
}
std::uint32_t TexturePyramid::levels(std::size_t image) const {
  return static_cast<std::uint32_t>(state_->images[image].levels.size());
}
std::uint32_t TexturePyramid::width(std::size_t image, std::uint32_t level) const {
  return state_->images[image].levels[level].width;
}
std::uint32_t TexturePyramid::height(std::size_t image, std::uint32_t level) const {
  return state_->images[image].levels[level].height;
}
std::uint64_t TexturePyramid::cacheBytes() const {
  return state_->cacheBytes;
}

Status TexturePyramid::read(std::size_t image, std::uint32_t level, std::int64_t x, std::int64_t y,
                            std::uint32_t w, std::uint32_t h, TextureWrap wrapS, TextureWrap wrapT,
                            std::uint8_t* out) const {
  assert(image < state_->images.size() && level < levels(image));
  const Level& l = state_->images[image].levels[level];
  std::lock_guard lock(state_->mutex);
  for (std::uint32_t row = 0; row < h; ++row) {
    const auto sy = static_cast<std::uint32_t>(wrapTexel(y + row, l.height, wrapT));
    for (std::uint32_t column = 0; column < w;) {
      const auto sx = static_cast<std::uint32_t>(wrapTexel(x + column, l.width, wrapS));
      Result<const std::uint8_t*> block =
          state_->block(image, level, sx / kPyramidBlock, sy / kPyramidBlock);
      if (!block) return block.status();
      // The run of texels this block gives, up to its right edge or a wrap.
      std::uint32_t run = 1;
      while (column + run < w && run < kPyramidBlock - sx % kPyramidBlock &&
             wrapTexel(x + column + run, l.width, wrapS) == sx + run)
        ++run;
      std::memcpy(
          out + 4 * (std::size_t{row} * w + column),
          *block + 4 * (std::size_t{sy % kPyramidBlock} * kPyramidBlock + sx % kPyramidBlock),
          4 * std::size_t{run});
      column += run;
    }
  }
  return {};
}

}  // namespace lodforge
