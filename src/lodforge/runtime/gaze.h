// Gaze-driven LOD selection and block paging over a point package (points paper §4.1 "View-
// dependent LOD selection", §4.2 "Data structures" and "View-dependent paging"). Part II of
// every visible block is always drawn; inside the fovea (and, less and less, around it) nodes
// whose splats look too big refine through their block's Part III, when that block is resident.
// A fixed number of blocks is resident; which ones is decided by the distance from the gaze to
// each block's bounds, then least recent use.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/points/cloud_file.h"
#include "lodforge/runtime/camera.h"

namespace lodforge {

// The fovea on the screen (Fig. 6a): a gaze point, a circle around it at full resolution, and a
// degradation function beyond.
struct FoveaOptions {
  double gazeX = -1, gazeY = -1;  // pixels from the top left; negative: the screen's centre
  double radius = 200;            // pixels of full resolution around the gaze
  double fovealSplat = 2;         // largest splat diameter (pixels) allowed inside the fovea
  // Beyond the fovea the allowed diameter grows linearly: ×(1 + falloff) one radius further.
  double falloff = 2;
};

// The degradation function: the largest splat diameter (pixels) allowed at `distance` pixels
// from the gaze.
double allowedSplatPixels(const FoveaOptions& fovea, double distance);

// The Segment Info table and the resident segments (Fig. 9).
class BlockPager {
 public:
  struct SegmentInfo {
    Vec3d centroid;
    Aabbd bounds;
    std::uint64_t calls = 0;     // frames the block was refined in (the paper's call_times)
    std::uint64_t lastUsed = 0;  // frame of the last call
    double gazeDistance = 0;     // this frame's, from the gaze ray to the bounds (∞: unseen)
    bool resident = false;
  };
  struct Request {
    std::uint32_t block = 0;
    double gazeDistance = 0;  // from the gaze ray to the block's bounds
  };

  BlockPager(const CloudFile& cloud, std::size_t residentBlocks, std::size_t loadsPerFrame);

  const std::vector<SegmentInfo>& info() const { return info_; }
  // The block's Part III, or nullptr when it is not resident.
  const std::vector<ClusterNode>* segment(std::uint32_t block) const;
  // Marks a block refined this frame as used.
  void touch(std::uint32_t block, std::uint64_t frame);
  void setGazeDistance(std::uint32_t block, double distance) {
    info_[block].gazeDistance = distance;
  }
  // Pages in the wanted blocks nearest the gaze (at most loadsPerFrame), evicting the least
  // recently used block not refined this frame, or else the resident one farthest from the gaze
  // if the newcomer is nearer. Returns how many blocks were loaded.
  Result<std::size_t> update(std::vector<Request> wanted, std::uint64_t frame);
  std::size_t residentCount() const;
  std::uint64_t loads() const { return loads_; }

 private:
  const CloudFile& cloud_;
  std::size_t capacity_, loadsPerFrame_;
  std::vector<SegmentInfo> info_;
  std::vector<std::vector<ClusterNode>> segments_;
  std::uint64_t loads_ = 0;
};

// What a frame draws: splats in flat arrays, positions relative to `origin`.
struct PointSelection {
  Vec3d origin;
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<float> radii;
  std::uint64_t inputPoints = 0;  // input points the drawn splats stand for
  std::uint32_t visibleBlocks = 0, refinedBlocks = 0;
  std::vector<BlockPager::Request> wanted;  // blocks that would refine if resident
  void clear();
  std::size_t size() const { return positions.size(); }
};

// One frame's selection (the paper's Fig. 6b/7) with the pager's resident segments; fills
// `out.wanted` for BlockPager::update.
void selectPoints(const CloudFile& cloud, BlockPager& pager, const Camera& camera,
                  const FoveaOptions& fovea, std::uint64_t frame, PointSelection& out);

}  // namespace lodforge
