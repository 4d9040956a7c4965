// How honest and how tight a mesh tileset's geometric errors are (issue 38), measured from the
// tileset alone: bench_tile_error [--samples N] [--certify] TILESET_DIR...
// Under REPLACE refinement the full-resolution surface a tile stands for is the union of the
// leaf contents under it. For every tile with content and children, the symmetric Hausdorff
// distance between its content and that union is measured by dense sampling (N area-uniform
// points on each side plus every triangle's corner, exact point-to-triangle distances) and
// compared with its declared geometricError, per level of the tree. A point tileset (refine ADD)
// is measured by issue 38's definition for points (measurePointTile). --certify adds a bracket of
// each distance that does not depend on sampling (directedBound). --chain F tries the bound
// issue 38 proposes for the builder (chainTile): each tile against its children only, with a
// value per triangle carried up the tree, pieces split to F times the tile's error.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/distance.h"
#include "lodforge/core/distance_bound.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// A mesh in one frame for the whole tileset: positions relative to the first content's origin.
struct Mesh {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
};

struct Tile {
  int depth = 0;
  double declared = 0;
  std::string uri;  // empty: no content
  std::vector<std::size_t> children;
};

struct Tileset {
  fs::path directory;
  std::vector<Tile> tiles;  // tiles[0] is the root
  bool haveFrame = false;
  Vec3d frame;  // the shared origin
};

std::size_t addTile(const nlohmann::json& json, int depth, Tileset& set) {
  const std::size_t index = set.tiles.size();
  set.tiles.push_back({depth,
                       json.at("geometricError").get<double>(),
                       json.contains("content") ? json["content"]["uri"].get<std::string>() : "",
                       {}});
  for (const auto& child : json.value("children", nlohmann::json::array())) {
    const std::size_t c = addTile(child, depth + 1, set);
    set.tiles[index].children.push_back(c);
  }
  return index;
}

void appendContent(Tileset& set, const std::string& uri, Mesh& out) {
  Result<Model> model = readGltf((set.directory / uri).string());
  if (!model) {
    fmt::print(stderr, "{}: {}\n", uri, model.error().message);
    std::exit(1);
  }
  if (!set.haveFrame) {
    set.frame = model->origin;
    set.haveFrame = true;
  }
  const Vec3d shift = model->origin - set.frame;
  const auto base = static_cast<std::uint32_t>(out.positions.size());
  for (const Vec3f& p : model->positions) out.positions.push_back(toFloat(toDouble(p) + shift));
  for (const ObjectRecord& o : model->objects) {
    for (std::uint32_t k = 0; k < 3 * o.triangleCount; ++k)
      out.indices.push_back(base + o.vertexOffset + model->indices[3 * o.triangleOffset + k]);
  }
}

void appendLeaves(Tileset& set, std::size_t tile, Mesh& out) {
  if (set.tiles[tile].children.empty()) {
    if (!set.tiles[tile].uri.empty()) appendContent(set, set.tiles[tile].uri, out);
    return;
  }
  for (std::size_t c : set.tiles[tile].children) appendLeaves(set, c, out);
}

using Piece3 = std::array<Vec3d, 3>;

// Triangle t (its first index) of a mesh, in double.
Piece3 triangleAt(const Mesh& m, std::size_t t) {
  return {toDouble(m.positions[m.indices[t]]), toDouble(m.positions[m.indices[t + 1]]),
          toDouble(m.positions[m.indices[t + 2]])};
}

// A piece split at its edges' midpoints: three corner pieces and the middle one.
std::array<Piece3, 4> quarters(const Piece3& p) {
  const Vec3d m01 = (p[0] + p[1]) / 2.0, m12 = (p[1] + p[2]) / 2.0, m20 = (p[2] + p[0]) / 2.0;
  return {Piece3{p[0], m01, m20}, Piece3{m01, p[1], m12}, Piece3{m20, m12, p[2]},
          Piece3{m01, m12, m20}};
}

// sup over A of the distance to B, bracketed by branch and bound: `lower` is a distance some
// point of A has (vertices and piece centroids, measured exactly), `upper` one no point of A
// exceeds. A piece of a triangle of A is bounded through the triangle of B nearest its centroid:
// the distance to one triangle is convex, so its largest over the piece is at a corner. The
// piece with the largest bound is split in four until the bound is within `ratio` of the lower
// one or `budget` pieces were made (then the bound is valid but looser).
struct Bracket {
  double lower = 0, upper = 0;
  std::size_t pieces = 0;
};

struct Piece {
  double upper;
  std::array<Vec3d, 3> p;
  bool operator<(const Piece& o) const { return upper < o.upper; }
};

