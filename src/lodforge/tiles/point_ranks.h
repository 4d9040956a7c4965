// A point tileset built by the ranks of a job (docs/distributed.md). Every rank reads a slice of
// the input into the shared work files where its format allows (an uncompressed LAS, a binary
// PLY; rank 0 reads the others alone); the partition's nodes too big for memory are split by
// streamed passes level by level, each level's nodes shared out among the ranks; every rank
// then splits its share of the remaining nodes in memory and ranks each block as it comes out,
// as one process does; rank 0 chooses the tolerances and counts each block's levels; every rank
// writes its share of the tiles; rank 0 writes tileset.json. The tileset is byte for byte the
// one a single process writes.
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiles/point_tiles.h"

namespace lodforge {

Result<PointTilesStats> writePointTilesAcrossRanks(const std::string& input,
                                                   const std::string& outputDirectory,
                                                   const PointTilesOptions& options);

}  // namespace lodforge
