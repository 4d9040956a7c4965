#include "lodforge/tiles/point_tiles.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// The points of one of our point GLBs, back in the tileset's z-up frame: POSITION as float or
// as KHR_mesh_quantization shorts, placed by the root's translation and the child's grid.
std::vector<Vec3d> readPointGlb(const std::string& path, nlohmann::json* gltfOut = nullptr) {
  const std::string bytes = test::readFile(path);
  EXPECT_GE(bytes.size(), 28u);
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  const nlohmann::json gltf = nlohmann::json::parse(bytes.substr(20, jsonLength));
  if (gltfOut) *gltfOut = gltf;
  const std::size_t binAt = 20 + jsonLength + 8;
  const auto& primitive = gltf["meshes"][0]["primitives"][0];
  EXPECT_EQ(primitive["mode"], 0);
  EXPECT_FALSE(primitive.contains("indices"));
  const auto& accessor = gltf["accessors"][primitive["attributes"]["POSITION"].get<int>()];
  const auto& view = gltf["bufferViews"][accessor["bufferView"].get<int>()];
  const std::size_t offset =
      binAt + view.value("byteOffset", 0u) + accessor.value("byteOffset", 0u);
  const std::size_t count = accessor["count"];
  const int type = accessor["componentType"];
  const std::size_t stride = view.value("byteStride", type == 5126 ? 12u : 8u);
  // Root (translation) -> child node drawing the mesh (its own translation and scale).
  Vec3d rootT, childT;
  double scale = 1;
  for (const auto& node : gltf["nodes"]) {
    if (node.contains("mesh")) {
      if (node.contains("translation"))
        childT = {node["translation"][0], node["translation"][1], node["translation"][2]};
      if (node.contains("scale")) scale = node["scale"][0];
    } else if (node.contains("translation")) {
      rootT = {node["translation"][0], node["translation"][1], node["translation"][2]};
    }
  }
  std::vector<Vec3d> points(count);
  for (std::size_t i = 0; i < count; ++i) {
    Vec3d q;
    for (int k = 0; k < 3; ++k) {
      if (type == 5126) {
        float f = 0;
        std::memcpy(&f, bytes.data() + offset + i * stride + 4 * std::size_t(k), 4);
        q[k] = f;
      } else {
        std::int16_t s = 0;
        std::memcpy(&s, bytes.data() + offset + i * stride + 2 * std::size_t(k), 2);
        q[k] = s;
      }
    }
    const Vec3d y = rootT + childT + q * scale;
    points[i] = {y.x, -y.z, y.y};  // y-up back to z-up
  }
  return points;
}

// Walks a tileset: boxes nest, errors do not grow downwards, every content exists.
void checkTileset(const nlohmann::json& tile, const fs::path& root, double parentError,
                  const nlohmann::json* parentBox, std::vector<std::string>& uris) {
  const double error = tile["geometricError"];
  EXPECT_LE(error, parentError);
  const auto& box = tile["boundingVolume"]["box"];
  if (parentBox) {
    for (int k = 0; k < 3; ++k) {
      const double lo = box[k].get<double>() - box[3 + 4 * k].get<double>();
      const double hi = box[k].get<double>() + box[3 + 4 * k].get<double>();
      const double plo = (*parentBox)[k].get<double>() - (*parentBox)[3 + 4 * k].get<double>();
      const double phi = (*parentBox)[k].get<double>() + (*parentBox)[3 + 4 * k].get<double>();
      EXPECT_GE(lo, plo - 1e-6);
      EXPECT_LE(hi, phi + 1e-6);
    }
  }
  if (tile.contains("content")) {
    const std::string uri = tile["content"]["uri"];
    EXPECT_TRUE(fs::exists(root / uri)) << uri;
    uris.push_back(uri);
  }
  if (tile.contains("children")) {
    for (const auto& child : tile["children"]) checkTileset(child, root, error, &box, uris);
  } else {
    EXPECT_EQ(error, 0) << "a block's tile holds every point left";
  }
}