Bracket directedBound(const Mesh& a, const Mesh& b, double ratio, std::size_t budget) {
  Bracket out;
  if (b.indices.empty()) {  // nothing to be near: no finite bound
    out.lower = out.upper = a.indices.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    return out;
  }
  const NearestTriangles nearest(b.positions, b.indices);
  std::uint32_t f = 0;
  for (const Vec3f& v : a.positions)
    out.lower = std::max(out.lower, std::sqrt(nearest.nearestSquared(toDouble(v), f)));
  const auto corner = [&](std::uint32_t t, int k) {
    return toDouble(b.positions[b.indices[3 * t + static_cast<std::size_t>(k)]]);
  };
  const auto bound = [&](const std::array<Vec3d, 3>& p) {
    const Vec3d g = (p[0] + p[1] + p[2]) / 3.0;
    out.lower = std::max(out.lower, std::sqrt(nearest.nearestSquared(g, f)));
    double worst = 0;
    for (const Vec3d& q : p)
      worst = std::max(worst,
                       pointTriangleDistanceSquared(q, corner(f, 0), corner(f, 1), corner(f, 2)));
    ++out.pieces;
    return Piece{std::sqrt(worst), p};
  };
  std::vector<Piece> heap;
  for (std::size_t t = 0; t + 2 < a.indices.size(); t += 3) heap.push_back(bound(triangleAt(a, t)));
  std::make_heap(heap.begin(), heap.end());
  while (!heap.empty() && heap.front().upper > ratio * out.lower && out.pieces < budget) {
    std::pop_heap(heap.begin(), heap.end());
    const std::array<Vec3d, 3> p = heap.back().p;
    heap.pop_back();
    for (const Piece3& q : quarters(p)) {
      heap.push_back(bound(q));
      std::push_heap(heap.begin(), heap.end());
    }
  }
  out.upper = std::max(out.lower, heap.empty() ? 0.0 : heap.front().upper);
  return out;
}

// Each tile's error bounded level by level with per-triangle values carried up the tree (the
// triangle inequality applied locally, not to the tile's largest). reach[t]: no point of triangle t
// is farther than it from the finest surface; cover[t]: every finest point chained to t is within
// it of t.
struct Chain {
  Mesh mesh;
  std::vector<double> reach, cover;
};

// Splits each triangle of A into pieces (PieceBounds over B, with B's `carried` values) until the
// bound is within `tol` of the piece's exact corner values or `cap` pieces were made for the
// triangle; `visit(t, bound)` gets each final piece of A's triangle t.
template <class Visit>
std::size_t chainPieces(const Mesh& a, const Mesh& b, std::span<const double> carried, double tol,
                        std::size_t cap, Visit visit) {
  std::size_t pieces = 0;
  std::vector<std::array<Vec3d, 3>> stack;
  const PieceBounds bounds(b.positions, b.indices);
  for (std::size_t t = 0; t + 2 < a.indices.size(); t += 3) {
    stack.push_back(triangleAt(a, t));
    std::size_t made = 1;
    while (!stack.empty()) {
      const std::array<Vec3d, 3> p = stack.back();
      stack.pop_back();
      ++pieces;
      const PieceBound bound = bounds.bound(p, carried);
      if (bound.upper - bound.lower > tol && made < cap) {
        for (const Piece3& q : quarters(p)) stack.push_back(q);
        made += 3;
        continue;
      }
      visit(t / 3, bound);
    }
  }
  return pieces;
}

