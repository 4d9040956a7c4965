// Shapes placed again in a build's object stream (a CAD part placed many times, a glTF mesh
// under several nodes): `lodforge build` simplifies a shape once and writes each further
// placement as that progressive mesh moved rigidly, so every placement has the same levels
// and `extract` writes the mesh once with a node transform per placement.
#pragma once

#include <cassert>
#include <cstdint>
#include <optional>
#include <vector>

#include "lodforge/core/instances.h"
#include "lodforge/core/math.h"
#include "lodforge/io/mesh/object_stream.h"
#include "lodforge/simplify/progressive.h"

namespace lodforge {

struct ShapeMatch {
  std::uint32_t shape = 0;  // a remembered shape
  Mat4d motion;             // takes the shape onto the object
};

// What the cache made of an object: a placement of a shape it holds, a new shape it holds, or
// neither (no room, or no triangles).
struct ShapeLookup {
  std::optional<ShapeMatch> placed;
  std::optional<std::uint32_t> remembered;
};

class ShapeCache {
 public:
  // Holds at most about `bytes` of shapes (their input and built mesh; 0: none); objects met after
  // that are compared with the shapes held but not kept. At most `candidates` shapes alike
  // (PlacementIndex).
  explicit ShapeCache(std::uint64_t bytes, double relativeTolerance = kPlacementTolerance,
                      std::size_t candidates = 64);

  // Objects must come in stream order; a remembered shape's mesh must be set before the first
  // placement of it is written.
  ShapeLookup lookup(const SourceObject& object);
  void setMesh(std::uint32_t shape, const ProgressiveMesh& mesh);
  const ProgressiveMesh& mesh(std::uint32_t shape) const {
    assert(shapes_[shape].built);  // the builder writes in stream order
    return shapes_[shape].mesh;
  }
  std::uint64_t bytes() const { return bytes_; }

 private:
  struct Shape {
    SourceObject input;  // without name and path
    ProgressiveMesh mesh;
    bool built = false;  // mesh set
  };
  std::uint64_t capacity_, bytes_ = 0;
  double relativeTolerance_;
  PlacementIndex index_;
  std::vector<Shape> shapes_;
};

// `mesh` moved by `motion`: positions and normals turn; triangles, collapses, levels and errors
// stay (a rigid motion keeps distances). The permutations are left out.
ProgressiveMesh placedMesh(const ProgressiveMesh& mesh, const Mat4d& motion);

}  // namespace lodforge
