// The point pipeline's work records on disk: a CloudPoint (64 bytes in memory) written with only
// what the input has. Positions on a LAS grid go as the file's own 32-bit integers (exact: the
// reader computed them from those), others as doubles; a normal, a colour and the lidar fields
// only when the input has them. An airborne LAS of format 3 takes 40 bytes a point instead of
// 64: fewer new page-cache pages for the kernel to find, which was most of the gap to
// PotreeConverter (docs/BENCHMARKS.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/point_reader.h"

namespace lodforge {

// One point as the pipeline holds it in memory (64 bytes): double position, normal (zero when
// the input has none), colour (white when it has none), lidar attributes (zero when it has
// none). Extra fields travel in a second work file, moved in step.
struct CloudPoint {
  Vec3d position;
  Vec3f normal;
  Rgba8 color;
  PointAttributes attributes;
};
static_assert(sizeof(CloudPoint) == 64);

// What a record keeps of the normal: the input's (nothing when it has none); always three
// floats (the pipeline computes them); or, for an input without normals whose computed ones are
// only drawn, three signed bytes (127 × each axis, rounded: 4 bytes instead of 12; point tiles
// store normals that are whole bytes over 127 already, so nothing is lost).
enum class RecordNormals { kInput, kFloat, kBytes };

class PointRecordLayout {
 public:
  PointRecordLayout() = default;  // every field, positions as doubles (64 bytes)
  // What an input's points need. `placed`: positions are transformed on reading (a CRS), so
  // they leave the file's grid.
  static PointRecordLayout of(const PointCloudInfo& info, bool placed,
                              RecordNormals normals = RecordNormals::kInput);

  std::size_t bytes() const { return bytes_; }
  bool gridded() const { return gridded_; }
  // Normals kept as bytes: decode gives each axis as byte / 127, and 127 × that rounds back to
  // the byte exactly.
  bool normalBytes() const { return normalBytes_; }
  // Writes points.size() records to `out` (bytes() each). Fails (kInternal) on a position the
  // grid does not hold exactly, which a reader's own grid never gives.
  Status encode(std::span<const CloudPoint> points, std::byte* out) const;
  // Reads points.size() records from `in`; what the layout leaves out comes back as the pipeline's
  // defaults (no normal, white, no lidar fields).
  void decode(const std::byte* in, std::span<CloudPoint> points) const;
  // The position of the record at `record` (bytes() long), exactly as decode gives it.
  Vec3d position(const std::byte* record) const {
    Vec3d p;
    if (gridded_) {
      for (int k = 0; k < 3; ++k) {
        std::int32_t integer;
        std::memcpy(&integer, record + static_cast<std::size_t>(k) * sizeof integer,
                    sizeof integer);
        p[k] = static_cast<double>(integer) * grid_.scale[k] + grid_.offset[k];
      }
    } else {
      std::memcpy(&p, record, sizeof p);
    }
    return p;
  }

 private:
  bool gridded_ = false, normals_ = true, normalBytes_ = false, colors_ = true, attributes_ = true;
  PointCloudInfo::Grid grid_{};
  Vec3d inverseScale_{1, 1, 1};
  std::size_t bytes_ = sizeof(CloudPoint);
};

}  // namespace lodforge
