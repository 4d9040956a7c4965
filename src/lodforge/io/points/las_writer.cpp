#include "lodforge/io/points/las_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "lodforge/io/points/las_format.h"

namespace lodforge {

namespace {

template <class T>
void put(std::array<std::byte, 227>& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

}  // namespace

using las::kExtraDescriptor;
using las::kVlrHeader;

LasWriter::LasWriter(OutputFile out, Vec3d scale, Vec3d offset, std::string software,
                     PointExtras extras)
    : out_(std::move(out)),
      scale_(scale),
      offset_(offset),
      software_(std::move(software)),
      extras_(std::move(extras)) {}

Result<LasWriter> LasWriter::create(const std::string& path, Vec3d scale, Vec3d offset,
                                    std::string generatingSoftware, PointExtras extras) {
  // The descriptors say nothing of offsets: the fields must lie back to back.
  std::uint32_t end = 0;
  for (const ExtraField& field : extras.fields) {
    if (field.offset != end)
      return Error{ErrorKind::kInternal,
                   fmt::format("{}: extra field \"{}\" at byte {} does not follow the one before "
                               "(byte {})",
                               path, field.name, field.offset, end)};
    end += static_cast<std::uint32_t>(extraTypeSize(field.type));
  }
  if (end != extras.stride || kLasFormat3Size + extras.stride > 0xFFFF ||
      kExtraDescriptor * extras.fields.size() > 0xFFFF)
    return Error{ErrorKind::kInternal,
                 fmt::format("{}: {} extra bytes in {} fields do not make a LAS record", path,
                             extras.stride, extras.fields.size())};
  Result<OutputFile> out = OutputFile::create(path);
  if (!out) return out.status();
  LasWriter writer(std::move(*out), scale, offset, std::move(generatingSoftware),
                   std::move(extras));
  const auto placeholder = writer.header();  // counts and bounds come with finish()
  LODFORGE_TRY(writer.out_.write(placeholder.data(), placeholder.size()));
  if (writer.extras_.stride == 0) return writer;
  // The Extra Bytes record ("LASF_Spec", 4): one descriptor a field.
  std::vector<std::byte> record(kVlrHeader);
  std::memcpy(record.data() + 2, "LASF_Spec", 9);
  const std::uint16_t id = 4;
  const auto length = static_cast<std::uint16_t>(kExtraDescriptor * writer.extras_.fields.size());
  std::memcpy(record.data() + 18, &id, 2);
  std::memcpy(record.data() + 20, &length, 2);
  std::memcpy(record.data() + 22, "extra bytes", 11);
  for (const ExtraField& field : writer.extras_.fields) {
    const std::vector<std::byte> descriptor = lasExtraBytesDescriptor(field);
    record.insert(record.end(), descriptor.begin(), descriptor.end());
  }
  LODFORGE_TRY(writer.out_.write(record.data(), record.size()));
  return writer;
}

std::uint32_t LasWriter::pointOffset() const {
  if (extras_.stride == 0) return 227;
  return static_cast<std::uint32_t>(227 + kVlrHeader + kExtraDescriptor * extras_.fields.size());
}

// The public header block of LAS 1.2 (227 bytes; the Extra Bytes record, if any, follows).
std::array<std::byte, 227> LasWriter::header() const {
  std::array<std::byte, 227> h{};
  std::memcpy(h.data(), "LASF", 4);
  h[24] = std::byte{1};
  h[25] = std::byte{2};
  std::memcpy(h.data() + 26, "lodforge", 8);
  std::memcpy(h.data() + 58, software_.data(), std::min<std::size_t>(software_.size(), 31));
  put<std::uint16_t>(h, 94, 227);
  put<std::uint32_t>(h, 96, pointOffset());
  put<std::uint32_t>(h, 100, extras_.stride == 0 ? 0u : 1u);
  put<std::uint8_t>(h, 104, 3);
  put<std::uint16_t>(h, 105, static_cast<std::uint16_t>(recordSize()));
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

Status LasWriter::write(std::span<const LasPoint3> points, std::span<const std::byte> extras) {
  const std::size_t stride = extras_.stride;
  if (extras.size() != points.size() * stride)
    return Error{ErrorKind::kInternal,
                 fmt::format("{}: {} extra bytes for {} points of {}", out_.path(), extras.size(),
                             points.size(), stride)};
  std::vector<std::byte> records(points.size() * recordSize());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LasPoint3& p = points[i];
    std::byte* r = records.data() + i * recordSize();
    if (stride != 0) std::memcpy(r + kLasFormat3Size, extras.data() + i * stride, stride);
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
