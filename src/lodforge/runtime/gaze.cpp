#include "lodforge/runtime/gaze.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lodforge {

namespace {

double pointBoxDistance(Vec3d p, const Aabbd& box) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({box.min[k] - p[k], 0.0, p[k] - box.max[k]});
    sum += d * d;
  }
  return std::sqrt(sum);
}

// From the gaze ray to a block: the distance to its bounds of the ray's point nearest the
// block's centre (0 when the ray passes through the centre's neighbourhood inside the box).
double gazeDistance(Vec3d eye, Vec3d direction, const Aabbd& box) {
  const double t = std::max(0.0, dot(box.center() - eye, direction));
  return pointBoxDistance(eye + direction * t, box);
}

}  // namespace

double allowedSplatPixels(const FoveaOptions& fovea, double distance) {
  const double beyond = std::max(0.0, distance - fovea.radius) / std::max(1.0, fovea.radius);
  return fovea.fovealSplat * (1 + fovea.falloff * beyond);
}

BlockPager::BlockPager(const CloudFile& cloud, std::size_t residentBlocks,
                       std::size_t loadsPerFrame)
    : cloud_(cloud),
      capacity_(std::max<std::size_t>(1, residentBlocks)),
      loadsPerFrame_(std::max<std::size_t>(1, loadsPerFrame)),
      info_(cloud.blocks().size()),
      segments_(cloud.blocks().size()) {
  for (std::size_t b = 0; b < info_.size(); ++b) {
    info_[b].centroid = cloud.blocks()[b].origin;
    info_[b].bounds = cloud.blocks()[b].bounds;
  }
}

const std::vector<ClusterNode>* BlockPager::segment(std::uint32_t block) const {
  return info_[block].resident ? &segments_[block] : nullptr;
}

void BlockPager::touch(std::uint32_t block, std::uint64_t frame) {
  ++info_[block].calls;
  info_[block].lastUsed = frame;
}

std::size_t BlockPager::residentCount() const {
  return static_cast<std::size_t>(
      std::count_if(info_.begin(), info_.end(), [](const SegmentInfo& s) { return s.resident; }));
}

Result<std::size_t> BlockPager::update(std::vector<Request> wanted, std::uint64_t frame) {
  // Nearest the gaze first (§4.2: distance from the gaze, then LRU).
  std::sort(wanted.begin(), wanted.end(), [](const Request& a, const Request& b) {
    return a.gazeDistance != b.gazeDistance ? a.gazeDistance < b.gazeDistance : a.block < b.block;
  });
  std::size_t loaded = 0;
  for (const Request& r : wanted) {
    if (loaded == loadsPerFrame_) break;
    if (info_[r.block].resident) continue;
    if (residentCount() >= capacity_) {
      // The least recently used block not refined this frame; else the resident one farthest
      // from the gaze, if farther than the newcomer.
      std::size_t victim = info_.size();
      for (std::size_t b = 0; b < info_.size(); ++b) {
        const SegmentInfo& s = info_[b];
        if (!s.resident || s.lastUsed == frame) continue;
        if (victim == info_.size() || s.lastUsed < info_[victim].lastUsed) victim = b;
      }
      if (victim == info_.size()) {
        for (std::size_t b = 0; b < info_.size(); ++b) {
          const SegmentInfo& s = info_[b];
          if (s.resident && s.gazeDistance > r.gazeDistance &&
              (victim == info_.size() || s.gazeDistance > info_[victim].gazeDistance))
            victim = b;
        }
      }
      if (victim == info_.size()) break;
      info_[victim].resident = false;
      segments_[victim] = {};
    }
    Result<std::vector<ClusterNode>> segment = cloud_.loadSegment(r.block);
    if (!segment) return segment.status();
    segments_[r.block] = std::move(*segment);
    info_[r.block].resident = true;
    info_[r.block].lastUsed = frame;
    ++loaded;
    ++loads_;
  }
  return loaded;
}

void PointSelection::clear() {
  positions.clear();
  normals.clear();
  colors.clear();
  radii.clear();
  wanted.clear();
  inputPoints = 0;
  visibleBlocks = refinedBlocks = 0;
}

void selectPoints(const CloudFile& cloud, BlockPager& pager, const Camera& camera,
                  const FoveaOptions& fovea, std::uint64_t frame, PointSelection& out) {
  out.clear();
  out.origin = cloud.header().bounds.center();
  const ViewProjection view(camera);
  const double width = camera.width, height = camera.height;
  const double gx = fovea.gazeX < 0 ? width / 2 : fovea.gazeX;
  const double gy = fovea.gazeY < 0 ? height / 2 : fovea.gazeY;
  const Vec3d gazeDirection =
      normalizeOr(view.forward + view.right * ((gx - view.halfWidth) / view.halfWidth * view.tanX) +
                      view.up * ((view.halfHeight - gy) / view.halfHeight * view.tanY),
                  view.forward);
  const double pixelScale = camera.pixelScale();
  std::vector<const ClusterNode*> stack;
  for (std::uint32_t b = 0; b < cloud.blocks().size(); ++b) {
    const CloudBlock& block = cloud.blocks()[b];
    if (projectedArea(view, block.bounds.min, block.bounds.max) <= 0) {
      pager.setGazeDistance(b, std::numeric_limits<double>::infinity());
      continue;
    }
    const double fromGazeRay = gazeDistance(view.origin, gazeDirection, block.bounds);
    pager.setGazeDistance(b, fromGazeRay);
    ++out.visibleBlocks;
    const std::vector<ClusterNode>* segment = pager.segment(b);
    bool refined = false, wanted = false;
    stack.clear();
    for (const ClusterNode& n : cloud.residentOf(b)) stack.push_back(&n);
    const Vec3d toBlock = block.origin - view.origin;
    while (!stack.empty()) {
      const ClusterNode& node = *stack.back();
      stack.pop_back();
      const Vec3d d = toBlock + toDouble(node.position);
      const double z = dot(d, view.forward);
      if (z + node.radius <= view.nearPlane || z - node.radius >= view.farPlane) continue;
      double sx = gx, sy = gy, diameter = std::numeric_limits<double>::infinity();
      if (z > view.nearPlane) {
        sx = view.halfWidth * (1 + dot(d, view.right) / z / view.tanX);
        sy = view.halfHeight * (1 - dot(d, view.up) / z / view.tanY);
        diameter = 2 * node.radius * pixelScale / z;
        // Off screen: the splat covers its descendants, so they are off screen too.
        if (sx + diameter / 2 < 0 || sx - diameter / 2 > width || sy + diameter / 2 < 0 ||
            sy - diameter / 2 > height)
          continue;
      }
      const double fromGaze = std::max(0.0, std::hypot(sx - gx, sy - gy) - diameter / 2);
      if (!node.leaf() && diameter > allowedSplatPixels(fovea, fromGaze)) {
        if (segment) {
          stack.push_back(&(*segment)[node.firstChild]);
          stack.push_back(&(*segment)[node.firstChild + 1]);
          refined = true;
          continue;
        }
        wanted = true;
      }
      out.positions.push_back(toFloat(block.origin + toDouble(node.position) - out.origin));
      out.normals.push_back(node.normal);
      out.colors.push_back(node.color);
      out.radii.push_back(node.radius);
      out.inputPoints += node.pointCount;
    }
    if (refined) {
      ++out.refinedBlocks;
      pager.touch(b, frame);
    }
    if (wanted) out.wanted.push_back({b, fromGazeRay});
  }
}

}  // namespace lodforge
