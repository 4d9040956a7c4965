#include "lodforge/tiles/tileset.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/generate/cad.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/builder.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

struct Box {
  double c[3], h[3];
};

Box boxOf(const nlohmann::json& tile) {
  const auto& b = tile.at("boundingVolume").at("box");
  Box box{};
  for (int i = 0; i < 3; ++i) {
    box.c[i] = b.at(static_cast<std::size_t>(i)).get<double>();
    box.h[i] = b.at(static_cast<std::size_t>(3 + 4 * i)).get<double>();  // axis-aligned
  }
  return box;
}

// The rules of docs/tiles.md: errors non-increasing, children inside parents, contents exist.
void checkTile(const nlohmann::json& tile, const fs::path& directory, double parentError,
               const Box* parent, int& contents) {
  const double error = tile.at("geometricError").get<double>();
  EXPECT_LE(error, parentError);
  EXPECT_EQ(tile.at("refine"), "REPLACE");
  const Box box = boxOf(tile);
  if (parent != nullptr) {
    for (int i = 0; i < 3; ++i) {
      const double slack = 1e-9 * (1 + std::abs(parent->c[i]));
      EXPECT_GE(box.c[i] - box.h[i], parent->c[i] - parent->h[i] - slack);
      EXPECT_LE(box.c[i] + box.h[i], parent->c[i] + parent->h[i] + slack);
    }
  }
  if (tile.contains("content")) {
    const fs::path file = directory / tile["content"]["uri"].get<std::string>();
    ASSERT_TRUE(fs::exists(file)) << file;
    std::ifstream in(file, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    EXPECT_EQ(std::memcmp(magic, "glTF", 4), 0);
    ++contents;
  }
  for (const auto& child : tile.value("children", nlohmann::json::array()))
    checkTile(child, directory, error, &box, contents);
}

TEST(Tiles, HorseTilesetFollowsTheRules) {
  const test::TempDir temp;  // removed with the test
  const fs::path out = temp.path() / "horse-tiles";
  fs::remove_all(out);
  TilesOptions options;
  options.input.chunkSize = 0.05;  // the horse is ~0.2 m long: a few chunks per axis
  options.octree.errorSamples = 2000;
  Result<TilesStats> stats = writeTiles(test::dataPath("meshes/horse.ply"), out.string(), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_GE(stats->levels, 2);
  EXPECT_GT(stats->leaves, 8u);
  std::ifstream in(out / "tileset.json");
  const nlohmann::json tileset = nlohmann::json::parse(in);
  EXPECT_EQ(tileset.at("asset").at("version"), "1.1");
  int contents = 0;
  checkTile(tileset.at("root"), out, tileset.at("geometricError").get<double>(), nullptr, contents);
  EXPECT_EQ(static_cast<std::uint64_t>(contents), stats->tiles);
  EXPECT_EQ(static_cast<std::uint64_t>(
                std::distance(fs::directory_iterator(out / "tiles"), fs::directory_iterator{})),
            stats->tiles);
  // Nothing but the tileset is left behind: no staging or work directories.
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("horse-tiles."), std::string::npos)
        << entry.path();
}

TEST(Tiles, QuantizedContentsStayWithinTheErrorTheyAddToTheTileset) {
  // The same horse tileset with and without KHR_mesh_quantization: the contents hold the same
  // vertices in the same order, each quantised one within the error the tile's geometricError
  // gained, and the tileset is smaller.
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "quantized";
  fs::remove_all(root);
  TilesOptions options;
  options.input.chunkSize = 0.05;
  options.octree.errorSamples = 2000;
  const std::string horse = test::dataPath("meshes/horse.ply");
  options.quantize = false;
  Result<TilesStats> plain = writeTiles(horse, (root / "float").string(), options);
  options.quantize = true;
  Result<TilesStats> quantized = writeTiles(horse, (root / "quantized").string(), options);
  ASSERT_TRUE(plain.ok() && quantized.ok());
  EXPECT_LT(static_cast<double>(quantized->outputBytes),
            0.8 * static_cast<double>(plain->outputBytes));
  const auto load = [](const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  };
  int compared = 0, quantizedTiles = 0;
  std::function<void(const nlohmann::json&, const nlohmann::json&)> compare =
      [&](const nlohmann::json& a, const nlohmann::json& b) {
        const double added =
            b.at("geometricError").get<double>() - a.at("geometricError").get<double>();
        EXPECT_GE(added, 0);
        if (a.contains("content")) {
          const std::string uri = a["content"]["uri"];
          Result<Model> floats = readGltf((root / "float" / uri).string());
          Result<Model> ints = readGltf((root / "quantized" / uri).string());
          ASSERT_TRUE(floats.ok() && ints.ok());
          ASSERT_EQ(floats->indices, ints->indices) << uri;
          double worst = 0;
          for (std::size_t v = 0; v < floats->vertexCount(); ++v) {
            const Vec3d f = floats->origin + toDouble(floats->positions[v]);
            const Vec3d q = ints->origin + toDouble(ints->positions[v]);
            worst = std::max(worst, length(f - q));
          }
          EXPECT_LE(worst, added + 1e-6) << uri;
          quantizedTiles += worst > 0 ? 1 : 0;
          ++compared;
        }
        ASSERT_EQ(a.value("children", nlohmann::json::array()).size(),
                  b.value("children", nlohmann::json::array()).size());
        for (std::size_t c = 0; c < a.value("children", nlohmann::json::array()).size(); ++c)
          compare(a["children"][c], b["children"][c]);
      };
  compare(load(root / "float/tileset.json").at("root"),
          load(root / "quantized/tileset.json").at("root"));
  EXPECT_EQ(static_cast<std::uint64_t>(compared), quantized->tiles);
  EXPECT_GE(static_cast<std::uint64_t>(quantizedTiles), quantized->leaves);
}

TEST(Tiles, NeighbouringTilesAgreeOnTheNormalsOfTheirSharedVertices) {
  // Shading seams: a vertex on a chunk border is in two or more tiles; its normal must be the
  // same in each (the input's, not one from each tile's half of its fan). The horse has normals
  // in its file; the bunny has none, so they are computed over the whole input.
  for (const char* name : {"meshes/horse.ply", "meshes/stanford-bunny.obj"}) {
    const test::TempDir temp;  // removed with the test
    const fs::path out = temp.path() / "normals";
    fs::remove_all(out);
    TilesOptions options;
    options.input.chunkSize = std::string(name).find("horse") != std::string::npos ? 0.04 : 0.03;
    options.octree.errorSamples = 1000;
    options.quantize = false;
    Result<TilesStats> stats = writeTiles(test::dataPath(name), out.string(), options);
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    // Per level: position (to 1e-7) -> the normals every tile of that level gives it.
    std::map<std::pair<int, std::array<std::int64_t, 3>>, std::vector<Vec3f>> seen;
    for (const auto& entry : fs::directory_iterator(out / "tiles")) {
      const int level = std::stoi(entry.path().filename().string());
      Result<Model> tile = readGltf(entry.path().string());
      ASSERT_TRUE(tile.ok());
      for (std::size_t v = 0; v < tile->vertexCount(); ++v) {
        const Vec3d p = tile->origin + toDouble(tile->positions[v]);
        const std::array<std::int64_t, 3> key = {std::llround(p.x * 1e7), std::llround(p.y * 1e7),
                                                 std::llround(p.z * 1e7)};
        seen[{level, key}].push_back(tile->normals[v]);
      }
    }
    std::size_t shared = 0;
    float worst = 1;
    for (const auto& [key, normals] : seen) {
      if (normals.size() < 2) continue;
      ++shared;
      for (const Vec3f& n : normals) worst = std::min(worst, dot(n, normals[0]));
    }
    EXPECT_GT(shared, 200u) << name;
    EXPECT_GE(static_cast<double>(worst), std::cos(0.05 * 3.14159265358979 / 180)) << name;
  }
}

// Average cache misses per triangle of `indices` through a FIFO cache of `size` entries.
double fifoMissesPerTriangle(const std::vector<std::uint32_t>& indices, std::size_t size) {
  std::vector<std::uint32_t> fifo;
  std::size_t misses = 0;
  for (std::uint32_t v : indices) {
    if (std::find(fifo.begin(), fifo.end(), v) != fifo.end()) continue;
    ++misses;
    fifo.push_back(v);
    if (fifo.size() > size) fifo.erase(fifo.begin());
  }
  return static_cast<double>(misses) /
         static_cast<double>(std::max<std::size_t>(1, indices.size() / 3));
}

TEST(Tiles, ContentsAreInVertexCacheAndFetchOrder) {
  // Triangles ordered for the GPU's post-transform cache, vertices in order of first use. The
  // horse's own order (chunks keep it) misses a 16-entry FIFO 2.7 times per triangle, the tiles
  // ~0.7 times.
  const test::TempDir temp;  // removed with the test
  const fs::path out = temp.path() / "cache-order";
  fs::remove_all(out);
  TilesOptions options;
  options.input.chunkSize = 0.05;
  options.octree.errorSamples = 1000;
  const std::string horse = test::dataPath("meshes/horse.ply");
  ASSERT_TRUE(writeTiles(horse, out.string(), options).ok());
  Result<Model> input = readModel(horse);
  ASSERT_TRUE(input.ok());
  const double inputMisses = fifoMissesPerTriangle(input->indices, 16);
  int tiles = 0;
  for (const auto& entry : fs::directory_iterator(out / "tiles")) {
    Result<Model> tile = readGltf(entry.path().string());
    ASSERT_TRUE(tile.ok());
    if (tile->indices.size() < 3000) continue;  // too few triangles for a stable ratio
    ++tiles;
    const double misses = fifoMissesPerTriangle(tile->indices, 16);
    EXPECT_LT(misses, 0.85) << entry.path();
    EXPECT_LT(misses, 0.5 * inputMisses) << entry.path();
    std::uint32_t next = 0;
    for (std::uint32_t v : tile->indices) {
      ASSERT_LE(v, next) << entry.path() << ": a vertex used before the ones ahead of it";
      next = std::max(next, v + 1);
    }
  }
  EXPECT_GE(tiles, 4);
}

TEST(Tiles, ParentsAreQuantizedOnlyWhenTheGridIsFarBelowTheirError) {
  OctreeNode node;
  node.bounds = Aabbd{{0, 0, 0}, {65.535, 10, 10}};  // a grid step of 1 mm
  node.triangles = 100;
  EXPECT_TRUE(tileQuantized(node));  // a leaf
  EXPECT_NEAR(tileQuantizationError(node, true), 0.5e-3 * std::sqrt(3.0), 1e-12);
  EXPECT_EQ(tileQuantizationError(node, false), 0);
  node.level = 2;
  node.geometricError = 0.032;  // 32 x 0.87 mm would be 0.0277: inside
  EXPECT_TRUE(tileQuantized(node));
  node.geometricError = 0.02;
  EXPECT_FALSE(tileQuantized(node));
}

TEST(Tiles, AssembliesAndPackagesAreTiledByPart) {
  // A generated 600-part assembly as GLB and as a progressive package (.lfp, read at full
  // detail): the same leaves, tilesets that follow the rules, and coarse tiles that shrink
  // because parents leave out the smallest whole parts.
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "assembly";
  fs::remove_all(root);
  fs::create_directories(root);
  ASSERT_TRUE(generateCad({.objects = 600, .seed = 9}, (root / "cad.glb").string()).ok());
  ASSERT_TRUE(buildPackage((root / "cad.glb").string(), (root / "cad.lfp").string()).ok());
  TilesOptions options;
  options.octree.errorSamples = 2000;
  options.input.trianglesPerChunk = 8192;  // a few levels for ~160 K triangles
  std::vector<TilesStats> stats;
  for (const char* input : {"cad.glb", "cad.lfp"}) {
    const fs::path out = root / (std::string(input) + "-tiles");
    Result<TilesStats> built = writeTiles((root / input).string(), out.string(), options);
    ASSERT_TRUE(built.ok()) << built.error().message;
    std::ifstream in(out / "tileset.json");
    const nlohmann::json tileset = nlohmann::json::parse(in);
    int contents = 0;
    checkTile(tileset.at("root"), out, tileset.at("geometricError").get<double>(), nullptr,
              contents);
    EXPECT_EQ(static_cast<std::uint64_t>(contents), built->tiles);
    EXPECT_GE(built->levels, 2);
    EXPECT_GT(built->droppedSegments, 0u);
    stats.push_back(*built);
  }
  EXPECT_EQ(stats[0].inputTriangles, stats[1].inputTriangles);
  EXPECT_EQ(stats[0].leafTriangles, stats[1].leafTriangles);
  EXPECT_EQ(stats[0].leaves, stats[1].leaves);
}

TEST(Tiles, GeoreferencedByOriginOrByCrs) {
  const test::TempDir temp;  // removed with the test
  const fs::path dir = temp.path() / "geo-tiles";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A 200 m x 200 m terrain patch in UTM 33N, in doubles (centimetres matter at 5e6 m).
  {
    std::ofstream ply(dir / "utm.ply");
    const int n = 40;
    ply << "ply\nformat ascii 1.0\nelement vertex " << (n + 1) * (n + 1)
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << 2 * n * n
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    ply.precision(17);
    for (int y = 0; y <= n; ++y)
      for (int x = 0; x <= n; ++x)
        ply << 500000.0 + 5 * x << " " << 5200000.0 + 5 * y << " " << 300 + std::sin(x * 0.3)
            << "\n";
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const int a = y * (n + 1) + x;
        ply << "3 " << a << " " << a + 1 << " " << a + n + 2 << "\n3 " << a << " " << a + n + 2
            << " " << a + n + 1 << "\n";
      }
    }
  }
  TilesOptions options;
  options.input.chunkSize = 60;
  options.octree.errorSamples = 1000;
  options.crs = "EPSG:32633";
  Result<TilesStats> stats =
      writeTiles((dir / "utm.ply").string(), (dir / "crs").string(), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  std::ifstream in(dir / "crs" / "tileset.json");
  const nlohmann::json tileset = nlohmann::json::parse(in);
  const auto transform = tileset["root"]["transform"].get<std::array<double, 16>>();
  // The frame sits on the first vertex (500000, 5200000, 300 m): near 15 E, 46.9 N.
  const Vec3d origin{transform[12], transform[13], transform[14]};
  EXPECT_NEAR(length(origin), 6'367'000, 10'000);
  EXPECT_NEAR(std::atan2(origin.y, origin.x) * 180 / 3.14159265358979, 15.0, 1e-6);
  // Contents are local: the box centre is ~100 m from the frame's origin, not 5e6 m.
  const Box box = boxOf(tileset["root"]);
  EXPECT_NEAR(box.c[0], 100, 2);
  EXPECT_NEAR(box.c[1], 100, 2);
  EXPECT_LT(std::abs(box.c[2]), 5);

  // --origin: the model's (0,0,0) at the given place, east-north-up.
  TilesOptions placed;
  placed.input.chunkSize = 0.05;
  placed.octree.errorSamples = 1000;
  placed.origin = Geodetic{8.5417, 47.3769, 408};
  stats = writeTiles(test::dataPath("meshes/horse.ply"), (dir / "origin").string(), placed);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  std::ifstream in2(dir / "origin" / "tileset.json");
  const nlohmann::json horse = nlohmann::json::parse(in2);
  const auto placedTransform = horse["root"]["transform"].get<std::array<double, 16>>();
  EXPECT_EQ(placedTransform, eastNorthUpToEcef(*placed.origin).m);
}

TEST(Tiles, BadInputIsRefusedWithoutLeavingAnything) {
  const test::TempDir temp;  // removed with the test
  const fs::path dir = temp.path() / "bad-tiles";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path input = dir / "broken.ply";
  std::ofstream(input)
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  Result<TilesStats> stats = writeTiles(input.string(), (dir / "out").string(), {});
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(stats.error().message.find("broken.ply"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
}

TEST(Tiles, RefusesToOverwriteADirectoryThatIsNotATileset) {
  const test::TempDir temp;  // removed with the test
  const fs::path dir = temp.path() / "not-a-tileset";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "precious.txt") << "keep me";
  Result<TilesStats> stats = writeTiles(test::dataPath("meshes/horse.ply"), dir.string(), {});
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.error().kind, ErrorKind::kUsage);
  EXPECT_TRUE(fs::exists(dir / "precious.txt"));
}

}  // namespace
}  // namespace lodforge
