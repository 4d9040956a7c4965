// A batch of points as every point reader yields it: double positions (geo-scale coordinates
// keep their millimetres), and normals, colours or lidar attributes when the file has them.
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

// The lidar fields of a LAS point (24 bytes, carried through the point pipeline's work files);
// PointCloudInfo::attributes says which of them the input has.
struct PointAttributes {
  double gpsTime = 0;
  float scanAngle = 0;  // degrees (formats 0–5 store whole degrees, 6–10 steps of 0.006°)
  std::uint16_t intensity = 0, pointSource = 0, nir = 0;
  std::uint8_t classification = 0;
  std::uint8_t returnNumber = 0, numberOfReturns = 0;
  // Classification flags (bits 0–3: synthetic, key-point, withheld, overlap), scanner channel
  // (4–5), scan direction (6), edge of flight line (7): LAS 1.4's byte 15.
  std::uint8_t flags = 0;
  std::uint8_t userData = 0;
  std::uint8_t unused = 0;
};
static_assert(sizeof(PointAttributes) == 24);

// Which PointAttributes fields an input has (a bit each).
enum PointAttributeBit : std::uint32_t {
  kAttrIntensity = 1u << 0,
  kAttrClassification = 1u << 1,
  kAttrReturns = 1u << 2,  // return number and number of returns
  kAttrFlags = 1u << 3,
  kAttrScanAngle = 1u << 4,
  kAttrUserData = 1u << 5,
  kAttrPointSource = 1u << 6,
  kAttrGpsTime = 1u << 7,
  kAttrNir = 1u << 8,
  kAttrExtras = 1u << 9,  // the fields of PointCloudInfo::extras (LAS extra bytes, PLY others)
};

struct PointBatch {
  std::uint64_t first = 0;  // index of the batch's first point in the file
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;               // empty, or one per point
  std::vector<Rgba8> colors;                // empty, or one per point
  std::vector<PointAttributes> attributes;  // empty, or one per point
  std::vector<std::byte> extras;            // PointExtras::stride bytes per point, or empty

  std::size_t size() const { return positions.size(); }
  void clear() {
    positions.clear();
    normals.clear();
    colors.clear();
    attributes.clear();
    extras.clear();
  }
};

}  // namespace lodforge
