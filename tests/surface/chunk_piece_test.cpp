#include "lodforge/surface/chunk_piece.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

// A wavy sheet over [0, 12]² with some noise, every point three times over (each copy its own
// colour): the nearest point to a vertex is then always a tie, which the rule must break alike.
std::vector<CloudRecord> wavySheet(std::size_t n, std::uint64_t seed) {
  Random random(seed);
  std::vector<CloudRecord> records;
  for (std::size_t i = 0; records.size() < n; ++i) {
    const double x = random.uniform(0, 12), y = random.uniform(0, 12);
    const double z =
        0.6 * std::sin(0.7 * x) + 0.4 * std::cos(0.9 * y) + random.uniform(-0.02, 0.02);
    const Vec3f normal = normalizeOr(Vec3f{static_cast<float>(-0.42 * std::cos(0.7 * x)),
                                           static_cast<float>(0.36 * std::sin(0.9 * y)), 1.0f},
                                     Vec3f{0, 0, 1});
    for (int copy = 0; copy < 3; ++copy)
      records.push_back(
          {records.size(),
           {x, y, z},
           normal,
           {static_cast<std::uint8_t>(random.below(256)),
            static_cast<std::uint8_t>(random.below(256)), static_cast<std::uint8_t>(copy), 255}});
  }
  return records;
}

ChunkLayout layoutOf(const std::vector<CloudRecord>& records, const DistanceOptions& distance,
                     std::uint32_t chunkVoxels) {
  Aabbd bounds;
  for (const CloudRecord& r : records) bounds.add(r.position);
  Result<ChunkLayout> layout = layOutChunks(bounds, 0.25, chunkVoxels, distance.radius, "sheet");
  EXPECT_TRUE(layout.ok());
  return *layout;
}

// The records within the radius and a voxel of the chunk: its members, in input order.
std::vector<std::uint32_t> membersOf(const ChunkLayout& layout, std::uint64_t chunk,
                                     const std::vector<CloudRecord>& records, double radius) {
  const std::array<std::uint64_t, 3> at = layout.chunkAt(chunk);
  std::vector<std::uint32_t> members;
  for (std::uint32_t i = 0; i < records.size(); ++i) {
    const ChunkBox box = layout.reach(records[i].position, radius + 1);
    bool in = true;
    for (std::size_t a = 0; a < 3; ++a) in = in && box.lo[a] <= at[a] && at[a] <= box.hi[a];
    if (in) members.push_back(i);
  }
  return members;
}

void expectSamePiece(const SurfacePiece& a, const SurfacePiece& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  if (!a.positions.empty()) {  // (memcmp of an empty vector's null data is undefined)
    EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * 24), 0);
    EXPECT_EQ(std::memcmp(a.normals.data(), b.normals.data(), a.normals.size() * 12), 0);
  }
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.indices, b.indices);
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (std::size_t v = 0; v < a.colors.size(); ++v) ASSERT_EQ(a.colors[v], b.colors[v]) << v;
}

// A chunk streamed from its file in blocks, its rows shared between 1 or 3 threads, makes the
// same bits as the chunk held in memory; and a vertex's colour is its nearest member's, the first
// in input order among equally near ones (checked against every member).
TEST(ChunkPiece, StreamedFromItsFileIsTheSameAsHeldInMemory) {
  test::TempDir dir;
  const std::vector<CloudRecord> records = wavySheet(60'000, 3);
  const DistanceOptions distance;
  // Chunks of 12 voxels (many chunks, each file one block) and of 64 (the sheet in a few
  // chunks, files of several blocks).
  for (const std::uint32_t n : {12u, 64u}) {
    const ChunkLayout layout = layoutOf(records, distance, n);
    std::size_t checked = 0, vertices = 0, largest = 0;
    for (std::uint64_t chunk = 0; chunk < layout.chunkCount(); ++chunk) {
      const std::vector<std::uint32_t> members = membersOf(layout, chunk, records, distance.radius);
      if (members.empty()) continue;
      largest = std::max(largest, members.size());
      const SurfacePiece held = heldChunkPiece(layout, chunk, members, records, distance, true);
      const std::string file = dir.file(fmt::format("chunk-{}-{}.points", n, chunk));
      Result<RecordWriter> writer = RecordWriter::create(file);
      ASSERT_TRUE(writer.ok());
      for (const std::uint32_t m : members) ASSERT_TRUE(writer->add(records[m]).ok());
      ASSERT_TRUE(writer->finish().ok());
      for (const int threads : {1, 3}) {
        tbb::task_arena arena(threads);
        Result<SurfacePiece> streamed =
            arena.execute([&] { return streamedChunkPiece(layout, chunk, file, distance, true); });
        ASSERT_TRUE(streamed.ok()) << streamed.error().message;
        expectSamePiece(held, *streamed);
      }
      for (std::size_t v = 0; v < held.positions.size(); v += 7) {
        std::uint32_t best = 0;
        double best2 = std::numeric_limits<double>::infinity();
        for (const std::uint32_t m : members) {
          const Vec3d d = records[m].position - held.positions[v];
          if (dot(d, d) < best2) best = m, best2 = dot(d, d);
        }
        ASSERT_EQ(held.colors[v], records[best].color) << chunk << ' ' << v;
      }
      vertices += held.positions.size();
      ++checked;
    }
    EXPECT_GT(checked, n == 12 ? 8u : 0u);
    EXPECT_GT(vertices, 10'000u);
    if (n == 64) {
      EXPECT_GT(largest, 40'000u);  // more than a block of the file (32 K records)
    }
  }
}

}  // namespace
}  // namespace lodforge
