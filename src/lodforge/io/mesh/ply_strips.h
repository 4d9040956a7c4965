// A PLY's triangle strips (a 'tristrips' element, a strip per element): triangle k of a run is
// (i[k], i[k+1], i[k+2]), every other one turned so that all face the way the first does; -1
// (the all-ones value of an unsigned index type) restarts the run, and triangles that repeat an
// index (how strips join and turn) are dropped. Read through PlyRecords (ply_records.h) for
// PlyReader, which numbers the triangles after the faces.
#pragma once

#include <cstddef>
#include <cstdint>

#include "lodforge/io/mesh/ply_records.h"

namespace lodforge {

class PlyStrips {
 public:
  explicit PlyStrips(PlyRecords& in) : in_(in) {}

  // Reads strips of the current element into `batch` until it holds about options.batchSize
  // triangles, from as many strips as that takes. A strip longer than that (igea is one strip of
  // 268 K triangles) goes on in the next call.
  void read(PlyBatch& batch);

  // A pass over the strips alone (the elements before them skipped, by seeking where they have
  // a fixed size) that counts their triangles. Salvaging, it counts those before the cut.
  static std::uint64_t countTriangles(PlyRecords& in);

 private:
  void begin(const PlyElement& e);
  void readIndices(const PlyElement& e, PlyBatch& batch, std::size_t limit);
  void addIndex(double raw, PlyType type, std::uint64_t at, PlyBatch& batch);

  PlyRecords& in_;
  // Where the strip being read stands; it carries over from one batch to the next.
  struct Strip {
    bool open = false;           // its length is read, not all its indices yet
    std::uint64_t left = 0;      // indices still to read
    std::uint64_t run = 0;       // indices since the strip began or restarted
    std::uint32_t a = 0, b = 0;  // the last two indices of the run
  } strip_;
};

}  // namespace lodforge
