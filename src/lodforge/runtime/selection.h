// LOD selection of the CAD paper §4: every object gets a vertex count so that the total is
// exactly the budget N. First pass (Eq. 2): shares by projected area, distance and primitive
// count; Eq. 3 maps each share into the object's range [q, p] with the MinT threshold. Second
// pass (Algorithm 3): raise the most important objects to their maximum (or drop the least
// important to zero), then a partial allocation makes the sum exact.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/runtime/camera.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

struct SelectionOptions {
  double exponent = 3.0;       // 1/α of Eq. 2 (the paper uses 3)
  double minT = 0.65;          // Eq. 3's threshold below q
  bool firstPassOnly = false;  // Eq. 2 and 3 alone (the paper's Fig. 7 comparison)
};

// What selection needs of each object, as flat arrays (the hot loop vectorises over them).
struct LodScene {
  const Package* package = nullptr;
  std::vector<float> cx, cy, cz;       // box centre, relative to the package origin
  std::vector<float> hx, hy, hz;       // box half extents
  std::vector<float> primitiveFactor;  // P_i^(β/α) = P_i^(1 - 1/α): the primitive term of Eq. 2
  std::vector<std::uint32_t> minVertices, maxVertices;  // q_i, p_i
  std::vector<std::uint64_t> levelOffset;  // into the package's map: map(n) = map[offset + n - q]
  const std::uint32_t* map = nullptr;      // the package's map section (mmap'd)
  // A textured package's whole counts (Package::wholeAt), same layout as map; null otherwise.
  const std::uint32_t* whole = nullptr;
  double exponent = 3.0;

  static LodScene fromPackage(const Package& package, double exponent = 3.0);
  std::size_t size() const { return cx.size(); }
  std::uint64_t totalMaxVertices() const;
};

struct Selection {
  std::vector<std::uint32_t> vertexCounts;    // vc_i
  std::vector<std::uint32_t> triangleCounts;  // tc_i = map(vc_i)
  std::vector<float> importance;  // (A_i / D_i)^(1/α) P_i^(β/α): Eq. 2's weight up to a constant
  std::uint64_t totalVertices = 0, totalTriangles = 0;
  std::uint64_t firstPassVertices = 0;  // N' after Eq. 3
  std::uint64_t visibleObjects = 0;
  double importanceTotal = 0;  // Σ importance: Eq. 2's denominator (up to the same constant)

  // Milliseconds of the last call, per step.
  struct Timings {
    double importance = 0, firstPass = 0, secondPass = 0, finish = 0;
    double total() const { return importance + firstPass + secondPass + finish; }
  } timings;

  // Reused from frame to frame so selection allocates nothing once warm.
  struct Workspace {
    std::vector<std::uint64_t> keys;                       // (rank key, id) of one bucket, to sort
    std::vector<std::uint32_t> order;                      // object ids by importance
    std::vector<std::uint64_t> chunkCounts, chunkWeights;  // per chunk and rank bucket
    std::vector<std::uint64_t> bucketStart, bucketWeight;  // prefix sums of Algorithm 3's VDif
    std::vector<std::uint32_t> bucketIds;                  // object ids grouped by rank bucket
    // Last frame's counts: tc_i = map(vc_i) is looked up only where vc_i changed.
    std::vector<std::uint32_t> previousVertexCounts;
    const std::uint32_t* previousMap = nullptr;  // which package they belong to
    std::vector<double> blockSums;               // Σ importance per fixed block of objects
  } workspace;
};

// The two passes; with options.firstPassOnly, Eq. 2 and Eq. 3 only (the sum is then not N). In
// a textured package each count then rounds down to a whole one (LodScene::whole), so the sum
// may fall short of N by less than one point's wedges per textured object.
void selectTwoPass(const LodScene& scene, const Camera& camera, std::uint64_t budget,
                   const SelectionOptions& options, Selection& out);

// Beyond the paper: the fewest vertices per object whose recorded geometric error projects to
// at most `pixels` on screen (no budget; objects outside the frustum get 0).
void selectByError(const LodScene& scene, const Camera& camera, double pixels, Selection& out);

}  // namespace lodforge
