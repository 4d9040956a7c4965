#include "lodforge/io/las_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace lodforge {

namespace {

template <class T>
void put(std::array<std::byte, 227>& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

}  // namespace

LasWriter::LasWriter(OutputFile out, Vec3d scale, Vec3d offset, std::string software)
    : out_(std::move(out)), scale_(scale), offset_(offset), software_(std::move(software)) {}

Result<LasWriter> LasWriter::create(const std::string& path, Vec3d scale, Vec3d offset,
                                    std::string generatingSoftware) {
  Result<OutputFile> out = OutputFile::create(path);
  if (!out) return out.status();
  LasWriter writer(std::move(*out), scale, offset, std::move(generatingSoftware));
  const auto placeholder = writer.header();  // counts and bounds come with finish()
  LODFORGE_TRY(writer.out_.write(placeholder.data(), placeholder.size()));
  return writer;
}

// The public header block of LAS 1.2 (227 bytes, no VLRs: the points follow it).
std::array<std::byte, 227> LasWriter::header() const {
  std::array<std::byte, 227> h{};
  std::memcpy(h.data(), "LASF", 4);
  h[24] = std::byte{1};
  h[25] = std::byte{2};
  std::memcpy(h.data() + 26, "lodforge", 8);
  std::memcpy(h.data() + 58, software_.data(), std::min<std::size_t>(software_.size(), 31));
  put<std::uint16_t>(h, 94, 227);
  put<std::uint32_t>(h, 96, 227);
  put<std::uint8_t>(h, 104, 3);
  put<std::uint16_t>(h, 105, static_cast<std::uint16_t>(kLasFormat3Size));
  put<std::uint32_t>(h, 107,
                     static_cast<std::uint32_t>(std::min<std::uint64_t>(points_, 0xFFFFFFFFu)));
  for (std::size_t r = 0; r < 5; ++r) put<std::uint32_t>(h, 111 + 4 * r, byReturn_[r]);
  const bool empty = points_ == 0;
  for (int k = 0; k < 3; ++k) {
    const auto at = static_cast<std::size_t>(k);
    put<double>(h, 131 + 8 * at, scale_[k]);
    put<double>(h, 155 + 8 * at, offset_[k]);
    put<double>(h, 179 + 16 * at, empty ? 0.0 : bounds_.max[k]);
    put<double>(h, 187 + 16 * at, empty ? 0.0 : bounds_.min[k]);
  }
  return h;
}

Status LasWriter::write(std::span<const LasPoint3> points) {
  std::vector<std::byte> records(points.size() * kLasFormat3Size);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LasPoint3& p = points[i];
    std::byte* r = records.data() + i * kLasFormat3Size;
    Vec3d stored;
    for (int k = 0; k < 3; ++k) {
      const double v = std::round((p.position[k] - offset_[k]) / scale_[k]);
      const auto integer = static_cast<std::int32_t>(std::clamp(v, -2147483648.0, 2147483647.0));
      std::memcpy(r + 4 * static_cast<std::size_t>(k), &integer, 4);
      stored[k] = integer * scale_[k] + offset_[k];  // the bounds of what the file holds
    }
    bounds_.add(stored);
    std::memcpy(r + 12, &p.intensity, 2);
    r[14] = static_cast<std::byte>((p.returnNumber & 7) | ((p.numberOfReturns & 7) << 3));
    r[15] = static_cast<std::byte>(p.classification & 31);
    r[16] = static_cast<std::byte>(p.scanAngle);
    r[17] = std::byte{0};
    std::memcpy(r + 18, &p.pointSource, 2);
    std::memcpy(r + 20, &p.gpsTime, 8);
    std::memcpy(r + 28, p.rgb.data(), 6);
    if (p.returnNumber >= 1 && p.returnNumber <= 5) ++byReturn_[p.returnNumber - 1u];
  }
  points_ += points.size();
  return out_.write(records.data(), records.size());
}

Status LasWriter::finish() {
  LODFORGE_TRY(out_.flush());
  const auto h = header();
  LODFORGE_TRY(out_.writeAt(0, h.data(), h.size()));
  return out_.commit();
}

}  // namespace lodforge
