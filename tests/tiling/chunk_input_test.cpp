#include "lodforge/tiling/chunk_input.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/generate/cad.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/io/model_io.h"
#include "lodforge/tiling/chunk_sizing.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

using Triangle = std::array<double, 9>;

// Every chunk's welded mesh as position triples, each with the chunk it is in.
std::vector<std::pair<Triangle, std::uint64_t>> chunkTriangles(const ChunkWriter& chunks) {
  std::vector<std::pair<Triangle, std::uint64_t>> out;
  for (const auto& [index, count] : chunks.triangleCounts()) {
    Result<MeshPart> mesh = chunks.load(cellOfIndex(chunks.grid(), index));
    EXPECT_TRUE(mesh.ok());
    for (std::size_t t = 0; t < mesh->indices.size(); t += 3) {
      Triangle tri{};
      for (std::size_t k = 0; k < 3; ++k) {
        const Vec3d p = mesh->positions[mesh->indices[t + k]];
        tri[3 * k] = p.x, tri[3 * k + 1] = p.y, tri[3 * k + 2] = p.z;
      }
      out.emplace_back(tri, index);
    }
  }
  return out;
}

// Sorted, without the chunks (order-free comparison).
std::vector<Triangle> contents(const ChunkWriter& chunks) {
  std::vector<Triangle> out;
  for (const auto& [tri, index] : chunkTriangles(chunks)) out.push_back(tri);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ChunkInput, StreamedPlyGivesTheSameChunksAsTheLoadedModel) {
  test::TempDir dir;
  // The horse as a binary PLY (streamed) and as a GLB (loaded whole).
  Result<Model> horse = readModel(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(horse.ok());
  ASSERT_TRUE(writeModel(*horse, dir.file("horse.glb")).ok());
  ChunkInputOptions options;
  options.chunkSize = 0.04;
  options.vertexCacheBytes = 1;  // the smallest cache: four blocks, many misses
  options.workDirectory = dir.file("streamed");
  Result<ChunkInput> streamed = chunkInput(test::dataPath("meshes/horse.ply"), options);
  ASSERT_TRUE(streamed.ok()) << streamed.error().message;
  EXPECT_TRUE(streamed->streamed);
  options.workDirectory = dir.file("loaded");
  Result<ChunkInput> loaded = chunkInput(dir.file("horse.glb"), options);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_FALSE(loaded->streamed);
  EXPECT_EQ(streamed->inputTriangles, horse->triangleCount());
  EXPECT_EQ(streamed->chunks->triangleCounts(), loaded->chunks->triangleCounts());
  EXPECT_GT(streamed->chunks->triangleCounts().size(), 8u);
  EXPECT_EQ(contents(*streamed->chunks), contents(*loaded->chunks));
  EXPECT_FALSE(fs::exists(dir.file("streamed/vertices.bin")));  // the work file is gone
}

TEST(ChunkInput, ReadingCuttingAndWritingInParallelWritesTheSameFiles) {
  // The face pass runs as a pipeline (read, cut in parallel, add in file order): the chunk files
  // are byte-identical whatever the thread count.
  test::TempDir dir;
  std::map<std::string, std::string> files[2];
  for (const int threads : {1, 2}) {
    ChunkInputOptions options;
    options.chunkSize = 0.03;
    options.chunkBufferBytes = 1 << 16;  // many appends while the pipeline runs
    options.threads = threads;
    options.workDirectory = dir.file(fmt::format("t{}", threads));
    Result<ChunkInput> input = chunkInput(test::dataPath("meshes/horse.ply"), options);
    ASSERT_TRUE(input.ok()) << input.error().message;
    for (const std::string& name : test::listFolder(options.workDirectory + "/chunks"))
      files[threads - 1][name] = test::readFile(options.workDirectory + "/chunks/" + name);
  }
  EXPECT_GT(files[0].size(), 20u);
  EXPECT_EQ(files[0], files[1]);
}

TEST(ChunkInput, NormalsOfAPlyWithoutThemAreTheWholeInputsAreaWeightedNormals) {
  // A PLY without normals gets them in an extra face pass, summed in the vertex work file through
  // the block cache (the smallest cache: blocks are written back and read again): they match the
  // area-weighted normals of the whole mesh at every chunk vertex, and cut vertices get normals
  // between their edge's ends.
  test::TempDir dir;
  Result<Model> horse = readModel(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(horse.ok());
  horse->normals.clear();
  ASSERT_TRUE(writeModel(*horse, dir.file("bare.ply")).ok());
  std::vector<Vec3f> expected(horse->vertexCount());
  computeVertexNormals(horse->positions, horse->indices, expected);
  std::map<std::array<double, 3>, Vec3f> normalAt;
  for (std::size_t v = 0; v < horse->vertexCount(); ++v) {
    const Vec3d p = horse->origin + toDouble(horse->positions[v]);
    normalAt[{p.x, p.y, p.z}] = expected[v];
  }
  ChunkInputOptions options;
  options.chunkSize = 0.04;
  options.vertexCacheBytes = 1;
  options.workDirectory = dir.file("work");
  Result<ChunkInput> input = chunkInput(dir.file("bare.ply"), options);
  ASSERT_TRUE(input.ok()) << input.error().message;
  std::size_t original = 0, cut = 0;
  for (const auto& [index, count] : input->chunks->triangleCounts()) {
    Result<MeshPart> mesh = input->chunks->load(cellOfIndex(input->chunks->grid(), index));
    ASSERT_TRUE(mesh.ok());
    ASSERT_EQ(mesh->normals.size(), mesh->positions.size());
    for (std::size_t v = 0; v < mesh->positions.size(); ++v) {
      const Vec3d& p = mesh->positions[v];
      ASSERT_NEAR(length(mesh->normals[v]), 1.0f, 1e-4f);
      const auto found = normalAt.find({p.x, p.y, p.z});
      if (found == normalAt.end()) {
        ++cut;
        continue;
      }
      ++original;
      EXPECT_GT(dot(mesh->normals[v], found->second), std::cos(0.1 * 3.14159265 / 180)) << v;
    }
  }
  EXPECT_GT(original, horse->vertexCount() * 9 / 10);
  EXPECT_GT(cut, 100u);
}

TEST(ChunkInput, KeptInMemoryEqualsWrittenToDisk) {
  test::TempDir dir;
  ChunkInputOptions options;
  options.chunkSize = 0.05;
  options.chunkBufferBytes = 4096;  // many appends
  options.workDirectory = dir.file("disk");
  Result<ChunkInput> disk = chunkInput(test::dataPath("meshes/stanford-bunny.obj"), options);
  ASSERT_TRUE(disk.ok());
  options.keepInMemory = true;
  options.workDirectory = dir.file("memory");
  Result<ChunkInput> memory = chunkInput(test::dataPath("meshes/stanford-bunny.obj"), options);
  ASSERT_TRUE(memory.ok());
  EXPECT_TRUE(test::listFolder(dir.file("memory/chunks")).empty());
  EXPECT_EQ(contents(*disk->chunks), contents(*memory->chunks));
}

TEST(ChunkInput, SmallSegmentsStayWholeAndLargeOnesAreCut) {
  // A generated assembly, loaded whole (GLB: segments are the parts' connected components) and
  // streamed (PLY with object ids: segments are the objects). Every part smaller than a chunk
  // arrives uncut (each of its triangles is in some chunk as it was), and from the PLY all in
  // one chunk; parts larger than a chunk are cut (more triangles come out than went in).
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 5}, dir.file("cad.glb")).ok());
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 5}, dir.file("cad.ply")).ok());
  for (const std::string name : {"cad.glb", "cad.ply"}) {
    Result<Model> model = readModel(dir.file(name));
    ASSERT_TRUE(model.ok());
    const Aabb box = computeBounds(model->positions);
    ChunkInputOptions options;
    options.chunkSize = box.longestSide() / 6;
    options.workDirectory = dir.file(name + ".work");
    Result<ChunkInput> input = chunkInput(dir.file(name), options);
    ASSERT_TRUE(input.ok()) << input.error().message;
    EXPECT_EQ(input->streamed, name == "cad.ply");
    std::map<Triangle, std::uint64_t> chunkOf;
    for (const auto& [tri, index] : chunkTriangles(*input->chunks)) chunkOf[tri] = index;
    std::size_t small = 0, large = 0;
    for (std::size_t o = 0; o < model->objectCount(); ++o) {
      const Aabb bounds = computeBounds(model->objectPositions(o));
      if (bounds.longestSide() >= options.chunkSize * 0.999) {
        ++large;
        continue;
      }
      ++small;
      std::set<std::uint64_t> chunks;
      const auto indices = model->objectIndices(o);
      for (std::size_t t = 0; t < indices.size(); t += 3) {
        Triangle tri{};
        for (std::size_t k = 0; k < 3; ++k) {
          const Vec3d p = model->origin + toDouble(model->objectPositions(o)[indices[t + k]]);
          tri[3 * k] = p.x, tri[3 * k + 1] = p.y, tri[3 * k + 2] = p.z;
        }
        const auto found = chunkOf.find(tri);
        ASSERT_NE(found, chunkOf.end()) << name << ": object " << o << " triangle " << t / 3;
        chunks.insert(found->second);
      }
      if (name == "cad.ply") {
        EXPECT_EQ(chunks.size(), 1u) << "object " << o;
      }
    }
    EXPECT_GT(small, 200u);
    EXPECT_GT(large, 0u);
    EXPECT_GT(input->chunks->triangleCount(), input->inputTriangles);
  }
}

