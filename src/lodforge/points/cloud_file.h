// The point package: `cloud.lfc` holds the header, the coordinate system, the block table (the
// paper's Segment Info: centroid, bounds) and every block's Part II; `cloud.lfs/` beside it holds
// one segment file per block with its Part III breadth-first (points paper §4.2, Fig. 8). Both
// carry a magic, a version, a checksum and the build's id, so a stale segment directory is
// caught. Layouts in docs/formats.md.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/points/cluster.h"

namespace lodforge {

inline constexpr char kCloudMagic[8] = {'L', 'F', 'C', 'L', 'O', 'U', 'D', '\0'};
inline constexpr char kSegmentMagic[8] = {'L', 'F', 'S', 'E', 'G', 'M', 'T', '\0'};
inline constexpr std::uint32_t kCloudVersion = 1;

enum CloudFlags : std::uint32_t {
  kCloudInputNormals = 1,  // normals came from the input (else estimated)
  kCloudInputColors = 2,   // colours came from the input (else white)
};

struct CloudHeader {
  char magic[8];
  std::uint32_t version = kCloudVersion;
  std::uint32_t flags = 0;
  std::uint64_t buildId = 0;  // also in every segment file of this build
  std::uint64_t pointCount = 0;
  std::uint64_t blockCount = 0;
  std::uint64_t residentCount = 0;  // Part II records over all blocks
  std::uint64_t segmentCount = 0;   // Part III records over all blocks
  std::uint64_t droppedCount = 0;   // Part I nodes over all blocks
  double tolerance = 0;             // the cut's error tolerance (metres)
  Aabbd bounds;
  std::uint32_t crsBytes = 0;  // the CRS text right after the header, padded to 8 bytes
  std::uint32_t reserved = 0;
};
static_assert(sizeof(CloudHeader) == 128);

struct CloudBlock {
  Aabbd bounds;
  Vec3d origin;  // the block's centroid: node positions are relative to it
  std::uint64_t pointCount = 0;
  std::uint64_t residentFirst = 0;  // into the resident records
  std::uint32_t residentCount = 0;
  std::uint32_t segmentCount = 0;  // records in the block's segment file
  float maxError = 0;              // the block root's error
  float residentError = 0;         // the largest error in Part II
};
static_assert(sizeof(CloudBlock) == 104);

// Claims `output` (a .lfc) and its segment directory for a package of `input` before any work:
// each is replaced only when it is a package (by its magic) or a segment directory (nothing but
// block-NNNNNN.seg files) that lodforge wrote.
Status claimPointPackageOutput(const std::string& input, const std::string& output);

// Where a package keeps its segment files: "x.lfc" -> "x.lfs".
std::string segmentDirectoryFor(const std::string& cloudPath);
std::string segmentFileName(std::uint64_t block);

// A package opened in place (mmap); the header, table and Part II are checked on open.
class CloudFile {
 public:
  static Result<CloudFile> open(const std::string& path);
  // The same checks over bytes the caller keeps alive (8-byte aligned), named `name`; segment
  // files are then looked for beside `name`.
  static Result<CloudFile> fromBytes(std::span<const std::byte> bytes, const std::string& name);
  const CloudHeader& header() const { return header_; }
  const std::string& crs() const { return crs_; }
  std::span<const CloudBlock> blocks() const { return blocks_; }
  std::span<const ClusterNode> resident() const { return resident_; }
  std::span<const ClusterNode> residentOf(std::size_t block) const {
    return resident_.subspan(blocks_[block].residentFirst, blocks_[block].residentCount);
  }
  // A block's Part III, read from its segment file and checked.
  Result<std::vector<ClusterNode>> loadSegment(std::size_t block) const;
  const std::string& path() const { return path_; }

 private:
  CloudFile() = default;
  static Result<CloudFile> parse(CloudFile cloud);
  std::optional<MappedFile> file_;
  std::span<const std::byte> bytes_;
  std::string path_;
  CloudHeader header_{};
  std::string crs_;
  std::span<const CloudBlock> blocks_;
  std::span<const ClusterNode> resident_;
};

// Checks the child links of Part II and Part III records against the segment's length.
bool childLinksValid(std::span<const ClusterNode> nodes, std::size_t segmentCount);

// Writes one block's segment file.
Status writeSegmentFile(const std::string& path, std::uint64_t buildId, std::uint64_t block,
                        std::span<const ClusterNode> segment);

// Writes the .lfc: header (counts filled from the table), CRS, table and resident records.
Status writeCloudFile(const std::string& path, CloudHeader header, const std::string& crs,
                      std::span<const CloudBlock> blocks, std::span<const ClusterNode> resident);
// The same with each block's Part II fetched when it is written (blocks[b].residentCount
// records), so the package is written without holding all of Part II.
using ResidentSource = std::function<Result<std::vector<ClusterNode>>(std::size_t block)>;
Status writeCloudFile(const std::string& path, CloudHeader header, const std::string& crs,
                      std::span<const CloudBlock> blocks, const ResidentSource& residentOf);

}  // namespace lodforge
