// The synthetic scanned surface shared by `generate scan` and `generate points`: a height field
// with detail at all scales (fractal Perlin noise down to the sampling distance), a meandering
// cliff that leans over its foot (an overhang, so the surface is not a height field there), and
// round holes (scanner shadows) on a jittered lattice so they never touch each other.
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

class Terrain {
 public:
  // `width` x `depth` metres of parameter domain; `detail` is the finest feature size to model.
  Terrain(std::uint64_t seed, double width, double depth, double detail);

  // Surface point for parameters (u, v) in metres (u across, v along the domain).
  Vec3d position(double u, double v) const;
  // Unit normal from central differences of position(); points to the scanned (upper) side.
  Vec3d normal(double u, double v) const;
  // True inside a hole: the scanner saw nothing there.
  bool inHole(double u, double v) const;
  // A plausible scanned colour (vegetation, soil, rock, by height and slope).
  Rgba8 color(double u, double v, Vec3d position, Vec3d normal) const;

  double width() const { return width_; }
  double depth() const { return depth_; }

 private:
  double height(double u, double v) const;
  double cliffLine(double v) const;

  struct Hole {
    double u, v, radius;
  };
  std::uint64_t seed_;
  double width_, depth_;
  int octaves_;
  double holeSpacing_;
  std::vector<Hole> holes_;  // one optional hole per lattice cell, indexed by cell
  int holeColumns_ = 0, holeRows_ = 0;
};

}  // namespace lodforge
