// A LAS 1.2 writer for point format 3 (the common airborne layout: returns, classification,
// intensity, scan angle, point source, GPS time, 16-bit RGB), with extra bytes if asked (and the
// Extra Bytes record that describes them), streaming: records are written as they come, and the
// header's counts and bounds are filled in by finish().
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "lodforge/core/file.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge {

inline constexpr std::size_t kLasFormat3Size = 34;

struct LasPoint3 {
  Vec3d position;
  std::uint16_t intensity = 0;
  std::uint8_t returnNumber = 1, numberOfReturns = 1;  // 1..5
  std::uint8_t classification = 1;                     // ASPRS class, 0..31
  std::int8_t scanAngle = 0;                           // degrees
  std::uint16_t pointSource = 0;
  double gpsTime = 0;
  std::array<std::uint16_t, 3> rgb{};
};

class LasWriter {
 public:
  // Coordinates are stored as integers of `scale` from `offset`; each record ends with
  // extras.stride extra bytes.
  static Result<LasWriter> create(const std::string& path, Vec3d scale, Vec3d offset,
                                  std::string generatingSoftware, PointExtras extras = {});
  // `extras`: extras.stride bytes a point (or none when the writer has no extra bytes).
  Status write(std::span<const LasPoint3> points, std::span<const std::byte> extras = {});
  // Fills in the point counts (by return) and the bounds, and renames the file into place.
  Status finish();
  std::uint64_t fileBytes() const { return out_.bytesWritten(); }

 private:
  LasWriter(OutputFile out, Vec3d scale, Vec3d offset, std::string software, PointExtras extras);
  std::size_t recordSize() const { return kLasFormat3Size + extras_.stride; }
  std::uint32_t pointOffset() const;
  std::array<std::byte, 227> header() const;

  OutputFile out_;
  Vec3d scale_, offset_;
  std::string software_;
  PointExtras extras_;
  std::uint64_t points_ = 0;
  std::array<std::uint32_t, 5> byReturn_{};
  Aabbd bounds_;
};

}  // namespace lodforge
