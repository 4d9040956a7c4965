// A point tileset built by the ranks of a job (docs/distributed.md). Rank 0 reads and partitions
// the input, putting each block in a queue on the shared file system as soon as it is written;
// every rank ranks blocks from that queue (rank 0 too, once its partition is done), so the
// ranking runs beside the partition; rank 0 chooses the tolerances and counts each block's
// levels; every rank writes its share of the tiles; rank 0 writes tileset.json. The tileset is
// byte for byte the one a single process writes.
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiles/point_tiles.h"

namespace lodforge {

Result<PointTilesStats> writePointTilesAcrossRanks(const std::string& input,
                                                   const std::string& outputDirectory,
                                                   const PointTilesOptions& options);

}  // namespace lodforge
