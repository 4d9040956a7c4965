// Point clouds as 3D Tiles 1.1 (refine ADD): the block partition of the points paper (§4.1) is
// the tile tree, and each block's clustering tree decides which points go up. Every cluster node
// is represented by one of its own points, chosen so that a parent's representative is one of
// its children's (so coarser cuts are subsets of finer ones). A tile at depth d holds the
// representatives of its blocks' cut at tolerance τ_d that no shallower tile holds; a block's
// own tile holds the rest: every input point appears in exactly one tile. Contents are glTF
// POINTS with COLOR_0 and NORMAL.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/points/cluster.h"
#include "lodforge/tiles/georeference.h"

namespace lodforge {

struct PointTilesOptions {
  std::uint64_t blockSize = 50'000;   // points per leaf tile at most
  std::uint64_t tilePoints = 50'000;  // about this many points in a tile above the blocks
  ClusterOptions cluster;
  std::uint64_t memoryLimit = 0;  // bytes, 0: the partition's default
  // Georeferencing: the input's CRS (default: the one its LAS file names) through PROJ, or its
  // (0, 0, 0) placed at `origin` with x east, y north, z up.
  std::string crs;
  std::optional<Geodetic> origin;
  bool quantize = true;  // KHR_mesh_quantization positions (16-bit over the tile's box)
  bool meshoptCompression = false;
  bool salvageTruncated = false;
  // Go on from an interrupted run's work (the same input and options), as far as it got.
  bool resume = false;
  // The lidar fields to carry (PointAttributeBit), of those the input has: all by default.
  std::uint32_t attributes = ~std::uint32_t{0};
};

struct PointTilesStats {
  std::uint64_t points = 0, blocks = 0, tiles = 0;
  int depth = 0;  // of the deepest block tile
  std::string crs;
  std::uint32_t attributes = 0;       // the lidar fields the tiles carry
  std::vector<std::string> warnings;  // what was read past, what viewers may not manage
  std::uint64_t outputBytes = 0;
  double seconds = 0;
  // --resume: whether the split input was taken as an interrupted run left it, and how many of
  // the partition's nodes (ranked) and tiles (written) were.
  bool resumed = false;
  std::uint64_t nodes = 0;  // the partition's nodes split in memory
  std::uint64_t nodesResumed = 0, tilesResumed = 0;
  // A job of several ranks (point_ranks.h): how many, whether the input was read in slices,
  // each rank's split and ranked points and written tiles (rank order), the seconds to the end
  // of the reading, of the streamed splits and of the ranking, and each rank's stages.
  int ranks = 1;
  bool readInSlices = false;
  std::vector<std::uint64_t> rankPoints, rankTiles;
  double readSeconds = 0, partitionSeconds = 0, rankingSeconds = 0;
  std::vector<std::string> rankStages;
};

// A node's "tile error" for point tiles: the largest of the clustering error E, the square's
// radius (a flat cluster is fitted well but still stands for a patch that wide) and `reach`
// (representativeReach: no point the node stands for is farther from the one point kept for it).
float pointTileError(const ClusterNode& node, float reach);

// One representative input point per cluster node (indices into the block's points, as
// clusterBlock left them): a leaf's own point; a parent's, the child representative nearest
// its centroid.
std::vector<std::uint32_t> clusterRepresentatives(std::span<const ClusterNode> tree,
                                                  std::span<const CloudPoint> points,
                                                  std::span<const std::uint32_t> firstPoint,
                                                  Vec3d origin);

// Per node, a bound on how far any point under it is from its representative (`reps`): 0 at a
// leaf, and at a parent the largest over its children of the distance between the two
// representatives plus the child's reach (the triangle inequality), rounded up to float.
// Non-decreasing towards the root.
std::vector<float> representativeReach(std::span<const ClusterNode> tree,
                                       std::span<const std::uint32_t> reps,
                                       std::span<const CloudPoint> points);

// Each point's key (indexed like `points`, from the tree's representatives `reps`): the tile
// error of the parent of the highest node the point represents, +∞ for the root's. The cut of
// the tree at τ holds the point exactly when τ < its key, whatever τ (so a block can be ranked
// before the tolerances are known).
std::vector<float> pointKeys(std::span<const ClusterNode> tree,
                             std::span<const std::uint32_t> reps);

// The order a block's points are written in: by key (non-negative, +∞ allowed), highest first,
// ties in index order (what a stable sort by descending key gives).
std::vector<std::uint32_t> descendingKeyOrder(std::span<const float> key);

// `lodforge tiles cloud.las`: the whole pipeline into `outputDirectory` (written under a
// temporary name and renamed when complete).
Result<PointTilesStats> writePointTiles(const std::string& input,
                                        const std::string& outputDirectory,
                                        const PointTilesOptions& options);

}  // namespace lodforge
