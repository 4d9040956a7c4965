// One streaming reader for every point format: LAS and LAZ (.las, .laz, COPC; io/points/laz
// decodes LAZ), PLY (the vertices of any PLY; faces are ignored), and XYZ/TXT/CSV/PTS text.
// Chosen by extension.
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
  // LAS and LAZ: every position is offset + scale × a 32-bit integer, computed in that order in
  // double precision, so the integers hold the positions exactly (the work files keep them so).
  struct Grid {
    Vec3d scale, offset;
  };
  std::optional<Grid> grid;
};

// Whether `path` names a point file by its extension (las laz xyz txt csv pts); a PLY may hold
// either, so the caller decides.
bool isPointCloudPath(const std::string& path);

struct PointReadOptions {
  std::size_t batchPoints = 1 << 16;  // points a batch holds at most
  // A PLY cut short is read up to its last whole point (truncation() then says where it was
  // cut); without, it is bad input.
  bool salvageTruncated = false;
  // Extra fields (LAS extra bytes, other PLY vertex properties) in the batches and in
  // info().extras; without, both are empty.
  bool readExtras = true;
  // Only points [first, first + count): a slice of an uncompressed LAS or a binary PLY, reached
  // by seeking, or of a LAZ file from the chunk that holds `first`; other inputs (text, ascii
  // PLY, a LAZ file without a chunk table) refuse a slice (kUnsupported).
  std::uint64_t first = 0, count = ~std::uint64_t{0};
};

class PointReader {
 public:
  static Result<PointReader> open(const std::string& path, const PointReadOptions& options = {});
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
