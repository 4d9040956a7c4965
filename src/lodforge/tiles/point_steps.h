// The steps of a point tileset (point_tiles.h), shared by the one-process build and the build
// across the ranks of a job (point_ranks.h): rank a block, choose the tolerances, count each
// block's points per depth, make the tile tree, write the contents and tileset.json.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/directory.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/space_release.h"
#include "lodforge/core/status.h"
#include "lodforge/points/build.h"
#include "lodforge/points/partition.h"
#include "lodforge/tiles/point_tiles.h"

namespace lodforge {

// One block, ranked: its points sorted by their key, highest first, in `path` from `first` on
// and the keys in `keysPath` (from `first` on too). A point's key is the tile error of the parent
// of the highest node it represents (+∞ for the root's): the cut at τ holds the point exactly when
// τ < key, so a tile at depth d (tolerance τ_d, non-increasing with d) holds a prefix of the sorted
// block whatever the τ turn out to be.
struct BlockTiles {
  std::string name;            // the partition's block name ("b0110")
  std::string path, keysPath;  // the ranked records and their keys (each from `first` on)
  std::string extrasPath;      // their extra bytes in step (from `first` on), if any
  PointRecordLayout layout;    // of the records
  std::uint64_t first = 0;
  std::vector<std::uint64_t> counts;  // per depth 0..depth of the block, once the τ are known
  Aabbd bounds;
  float rootError = 0;
  float leastError = 0;  // the least tile error in the block's tree
};

// The work file of every block's keys (`BlockTiles::keysPath`): a block's keys at its records'
// place, record i's key at float i.
std::string pointKeysPath(const std::string& workDirectory);

// Sorts the block's points by key (the caller writes them back in that order, with the ids'
// extra bytes) and writes the keys into the keys file of `workDirectory`.
Status rankBlock(std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                 const PointBlock& block, bool hasNormals, const PointTilesOptions& options,
                 const std::string& workDirectory, BlockTiles& out);

// τ_d per depth of the partition tree (the median over up to 8 sample blocks' keys).
Result<std::vector<float>> toleranceSchedule(const Partition& partition,
                                             std::span<const BlockTiles> blocks,
                                             const PointTilesOptions& options, int maxDepth);
// Each block's points per depth once the τ are known.
Status countLevels(const Partition& partition, std::span<const float> taus,
                   std::span<BlockTiles> blocks);

struct TileNode {
  std::string name;
  int depth = 0;
  std::vector<std::size_t> blocks;    // under it
  std::vector<std::string> children;  // names
  Aabbd bounds;
  std::uint64_t points = 0;  // in its own content
  std::string uri;           // empty when it has no content
};
// Every prefix of a block's name is a tile; those with points get a content URI.
std::map<std::string, TileNode> tileTree(std::span<const BlockTiles> blocks);

// What a tile's GLB carries besides positions and normals: colours, the lidar attributes and
// the extra fields (each block's extras file).
struct ContentFields {
  bool colors = false;
  std::uint32_t attributes = 0;  // PointAttributeBit
  const PointExtras* extras = nullptr;
};
// Which tiles a rank writes: of `ranks`, the share of `rank` (the largest tiles first, each to
// the rank with the fewest points so far); all of them for a job of one.
struct ContentShare {
  int rank = 0, ranks = 1;
  bool resumed = false;  // tiles already in the folder (whole: written by rename) stay
};
struct ContentsWritten {
  std::uint64_t tiles = 0;  // of the share
  std::uint64_t kept = 0;   // of those, already there
};
// The GLB of every tile with points in this rank's share, in parallel. With `release` (one
// process only: a job's ranks read each other's blocks), each block's records are given to it
// once the last tile reading them is written: a resumed run reads only the blocks of tiles not
// yet written, and those are whole.
Result<ContentsWritten> writeContents(const std::map<std::string, TileNode>& nodes,
                                      std::span<const BlockTiles> blocks,
                                      const PointTilesOptions& options, const ContentFields& fields,
                                      const std::string& tilesetDirectory, ContentShare share = {},
                                      SpaceRelease* release = nullptr);

Status writePointTilesetJson(const std::map<std::string, TileNode>& nodes,
                             std::span<const BlockTiles> blocks, const std::vector<float>& taus,
                             const std::optional<Mat4d>& rootTransform, bool quantized,
                             const std::string& path);

// Where a point tileset is built: `pointWorkDirectory(output)`, below the tiles work directory.
std::string pointWorkDirectory(const std::string& outputDirectory);
// What a point run removes when it ends: on success the whole work directory, unless another
// run's work is kept there (then the point folder); on failure nothing once the input is split
// (pointWorkKept), so that --resume can go on.
struct PointWorkScope {
  ScopedDirectory directory;
  std::string work;  // the point work directory
  bool finished = false;
  PointWorkScope() = default;
  PointWorkScope(const PointWorkScope&) = delete;
  PointWorkScope& operator=(const PointWorkScope&) = delete;
  ~PointWorkScope();
};
// Claims the output and the tiles work directory, locked (WorkLock) so that a second run on the
// same output is refused. Without `resume`, makes the point work directory afresh with its
// folders (resetPointWork); with it, keeps an earlier run's work (the caller resets it when that
// is not what it can go on from) but removes the temporaries a killed run left in the staged
// tileset (they would be renamed into the output with it).
Status claimPointWorkPlace(const std::string& input, const std::string& outputDirectory,
                           bool resume, WorkLock& lock, PointWorkScope& scope);
// The point work directory emptied, with its staging folder (`/tileset/tiles`) and `/nodes`.
Status resetPointWork(const std::string& workDirectory);

// The local east-north-up frame of the CRS (given, or the input's), if any; `hasNormals` and
// the stats' CRS from the input.
Result<std::optional<CrsToLocal>> localFrame(const std::string& input,
                                             const PointTilesOptions& options,
                                             PointTilesStats& stats, bool& hasNormals);
// Where the root sits on Earth: the local frame of the CRS, or --origin's; none without either.
std::optional<Mat4d> rootTransformOf(const std::optional<CrsToLocal>& frame,
                                     const PointTilesOptions& options);
// The partition's options for point tiles (no sink): records with byte or float normals, the
// frame applied as points are read.
PartitionOptions pointPartitionOptions(const PointTilesOptions& options,
                                       const PointMemoryPlan& plan,
                                       const std::optional<CrsToLocal>& frame,
                                       const std::string& workDirectory);
// What the partition read into the stats: counts, attributes, warnings, the deepest block.
void noteStats(const Partition& partition, const PointTilesOptions& options,
               PointTilesStats& stats);

}  // namespace lodforge
