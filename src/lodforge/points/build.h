// `lodforge points INPUT -o cloud.lfc` (points paper §4.1): partition into blocks, then per block
// (in parallel) normals, clustering tree, LOD cut; Part II into the package, Part III into the
// block's segment file.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/points/cluster.h"

namespace lodforge {

struct PointsBuildOptions {
  std::uint64_t blockSize = 50'000;
  // The cut's error tolerance in metres; 0 picks the one that keeps about `residentShare` of
  // the points as Part II nodes (the median over up to 8 sample blocks).
  double tolerance = 0;
  double residentShare = 1.0 / 32;
  ClusterOptions cluster;
  std::uint64_t memoryLimit = 0;  // bytes for the whole build, 0: 256 MiB of points when splitting
  std::uint64_t splitBytes = 0;   // points split in memory (bytes); 0: planned from the limit
  std::string workDirectory;      // default: beside the output
  bool salvageTruncated = false;  // a PLY cut short: read up to its last whole point
};

// Under --memory-limit: what the process already holds, then the blocks in flight (as many
// threads as fit in half of what is left), and the rest for splitting in memory. A limit below
// what one block needs is refused (kLimit) with the least that works.
struct PointMemoryPlan {
  int threads = 1;
  std::uint64_t partitionBytes = 0;  // points held in memory while splitting
};
Result<PointMemoryPlan> planPointMemory(std::uint64_t memoryLimit, std::uint64_t blockSize);

struct PointsBuildStats {
  std::uint64_t points = 0, blocks = 0;
  std::uint64_t residentNodes = 0, segmentNodes = 0, droppedNodes = 0;
  std::uint64_t minBlock = 0, maxBlock = 0;  // points per block
  double tolerance = 0;
  bool estimatedNormals = false;
  int threads = 0;  // blocks built at once (fewer than asked when the memory limit is tight)
  int streamedPasses = 0;
  double seconds = 0, partitionSeconds = 0;
  std::uint64_t outputBytes = 0;          // package and segment files
  std::optional<std::string> truncation;  // where a salvaged input was cut short
  std::vector<std::string> warnings;      // what the reader read past (PointCloudInfo)
};

Result<PointsBuildStats> buildPointCloud(const std::string& input, const std::string& output,
                                         const PointsBuildOptions& options);

}  // namespace lodforge