// A real CAD assembly (the STEP motor: dense small parts beside long-sliver plates): leaf
// chunks of about the target, not hundreds of slivers. Before, a triangle-weighted mean load
// halved the chunk edge down to 94 chunks of median 240 triangles holding 1.93 x the input
// (each cut triangle a centroid fan); now a few chunks of about 2 K hold little more than it.
TEST(ChunkInput, ACadAssemblyMakesLeafChunksOfAboutTheTargetNotSlivers) {
  test::TempDir dir;
  ChunkInputOptions options;
  options.workDirectory = dir.file("work");
  Result<ChunkInput> input = chunkInput(test::dataPath("cad/as1_motor.step"), options);
  ASSERT_TRUE(input.ok()) << input.error().message;
  const auto counts = input->chunks->triangleCounts();
  std::vector<std::uint64_t> sizes;
  for (const auto& [cell, count] : counts) sizes.push_back(count);
  std::sort(sizes.begin(), sizes.end());
  ASSERT_FALSE(sizes.empty());
  const std::uint64_t target = leafTriangles(options, input->inputTriangles);
  EXPECT_LE(sizes.size(), 2 * input->inputTriangles / target) << "chunks";
  EXPECT_GE(sizes[sizes.size() / 2], target / 2) << "median chunk";
  EXPECT_LE(input->chunks->triangleCount(), input->inputTriangles * 13 / 10)
      << input->inputTriangles << " triangles in";
}

TEST(ChunkInput, AFaceOutsideTheVerticesIsBadInputNamingTheFile) {
  test::TempDir dir;
  std::ofstream(dir.file("bad.ply"))
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  ChunkInputOptions options;
  options.workDirectory = dir.file("work");
  Result<ChunkInput> input = chunkInput(dir.file("bad.ply"), options);
  ASSERT_FALSE(input.ok());
  EXPECT_EQ(input.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(input.error().message.find("bad.ply"), std::string::npos) << input.error().message;
}

}  // namespace
}  // namespace lodforge