// The tile's chain from its content and its children's chains (concatenated in `below`).
Chain chainUp(Mesh content, const Chain& below, double tolFraction, std::size_t& pieces) {
  Chain out;
  out.mesh = std::move(content);
  const std::size_t n = out.mesh.indices.size() / 3;
  out.reach.assign(n, 0);
  out.cover.assign(n, 0);
  const double carried = std::max(
      below.reach.empty() ? 0.0 : *std::max_element(below.reach.begin(), below.reach.end()),
      below.cover.empty() ? 0.0 : *std::max_element(below.cover.begin(), below.cover.end()));
  const double sampled = sampledHausdorff(out.mesh.positions, out.mesh.indices,
                                          below.mesh.positions, below.mesh.indices, 10'000, 1);
  const double tol = tolFraction * (sampled + carried);
  const std::size_t cap = 1 << 14;
  // reach: the tile's pieces through the children's triangles; cover: the children's pieces
  // through the tile's triangles.
  pieces += chainPieces(
      out.mesh, below.mesh, below.reach, tol, cap,
      [&](std::size_t t, const PieceBound& b) { out.reach[t] = std::max(out.reach[t], b.upper); });
  // Every finest point chained to a child's piece is within its cover of the piece, and every
  // point of the piece within `upper` of one of the tile's triangles used.
  pieces +=
      chainPieces(below.mesh, out.mesh, {}, tol, cap, [&](std::size_t a, const PieceBound& b) {
        for (std::uint32_t t : b.used)
          out.cover[t] = std::max(out.cover[t], b.upper + below.cover[a]);
      });
  return out;
}

// Post order: every tile's chain; `bound[t]` gets the tile's chained error.
Chain chainTile(Tileset& set, std::size_t t, std::vector<double>& bound, double tolFraction,
                std::size_t& pieces) {
  const Tile tile = set.tiles[t];
  Mesh content;
  if (!tile.uri.empty()) appendContent(set, tile.uri, content);
  if (tile.children.empty()) {
    Chain leaf;
    leaf.reach.assign(content.indices.size() / 3, 0);
    leaf.cover = leaf.reach;
    leaf.mesh = std::move(content);
    return leaf;
  }
  Chain below;
  for (std::size_t c : tile.children) {
    Chain child = chainTile(set, c, bound, tolFraction, pieces);
    const auto base = static_cast<std::uint32_t>(below.mesh.positions.size());
    below.mesh.positions.insert(below.mesh.positions.end(), child.mesh.positions.begin(),
                                child.mesh.positions.end());
    for (std::uint32_t i : child.mesh.indices) below.mesh.indices.push_back(base + i);
    below.reach.insert(below.reach.end(), child.reach.begin(), child.reach.end());
    below.cover.insert(below.cover.end(), child.cover.begin(), child.cover.end());
  }
  if (tile.uri.empty()) return below;
  Chain out = chainUp(std::move(content), below, tolFraction, pieces);
  bound[t] = std::max(*std::max_element(out.reach.begin(), out.reach.end()),
                      *std::max_element(out.cover.begin(), out.cover.end()));
  return out;
}

struct LevelStats {
  std::vector<double> ratios;  // measured / declared
  std::size_t under = 0;       // measured above declared
  std::size_t notMonotonic = 0;
  std::vector<double> bracket, overCertified;  // --certify: upper / lower, declared / upper
};

// The table per depth (and with --certify the brackets').
void printLevels(const fs::path& directory, const Tileset& set, std::map<int, LevelStats>& levels,
                 bool certify) {
  fmt::print("\n{}: {} tiles\n", directory.string(), set.tiles.size());
  fmt::print(
      "| depth | tiles measured | measured/declared min / median / max | under half | "
      "under-declared | child above parent |\n|---|---|---|---|---|---|\n");
  for (auto& [depth, stats] : levels) {
    std::vector<double>& r = stats.ratios;
    if (r.empty()) continue;
    std::sort(r.begin(), r.end());
    const auto half = std::count_if(r.begin(), r.end(), [](double x) { return x < 0.5; });
    fmt::print("| {} | {} | {:.2f} / {:.2f} / {:.2f} | {:.0f} % | {} | {} |\n", depth, r.size(),
               r.front(), r[r.size() / 2], r.back(),
               100.0 * static_cast<double>(half) / static_cast<double>(r.size()), stats.under,
               stats.notMonotonic);
  }
  if (certify) {
    fmt::print(
        "| depth | certified upper / lower: max | declared / certified upper: min / "
        "median / max |\n|---|---|---|\n");
    for (auto& [depth, stats] : levels) {
      if (stats.bracket.empty()) continue;
      std::sort(stats.overCertified.begin(), stats.overCertified.end());
      const std::vector<double>& o = stats.overCertified;
      fmt::print("| {} | {:.3f} | {:.2f} / {:.2f} / {:.2f} |\n", depth,
                 *std::max_element(stats.bracket.begin(), stats.bracket.end()), o.front(),
                 o[o.size() / 2], o.back());
    }
  }
  std::fflush(stdout);
}

// Points of the tiles under `tile` (not its own).
void appendDescendants(Tileset& set, std::size_t tile, Mesh& out) {
  for (std::size_t c : set.tiles[tile].children) {
    if (!set.tiles[c].uri.empty()) appendContent(set, set.tiles[c].uri, out);
    appendDescendants(set, c, out);
  }
}

// A point tileset refines by adding: a tile drawn without its children shows its own and its
// ancestors' points (`shown`), and drops every point below it. Its error as issue 38 defines it
// for points: the largest distance from a dropped point to the nearest shown one (exact, by a
// k-d tree over the shown points).
void measurePointTile(Tileset& set, std::size_t t, std::vector<Vec3f>& shown,
                      std::map<int, LevelStats>& levels) {
  const Tile tile = set.tiles[t];
  const std::size_t before = shown.size();
  Mesh own;
  if (!tile.uri.empty()) appendContent(set, tile.uri, own);
  shown.insert(shown.end(), own.positions.begin(), own.positions.end());
  LevelStats& stats = levels[tile.depth];
  for (std::size_t c : tile.children) stats.notMonotonic += set.tiles[c].declared > tile.declared;
  if (!tile.children.empty() && !shown.empty()) {
    Mesh dropped;
    appendDescendants(set, t, dropped);
    std::vector<Vec3d> shownPoints(shown.size());
    for (std::size_t i = 0; i < shown.size(); ++i) shownPoints[i] = toDouble(shown[i]);
    const PointIndex index(shownPoints);
    double farthest = 0;
    for (const Vec3f& p : dropped.positions) {
      std::uint32_t nearest = 0;
      double squared = 0;
      index.nearest(toDouble(p), 1, &nearest, &squared);
      farthest = std::max(farthest, squared);
    }
    const double measured = std::sqrt(farthest);
    stats.ratios.push_back(measured / tile.declared);
    stats.under += measured > tile.declared;
  }
  for (std::size_t c : tile.children) measurePointTile(set, c, shown, levels);
  shown.resize(before);
}

void measure(const fs::path& directory, std::uint32_t samples, bool certify, double chainFraction) {
  std::ifstream in(directory / "tileset.json");
  const nlohmann::json json = nlohmann::json::parse(in);
  Tileset set{directory, {}, false, {}};
  addTile(json.at("root"), 0, set);
  std::map<int, LevelStats> levels;
  if (json.at("root").value("refine", "") == "ADD") {
    std::vector<Vec3f> shown;
    measurePointTile(set, 0, shown, levels);
    printLevels(directory, set, levels, false);
    return;
  }
  std::vector<double> chained(set.tiles.size(), -1);
  if (chainFraction > 0) {
    std::size_t pieces = 0;
    chainTile(set, 0, chained, chainFraction, pieces);
    fmt::print("chained: {} pieces\n", pieces);
  }
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    LevelStats& stats = levels[tile.depth];
    for (std::size_t c : tile.children) stats.notMonotonic += set.tiles[c].declared > tile.declared;
    if (tile.uri.empty() || tile.children.empty()) continue;
    Mesh content, finest;
    appendContent(set, tile.uri, content);
    appendLeaves(set, t, finest);
    const SurfaceDistance d = surfaceDistance(content.positions, content.indices, finest.positions,
                                              finest.indices, samples, t + 1);
    stats.ratios.push_back(d.hausdorff / tile.declared);
    if (certify) {
      const std::size_t budget = 64 * (content.indices.size() + finest.indices.size());
      const Bracket ab = directedBound(content, finest, 1.05, budget);
      const Bracket ba = directedBound(finest, content, 1.05, budget);
      const double lower = std::max(ab.lower, ba.lower), upper = std::max(ab.upper, ba.upper);
      stats.bracket.push_back(upper > lower ? upper / lower : 1.0);  // 0 / 0: exact
      stats.overCertified.push_back(tile.declared / upper);
      if (chained[t] >= 0)
        fmt::print("  {} chained {:.4g}: / certified upper {:.3f}, / lower {:.3f}\n", tile.uri,
                   chained[t], chained[t] / upper, chained[t] / lower);
      fmt::print(
          "  {}: declared {:.4g}, sampled {:.4g}, certified [{:.4g}, {:.4g}] "
          "(content to leaves [{:.4g}, {:.4g}] in {} pieces, leaves to content "
          "[{:.4g}, {:.4g}] in {})\n",
          tile.uri, tile.declared, d.hausdorff, lower, upper, ab.lower, ab.upper, ab.pieces,
          ba.lower, ba.upper, ba.pieces);
    }
    if (d.hausdorff > tile.declared) {
      ++stats.under;
      fmt::print(
          "under-declared: {} declares {:.4g}, measured {:.4g} (content to leaves {:.4g}, "
          "leaves to content {:.4g})\n",
          tile.uri, tile.declared, d.hausdorff, d.maxAB, d.maxBA);
    }
  }
  printLevels(directory, set, levels, certify);
  std::fflush(stdout);
}

}  // namespace
}  // namespace lodforge

int main(int argc, char** argv) {
  std::uint32_t samples = 100'000;
  bool certify = false;
  double chainFraction = 0;
  std::vector<std::string> directories;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--certify")
      certify = true;
    else if (arg == "--chain" && i + 1 < argc)
      chainFraction = std::stod(argv[++i]);
    else if (arg == "--samples" && i + 1 < argc)
      samples = static_cast<std::uint32_t>(std::stoul(argv[++i]));
    else
      directories.push_back(arg);
  }
  if (directories.empty()) {
    std::fprintf(stderr,
                 "usage: bench_tile_error [--samples N] [--certify] [--chain F] TILESET_DIR...\n");
    return 2;
  }
  for (const std::string& d : directories) lodforge::measure(d, samples, certify, chainFraction);
}