TEST(PointTiles, EveryPointIsInExactlyOneTileOfAnAddTree) {
  test::TempDir dir;
  Random random(4);
  // Input points bucketed by 10 cm cell: each output point must match one within 0.1 mm.
  std::map<std::tuple<long, long, long>, std::vector<Vec3d>> want;
  const auto cell = [](const Vec3d& p) {
    return std::tuple<long, long, long>{std::lround(std::floor(p.x * 10)),
                                        std::lround(std::floor(p.y * 10)),
                                        std::lround(std::floor(p.z * 10))};
  };
  {
    std::ofstream out(dir.file("cloud.xyz"));
    out.precision(12);
    for (int i = 0; i < 30'000; ++i) {
      const double x = random.uniform(0, 400), y = random.uniform(0, 300);
      const double z = 10 * std::sin(x / 40) + random.uniform(0, 0.5);
      out << x << ' ' << y << ' ' << z << ' ' << i % 256 << " 100 50\n";
      // What the text holds, to its 12 digits.
      std::ostringstream text;
      text.precision(12);
      text << x << ' ' << y << ' ' << z;
      Vec3d p;
      std::istringstream(text.str()) >> p.x >> p.y >> p.z;
      want[cell(p)].push_back(p);
    }
  }
  PointTilesOptions options;
  options.blockSize = 2'000;
  options.tilePoints = 1'500;
  options.quantize = false;
  Result<PointTilesStats> stats = writePointTiles(dir.file("cloud.xyz"), dir.file("t"), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->points, 30'000u);
  EXPECT_GE(stats->depth, 4);
  const auto tileset = nlohmann::json::parse(test::readFile(dir.file("t/tileset.json")));
  EXPECT_EQ(tileset["asset"]["version"], "1.1");
  EXPECT_EQ(tileset["root"]["refine"], "ADD");
  EXPECT_FALSE(tileset["root"].contains("transform"));
  std::vector<std::string> uris;
  checkTileset(tileset["root"], dir.file("t"), tileset["geometricError"], nullptr, uris);
  EXPECT_EQ(uris.size(), stats->tiles);
  // Every input point once, over all tiles (float contents: to a tenth of a millimetre).
  std::size_t rootPoints = 0, total = 0, unmatched = 0;
  for (const std::string& uri : uris) {
    const std::vector<Vec3d> points = readPointGlb(dir.file("t/" + uri));
    if (uri == "tiles/b.glb") rootPoints = points.size();
    total += points.size();
    for (const Vec3d& p : points) {
      bool found = false;
      const auto [cx, cy, cz] = cell(p);
      for (long dx = -1; dx <= 1 && !found; ++dx)
        for (long dy = -1; dy <= 1 && !found; ++dy)
          for (long dz = -1; dz <= 1 && !found; ++dz) {
            auto it = want.find({cx + dx, cy + dy, cz + dz});
            if (it == want.end()) continue;
            auto& list = it->second;
            for (std::size_t i = 0; i < list.size(); ++i) {
              if (length(list[i] - p) < 1e-4) {
                list.erase(list.begin() + static_cast<std::ptrdiff_t>(i));
                found = true;
                break;
              }
            }
          }
      unmatched += !found;
    }
  }
  EXPECT_EQ(total, 30'000u);
  EXPECT_EQ(unmatched, 0u);
  // The root holds about tilePoints, spread over the whole cloud.
  EXPECT_GT(rootPoints, 1'500u / 3);
  EXPECT_LT(rootPoints, 1'500u * 3);
  // Nothing else left: the tileset folder only.
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_TRUE(entry.path().filename() == "t" || entry.path().filename() == "cloud.xyz")
        << entry.path();
}

TEST(PointTiles, RepresentativesMakeCoarserCutsSubsetsOfFinerOnes) {
  Random random(6);
  std::vector<CloudPoint> points(3'000);
  for (CloudPoint& p : points)
    p.position = {random.uniform(0, 10), random.uniform(0, 10), random.uniform(0, 0.3)};
  std::vector<std::uint32_t> first;
  std::vector<ClusterNode> tree = clusterBlock(points, {5, 5, 0}, false, {}, &first);
  for (ClusterNode& n : tree) n.error = pointTileError(n);
  const std::vector<std::uint32_t> reps = clusterRepresentatives(tree, points, first, {5, 5, 0});
  for (std::size_t i = 0; i < tree.size(); ++i) {
    if (tree[i].leaf()) {
      EXPECT_EQ(reps[i], first[i]);
    } else {
      EXPECT_TRUE(reps[i] == reps[tree[i].firstChild] || reps[i] == reps[tree[i].firstChild + 1]);
    }
  }
  const auto repsOfCut = [&](float tolerance) {
    std::set<std::uint32_t> out;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      if (tree[t].error <= tolerance || tree[t].leaf()) {
        out.insert(reps[t]);
      } else {
        stack.push_back(tree[t].firstChild);
        stack.push_back(tree[t].firstChild + 1);
      }
    }
    return out;
  };
  std::set<std::uint32_t> coarser = repsOfCut(1e9f);
  EXPECT_EQ(coarser.size(), 1u);
  for (float tolerance : {2.0f, 1.0f, 0.5f, 0.2f, 0.1f, 0.0f}) {
    const std::set<std::uint32_t> finer = repsOfCut(tolerance);
    EXPECT_TRUE(std::includes(finer.begin(), finer.end(), coarser.begin(), coarser.end()))
        << tolerance;
    coarser = finer;
  }
  EXPECT_EQ(coarser.size(), points.size());
}

TEST(PointTiles, PlacesALasOnEarthFromItsCoordinateSystem) {
  test::TempDir dir;
  PointTilesOptions options;
  options.blockSize = 20'000;
  options.tilePoints = 10'000;
  Result<PointTilesStats> stats =
      writePointTiles(test::dataPath("points/autzen_trim.las"), dir.file("t"), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_NE(stats->crs.find("Lambert_Conformal_Conic"), std::string::npos);
  const auto tileset = nlohmann::json::parse(test::readFile(dir.file("t/tileset.json")));
  ASSERT_TRUE(tileset["root"].contains("transform"));
  const auto& m = tileset["root"]["transform"];
  // The local frame's origin in ECEF: Autzen Stadium, Eugene, Oregon (44.06 N, 123.07 W).
  const double x = m[12], y = m[13], z = m[14];
  const double lon = std::atan2(y, x) * 180 / 3.14159265358979;
  const double lat = std::atan2(z, std::hypot(x, y)) * 180 / 3.14159265358979;
  EXPECT_NEAR(lon, -123.07, 0.05);
  EXPECT_NEAR(lat, 43.9, 0.3);  // geocentric latitude, a little below the geodetic 44.06
  // Quantised contents, all 110,000 points over the tiles.
  std::vector<std::string> uris;
  checkTileset(tileset["root"], dir.file("t"), tileset["geometricError"], nullptr, uris);
  std::size_t total = 0;
  for (const std::string& uri : uris) {
    nlohmann::json gltf;
    total += readPointGlb(dir.file("t/" + uri), &gltf).size();
    EXPECT_NE(gltf["extensionsUsed"].dump().find("KHR_mesh_quantization"), std::string::npos);
  }
  EXPECT_EQ(total, 110'000u);
}

}  // namespace
}  // namespace lodforge
