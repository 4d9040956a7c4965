// 3D Tiles 1.1 implicit tiling of a mesh tileset: the octree written as an OCTREE subdivision
// of the grid's cube (tileset.json then holds one root tile, however many tiles there are), its
// tiles and contents given by availability bitstreams in subtree files, and each tile's own
// geometric error and tight box kept as tile metadata (TILE_GEOMETRIC_ERROR, TILE_BOUNDING_BOX),
// so viewers that read them (CesiumJS) see exactly what the explicit tileset declares.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// Levels per subtree file (at most; fewer for a shallower tree): 8^5 child-subtree bits (4 KiB) at
// most, so a file stays small while a billion-triangle tree (10 levels) needs two rows of them.
inline constexpr int kSubtreeLevels = 5;

// The position of (x, y, z) among the 8^level tiles of a level: bits interleaved x, y, z from
// the lowest (the order of 3D Tiles' octree availability).
std::uint64_t mortonIndex(std::uint32_t x, std::uint32_t y, std::uint32_t z);

// Where level `level`'s bits start in a subtree's tile availability: (8^level - 1) / 7.
std::uint64_t levelOffset(int level);

// Whether the octree is one OCTREE subdivision: a single root over every level (not a root added
// over a --levels cut).
bool implicitTilingFits(const OctreeResult& octree);

// A node's content in an implicit tileset: tiles/{level}/{x}/{y}/{z}.glb, the level counted from
// the root.
std::string implicitContentUri(const OctreeResult& octree, const OctreeNode& node);

// Moves each node's content to its name in the layout about to be written (tileContentUri or
// implicitContentUri), from the other layout's name where an interrupted run that was writing
// the other layout left it (--resume then writes either); for the explicit layout, also removes
// what such a run's implicit layout left (subtree files, numbered folders).
Status placeContents(const OctreeResult& octree, const std::string& directory, bool implicit);

// Writes `directory`/tileset.json with an implicit root over the root node's cube of `grid` and
// the subtree files under subtrees/ (the contents already placed by placeContents). Errors and
// boxes are those writeTilesetJson writes; the root's own
// geometricError is the least one whose halving per level stays at or above every tile's error,
// for viewers that ignore the metadata. Expects implicitTilingFits.
Status writeImplicitTileset(const OctreeResult& octree, const ChunkGrid& grid,
                            const std::string& directory, const std::optional<Mat4d>& rootTransform,
                            bool quantized, const std::string& partsUri,
                            int subtreeLevels = kSubtreeLevels);

}  // namespace lodforge
