// Chunks on disk (large-meshes paper §3.3–3.4): the input streamed into the chunk grid, one
// file per non-empty chunk, buffered in memory up to a budget and appended to disk when it is
// reached (a block per append: the vertices since the last one, an input vertex once, and
// triangles over them), and read back welded. Node meshes go to mesh files (mesh_file.h).
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_grid.h"
// Every work file of `lodforge tiles` from one include (their tests and fuzzer take them
// together): a chunk loads welded (weld.h) as the mesh (mesh_part.h) that node mesh files hold
// (mesh_file.h).
#include "lodforge/tiling/mesh_file.h"
#include "lodforge/tiling/mesh_part.h"
#include "lodforge/tiling/weld.h"

namespace lodforge {

class ChunkWriter {
 public:
  // Chunk files go to `directory` (created); at most `bufferBytes` are held before appending.
  // With `keepInMemory` nothing is written: the chunks stay in their buffers.
  ChunkWriter(ChunkGrid grid, std::string directory, std::uint64_t bufferBytes,
              bool keepInMemory = false);

  // Chunk files written by an earlier, interrupted run (--resume) or by the ranks of a job: the
  // grid and the counts. With `pieces` > 0 each chunk is in pieces, one per rank that read a
  // slice of the input, at piecePath(cell, r): read back in rank order, as one file.
  static ChunkWriter reopen(ChunkGrid grid, std::string directory,
                            std::map<std::uint64_t, std::uint64_t> counts, int pieces = 0);

  // Records carry each corner's texture coordinate and material (a textured input): set before
  // the first triangle is added.
  void setTextured(bool textured) {
    assert(triangles_ == 0);
    textured_ = textured;
  }
  bool textured() const { return textured_; }

  // One triangle piece (3 corners) for `cell`.
  Status add(const ChunkCell& cell, std::span<const CutCorner, 3> corners);
  // A whole triangle: cut at the grid planes it crosses, each piece added to its chunk.
  Status addTriangle(const std::array<CutCorner, 3>& triangle);
  // A triangle of a segment (a connected part, §3.3) with these bounds: whole, in the chunk of
  // the segment's centre, when the segment is smaller than a chunk along every axis (it may
  // stick out of that chunk); cut like addTriangle otherwise.
  Status addSegmentTriangle(const Aabbd& segment, const std::array<CutCorner, 3>& triangle);
  // Pieces made by cutSegmentTriangle: cells[i] gets corners 3i..3i+2.
  Status addPieces(std::span<const ChunkCell> cells, std::span<const CutCorner> corners);
  Status flush();

  const ChunkGrid& grid() const { return grid_; }
  // Non-empty chunks and their triangle counts, in cell order.
  const std::map<std::uint64_t, std::uint64_t>& triangleCounts() const { return counts_; }
  std::uint64_t triangleCount() const { return triangles_; }
  std::string chunkPath(const ChunkCell& cell) const;
  int pieces() const { return pieces_; }
  // The chunk's work files (its file, or its pieces), for removal once its leaf is built.
  std::vector<std::string> chunkFiles(const ChunkCell& cell) const;
  // A chunk as a welded mesh, from its buffer or its file.
  Result<MeshPart> load(const ChunkCell& cell) const;

 private:
  ChunkGrid grid_;
  std::string directory_;
  std::uint64_t bufferBytes_ = 0, buffered_ = 0, triangles_ = 0;
  bool keepInMemory_ = false;
  bool textured_ = false;
  int pieces_ = 0;
  // A chunk's pieces since the last flush: vertex records and triangles over them, and where
  // each input vertex's record is. Input vertices arrive in runs of nearby numbers (a scan's
  // rows, looked up again a row later), so the lookup is by runs of 64 numbers: an
  // open-addressing table from run (+ 1; 0 is empty) to a block of 64 records (~0: none yet).
  // Consecutive vertices then share a block instead of each taking a random table slot.
  struct Buffer {
    std::vector<std::byte> vertices;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint64_t> runs;
    std::vector<std::uint32_t> runBlock;
    std::vector<std::uint32_t> blocks;
    std::uint32_t runCount = 0;
  };
  Result<MeshPart> loadPieces(const ChunkCell& cell) const;
  // The record of `corner` in `buffer` (added if new); the bytes it took go to buffered_.
  std::uint32_t vertexOf(Buffer& buffer, const CutCorner& corner);
  std::map<std::uint64_t, Buffer> buffers_;  // by cell index
  std::map<std::uint64_t, std::uint64_t> counts_;
  // The chunk the last piece went to: neighbouring triangles mostly share it, so the two map
  // lookups are skipped (map nodes do not move; flush() forgets the buffer).
  std::uint64_t lastIndex_ = ~std::uint64_t{0};
  Buffer* lastBuffer_ = nullptr;
  std::uint64_t* lastCount_ = nullptr;
  std::vector<ChunkCell> pieceCells_;  // addTriangle's scratch
  std::vector<CutCorner> pieceCorners_;
};

// Where rank `r` of a job writes its pieces of the chunks in `chunkDirectory` (a ChunkWriter of
// its own there; ChunkWriter::reopen with pieces reads them back).
std::string chunkPieceDirectory(const std::string& chunkDirectory, int r);

// The pieces addSegmentTriangle adds (`segment` null: a triangle of no segment, cut), appended
// to `cells` and `corners`, so that cutting can run apart from adding.
void cutSegmentTriangle(const ChunkGrid& grid, const Aabbd* segment,
                        const std::array<CutCorner, 3>& triangle, std::vector<ChunkCell>& cells,
                        std::vector<CutCorner>& corners);

// A chunk file read back as a welded mesh.
Result<MeshPart> loadChunk(const std::string& path);
// The same from bytes in memory (`name` for messages): what loadChunk parses.
Result<MeshPart> parseChunk(std::span<const std::byte> bytes, const std::string& name);

// The cell of a cell index (inverse of ChunkGrid::cellIndex).
ChunkCell cellOfIndex(const ChunkGrid& grid, std::uint64_t index);

}  // namespace lodforge
