// `lodforge build`: every object of an input through prepareObject and buildProgressive into a
// package. Objects stream in (a grouped PLY never sits in memory whole), are built in parallel
// waves that fit the memory limit, and are written in input order as they finish. A shape
// placed again is built once (shape_cache.h).
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/progressive.h"

namespace lodforge {

struct BuildOptions {
  ProgressiveOptions progressive;
  // Bytes the whole build may use (the process's peak stays under it); 0: a quarter of physical
  // memory for the objects in flight.
  std::uint64_t memoryLimit = 0;
  ReadOptions read;
  // An object that is an earlier object's shape moved rigidly gets that shape's progressive mesh
  // moved likewise (ShapeCache), so all placements share their levels and are simplified once.
  bool placeRepeatedShapes = true;
};

struct BuildStats {
  std::uint64_t objects = 0;
  std::uint64_t inputTriangles = 0;
  std::uint64_t vertices = 0;                       // after welding
  std::uint64_t triangles = 0;                      // after dropping degenerate ones
  std::uint64_t minVertices = 0, minTriangles = 0;  // the simplest level, summed
  std::uint64_t packageBytes = 0;
  std::uint64_t waves = 0;
  // Objects written as an earlier object's shape moved rigidly (ShapeCache), not built anew.
  std::uint64_t placements = 0;
  std::uint64_t shapeCacheBytes = 0;  // what the shapes kept to place again held at the end
  bool streamed = false;
  double seconds = 0;
};

Result<BuildStats> buildPackage(const std::string& input, const std::string& output,
                                const BuildOptions& options = {});

}  // namespace lodforge
