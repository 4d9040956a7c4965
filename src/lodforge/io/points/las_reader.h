// LAS reader (ASPRS LAS 1.0–1.4, point formats 0–10, uncompressed): the header, the variable
// length records that carry the coordinate system (OGC WKT, or GeoTIFF keys naming an EPSG
// code), and the points streamed in batches with scale and offset applied in double precision.
// LAZ (LASzip-compressed, COPC included) is decoded as it is read (io/points/laz/laz_reader): the
// records come out as the LAS file of the same points would hold them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/laz/laz_vlr.h"
#include "lodforge/io/points/point_batch.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge {

struct LasHeader {
  int versionMajor = 1, versionMinor = 2;
  int pointFormat = 0;
  std::uint16_t headerSize = 0;
  std::uint16_t recordLength = 0;  // bytes per point record (the format's size plus extra bytes)
  std::uint32_t pointOffset = 0;   // byte where the point records start
  std::uint32_t vlrCount = 0;
  std::uint64_t pointCount = 0;  // the 64-bit count of LAS 1.4 where it is set
  Vec3d scale{1, 1, 1}, offset;
  Aabbd bounds;  // as the header states it
  std::string systemIdentifier, generatingSoftware;
  // Coordinate system: WKT (record 2112) when present, else "EPSG:N" from the GeoTIFF keys
  // (projected, else geographic); empty when the file names none.
  std::string crs;
  bool hasColors = false;
  // Colours are 16-bit in the spec, but many writers store 0–255: true when the first points'
  // colours all fit in 8 bits, and then they are taken as they are.
  bool eightBitColors = false;
  // LAZ: the point data is compressed (the format byte's top bits); what LASzip wrote it with,
  // and whether a COPC record ("copc", 1) says it is in COPC order.
  bool compressed = false;
  std::optional<LazInfo> laz;
  bool copc = false;
  std::uint32_t attributes = 0;  // PointAttributeBit: the lidar fields of the point format
  // The record's bytes past its format's, as the Extra Bytes record describes them (none
  // carried when no record describes them, or when the record is damaged: then
  // `extrasIgnored` says why).
  PointExtras extras;
  std::string extrasIgnored;
};

// The smallest record of a point format (0–10), 0 for an unknown format.
std::uint16_t lasRecordSize(int pointFormat);

class LasReader {
 public:
  static Result<LasReader> open(const std::string& path, std::size_t batchSize = 1 << 16);
  static Result<LasReader> fromMemory(std::span<const std::byte> bytes, std::string name,
                                      std::size_t batchSize = 1 << 16);
  // The header and records alone, LAZ too (no point is read; colour depth is not probed).
  static Result<LasHeader> readHeader(const std::string& path);
  LasReader(LasReader&&) noexcept;
  LasReader& operator=(LasReader&&) noexcept;
  ~LasReader();

  const LasHeader& header() const;
  // From now on, batches leave the extra bytes out (header().extras becomes empty).
  void skipExtraBytes();
  // The next batch of points (positions, the lidar attributes, colours when the format has
  // them, and the extra bytes the header describes); false at the end of the point records.
  Result<bool> next(PointBatch& batch);
  // From now on, only points [first, first + count) (clipped to the file's): a slice, reached by
  // seeking in an uncompressed file and by decoding from the chunk that holds `first` in a LAZ
  // file (kUnsupported for one without a chunk table). Call before the first batch.
  Status restrictTo(std::uint64_t first, std::uint64_t count);
  // Or the next batch as the point records themselves (record length bytes each, decoded when
  // the file is LAZ); false at the end.
  Result<bool> nextRecords(std::vector<std::byte>& records);

 private:
  struct State;
  explicit LasReader(std::unique_ptr<State> state);
  static Result<LasReader> start(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
