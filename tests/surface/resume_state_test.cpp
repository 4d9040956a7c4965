#include "lodforge/surface/resume_state.h"

#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

SurfacePiece randomPiece(Random& random, std::size_t vertices, bool colors) {
  SurfacePiece p;
  for (std::size_t v = 0; v < vertices; ++v) {
    p.positions.push_back({random.uniform(-1e6, 1e6), random.uniform(0, 1), random.uniform()});
    p.normals.push_back({static_cast<float>(random.uniform()), 0.5f, -1});
    if (colors) p.colors.push_back({static_cast<std::uint8_t>(random.below(256)), 1, 2, 255});
    p.edges.push_back(random.next());
    for (int c = 0; c < 3; ++c)
      p.indices.push_back(static_cast<std::uint32_t>(random.below(vertices)));
  }
  return p;
}

struct Recorder : PieceSink {
  Status begin(const ChunkLayout&, bool) override { return {}; }
  Status add(std::uint64_t chunk, const SurfacePiece& piece) override {
    chunks.push_back(chunk);
    pieces.push_back(piece);
    return {};
  }
  std::vector<std::uint64_t> chunks;
  std::vector<SurfacePiece> pieces;
};

// Kept pieces come back as they went in, empty ones and ones without colours included; a file
// cut short is an error naming it, not a shorter mesh.
TEST(ResumeState, PiecesComeBackAsWrittenAndACutFileIsAnError) {
  test::TempDir dir;
  Random random(5);
  std::vector<SurfacePiece> written;
  Result<PieceWriter> writer = PieceWriter::create(piecesPath(dir.path().string(), 3));
  ASSERT_TRUE(writer.ok());
  for (std::uint64_t c = 0; c < 6; ++c) {
    written.push_back(randomPiece(random, c == 2 ? 0 : 50 + c * 10, c % 3 != 1));
    ASSERT_TRUE(writer->add(c * 7, written.back()).ok());
  }
  EXPECT_FALSE(std::filesystem::exists(piecesPath(dir.path().string(), 3)));  // not yet done
  ASSERT_TRUE(writer->finish().ok());
  const std::string path = piecesPath(dir.path().string(), 3);
  Recorder back;
  ASSERT_TRUE(replayPieces(path, back).ok());
  ASSERT_EQ(back.pieces.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ(back.chunks[i], i * 7);
    EXPECT_EQ(back.pieces[i].positions, written[i].positions);
    EXPECT_EQ(back.pieces[i].normals, written[i].normals);
    EXPECT_EQ(back.pieces[i].colors, written[i].colors);
    EXPECT_EQ(back.pieces[i].edges, written[i].edges);
    EXPECT_EQ(back.pieces[i].indices, written[i].indices);
  }
  // A header whose counts the file cannot hold allocates nothing and is an error.
  const std::uint64_t huge[4] = {0, std::uint64_t{1} << 40, std::uint64_t{1} << 40, 1};
  test::writeFile(dir.file("huge.pieces"),
                  std::string_view(reinterpret_cast<const char*>(huge), sizeof huge));
  Recorder none;
  EXPECT_FALSE(replayPieces(dir.file("huge.pieces"), none).ok());
  EXPECT_TRUE(none.pieces.empty());
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 5);
  Recorder cut;
  const Status status = replayPieces(path, cut);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find(path), std::string::npos);
  EXPECT_LT(cut.pieces.size(), written.size());
}

// The state comes back only when it is whole and made from the same input and options.
TEST(ResumeState, TheStateComesBackOnlyForTheSameIdentity) {
  test::TempDir dir;
  const std::string path = reconstructStatePath(dir.path().string());
  ReconstructState state;
  state.layout.grid = {{0.1, -2.5, 1e6 + 0.3}, 0.7, {40, 50, 60}};
  state.layout.n = 9;
  state.layout.chunks = {5, 6, 7};
  state.runs.chunks = {1, 4, 9, 100};
  state.runs.points = {10, 20, 30, 40};
  state.runs.firstChunk = {0, 2, 4};
  state.runBudget = 25;
  state.points = 12345;
  state.hasColors = true;
  const nlohmann::json identity = {{"input", "/a/b.laz"}, {"voxel", 0.7}};
  ASSERT_TRUE(saveReconstructState(path, identity, state).ok());
  const std::optional<ReconstructState> back = loadReconstructState(path, identity);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->layout.grid.origin, state.layout.grid.origin);
  EXPECT_EQ(back->layout.grid.voxel, state.layout.grid.voxel);
  EXPECT_EQ(back->layout.grid.corners, state.layout.grid.corners);
  EXPECT_EQ(back->layout.n, 9u);
  EXPECT_EQ(back->layout.chunks, state.layout.chunks);
  EXPECT_EQ(back->runs.chunks, state.runs.chunks);
  EXPECT_EQ(back->runs.points, state.runs.points);
  EXPECT_EQ(back->runs.firstChunk, state.runs.firstChunk);
  EXPECT_EQ(back->runBudget, 25u);
  EXPECT_EQ(back->points, 12345u);
  EXPECT_TRUE(back->hasColors);
  EXPECT_FALSE(back->estimatedNormals);
  EXPECT_FALSE(loadReconstructState(path, {{"input", "/a/b.laz"}, {"voxel", 0.8}}).has_value());
  ReconstructState odd = state;  // runs that do not start at the first chunk
  odd.runs.firstChunk = {1, 2, 4};
  ASSERT_TRUE(saveReconstructState(path, identity, odd).ok());
  EXPECT_FALSE(loadReconstructState(path, identity).has_value());
  odd = state;  // no budget to find the dense chunks by
  odd.runBudget = 0;
  ASSERT_TRUE(saveReconstructState(path, identity, odd).ok());
  EXPECT_FALSE(loadReconstructState(path, identity).has_value());
  odd = state;  // a chunk outside the lattice
  odd.runs.chunks.back() = 5 * 6 * 7;
  ASSERT_TRUE(saveReconstructState(path, identity, odd).ok());
  EXPECT_FALSE(loadReconstructState(path, identity).has_value());
  ASSERT_TRUE(saveReconstructState(path, identity, state).ok());
  test::writeFile(path, test::readFile(path).substr(0, 40));
  EXPECT_FALSE(loadReconstructState(path, identity).has_value());
}

}  // namespace
}  // namespace lodforge
