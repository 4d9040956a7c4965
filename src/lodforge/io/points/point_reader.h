// One streaming reader for every point format: LAS (.las; .laz is refused with advice), PLY
// (the vertices of any PLY; faces are ignored), and XYZ/TXT/CSV/PTS text. Chosen by extension.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/io/points/point_batch.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge {

struct PointCloudInfo {
  std::string format;                  // e.g. "LAS 1.2, point format 3"
  std::optional<std::uint64_t> count;  // unknown for text until it is read
  std::optional<Aabbd> bounds;         // as a LAS header states it
  std::string crs;                     // WKT or "EPSG:N" from a LAS file; empty when unknown
  bool hasNormals = false, hasColors = false;
  std::uint32_t attributes = 0;       // PointAttributeBit: the lidar fields a LAS or LAZ has
  PointExtras extras;                 // documented extra bytes, other PLY vertex properties
  std::vector<std::string> warnings;  // what is read past (a damaged Extra Bytes record, …)
};

// Whether `path` names a point file by its extension (las laz xyz txt csv pts); a PLY may hold
// either, so the caller decides.
bool isPointCloudPath(const std::string& path);

class PointReader {
 public:
  // With `salvageTruncated`, a PLY cut short is read up to its last whole point (truncation()
  // then says where it was cut); otherwise it is bad input. Without `extras`, batches carry no
  // extra fields (and info().extras is empty).
  static Result<PointReader> open(const std::string& path, std::size_t batchSize = 1 << 16,
                                  bool salvageTruncated = false, bool extras = true);
  PointReader(PointReader&&) noexcept;
  PointReader& operator=(PointReader&&) noexcept;
  ~PointReader();

  const PointCloudInfo& info() const;
  // Where a salvaged file was cut short (after the last batch); empty if it was whole.
  std::optional<std::string> truncation() const;
  // The next batch; false when the file is done.
  Result<bool> next(PointBatch& batch);

 private:
  struct State;
  explicit PointReader(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
