#include "lodforge/generate/terrain.h"

#include <algorithm>
#include <cmath>

#include <stb_perlin.h>

#include "lodforge/core/random.h"

namespace lodforge {

namespace {
constexpr double kBaseWavelength = 400.0;  // metres: the coarsest hills
constexpr double kRelief = 60.0;           // metres of hill amplitude
constexpr double kCliffHeight = 45.0;
constexpr double kCliffWidth = 12.0;
constexpr double kOverhang = 2.2;  // > 1: the cliff's top leans out past its foot
}  // namespace

Terrain::Terrain(std::uint64_t seed, double width, double depth, double detail)
    : seed_(seed), width_(width), depth_(depth) {
  // Octaves until the finest wavelength reaches the sampling distance: detail at all scales.
  octaves_ = std::clamp(
      static_cast<int>(std::ceil(std::log2(kBaseWavelength / std::max(detail, 1e-3)))) + 1, 1, 24);
  // Holes: at most one per lattice cell, radius well under half the spacing, away from the
  // domain edges so the surface stays one connected piece.
  holeSpacing_ = std::max(width, depth) / 6.0;
  holeColumns_ = std::max(1, static_cast<int>(width / holeSpacing_));
  holeRows_ = std::max(1, static_cast<int>(depth / holeSpacing_));
  Random random(seed ^ 0x5CA4u);
  for (int row = 0; row < holeRows_; ++row) {
    for (int column = 0; column < holeColumns_; ++column) {
      Hole hole{0, 0, 0};
      // Grids too coarse to go around a hole get none (a hole could cut them in two).
      const bool fineEnough = std::min(width, depth) / detail >= 24;
      const bool interior =
          row > 0 && column > 0 && row + 1 < holeRows_ && column + 1 < holeColumns_;
      if (fineEnough && interior && random.uniform() < 0.6) {
        hole.radius = holeSpacing_ * random.uniform(0.04, 0.15);
        hole.u = (column + random.uniform(0.3, 0.7)) * holeSpacing_;
        hole.v = (row + random.uniform(0.3, 0.7)) * holeSpacing_;
      } else {
        (void)random.next();
      }
      holes_.push_back(hole);
    }
  }
}

double Terrain::cliffLine(double v) const {
  return width_ * (0.55 + 0.08 * std::sin(v / std::max(depth_, 1.0) * 6.2831853 * 1.5));
}

double Terrain::height(double u, double v) const {
  double sum = 0, amplitude = kRelief, frequency = 1.0 / kBaseWavelength;
  for (int octave = 0; octave < octaves_; ++octave) {
    // Perlin noise repeats every 256 units: wrap in double, then offset each octave so the
    // repeats of different octaves never line up.
    const double x = std::fmod(u * frequency + 17.31 * octave, 256.0);
    const double y = std::fmod(v * frequency + 41.77 * octave, 256.0);
    sum += amplitude *
           static_cast<double>(stb_perlin_noise3_seed(
               static_cast<float>(x), static_cast<float>(y), 0.5f, 0, 0, 0,
               static_cast<int>((seed_ + static_cast<std::uint64_t>(octave)) & 0x7FFFFFFF)));
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum;
}

Vec3d Terrain::position(double u, double v) const {
  // The cliff: z rises monotonically across it while x first advances, then retreats
  // (dx/du = 1 - kOverhang * sech^2 < 0 near the middle): the top hangs over the foot, and
  // because z is monotonic there the surface never meets itself.
  const double t = (u - cliffLine(v)) / kCliffWidth;
  const double tanhT = std::tanh(t);
  const double x = u - kOverhang * kCliffWidth * tanhT;
  // Calm the noise on the cliff face so its slope never beats the cliff's and breaks z's
  // monotonicity (which would fold the overhang through itself).
  const double sech2 = 1.0 - tanhT * tanhT;
  const double z = height(u, v) * (1.0 - 0.85 * sech2) + kCliffHeight * 0.5 * (tanhT + 1.0);
  return {x, v, z};
}

Vec3d Terrain::normal(double u, double v) const {
  const double h = 0.05;
  const Vec3d du = position(u + h, v) - position(u - h, v);
  const Vec3d dv = position(u, v + h) - position(u, v - h);
  return normalizeOr(cross(du, dv), Vec3d{0, 0, 1});
}

bool Terrain::inHole(double u, double v) const {
  const int column = static_cast<int>(std::floor(u / holeSpacing_));
  const int row = static_cast<int>(std::floor(v / holeSpacing_));
  if (column < 0 || row < 0 || column >= holeColumns_ || row >= holeRows_) return false;
  const Hole& hole = holes_[static_cast<std::size_t>(row * holeColumns_ + column)];
  if (hole.radius <= 0) return false;
  const double du = u - hole.u, dv = v - hole.v;
  return du * du + dv * dv < hole.radius * hole.radius;
}

Rgba8 Terrain::color(double u, double v, Vec3d p, Vec3d n) const {
  // Steep or overhanging: rock grey; high: pale; low and flat: vegetation green; between: soil.
  const double variation =
      0.5 + 0.5 * static_cast<double>(stb_perlin_noise3(
                      static_cast<float>(std::fmod(u / 7.0, 256.0)),
                      static_cast<float>(std::fmod(v / 7.0, 256.0)), 3.5f, 0, 0, 0));
  auto mix = [](Vec3d a, Vec3d b, double t) { return a + (b - a) * std::clamp(t, 0.0, 1.0); };
  const Vec3d vegetation{70, 110, 50}, soil{140, 110, 75}, rock{120, 118, 112}, snow{225, 225, 230};
  Vec3d c = mix(vegetation, soil, (p.z + 20.0) / 80.0 + 0.3 * (variation - 0.5));
  c = mix(c, snow, (p.z - 70.0) / 30.0);
  c = mix(c, rock, (0.8 - n.z) / 0.4);
  c = c * (0.85 + 0.3 * variation);
  auto channel = [](double x) { return static_cast<std::uint8_t>(std::clamp(x, 0.0, 255.0)); };
  return {channel(c.x), channel(c.y), channel(c.z), 255};
}

}  // namespace lodforge
