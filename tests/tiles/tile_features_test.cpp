#include "lodforge/tiles/tile_features.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/random.h"
#include "lodforge/generate/cad.h"
#include "lodforge/io/cad/cad_reader.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/model_io.h"
#include "lodforge/tiles/tile_content.h"
#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_parts.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

TEST(TileFeatures, RowsIndexTheTilesOwnPartsInAscendingOrder) {
  Random random(5);
  std::vector<std::uint32_t> features(1000);
  for (std::uint32_t& f : features) f = 1000 + static_cast<std::uint32_t>(random.below(37)) * 13;
  const TileFeatures tile = tileFeatures(features);
  EXPECT_TRUE(std::is_sorted(tile.parts.begin(), tile.parts.end()));
  EXPECT_EQ(std::adjacent_find(tile.parts.begin(), tile.parts.end()), tile.parts.end());
  EXPECT_EQ(tile.parts.size(), std::set<std::uint32_t>(features.begin(), features.end()).size());
  ASSERT_EQ(tile.rows.size(), features.size());
  for (std::size_t v = 0; v < features.size(); ++v) {
    ASSERT_LT(tile.rows[v], tile.parts.size());
    EXPECT_EQ(tile.parts[tile.rows[v]], features[v]);
  }
}

// One GLB tile as written without quantisation: the JSON, the binary chunk, and what its
// EXT_mesh_features / EXT_structural_metadata say.
struct DecodedTile {
  nlohmann::json gltf;
  std::string bin;
  std::vector<Vec3d> world;         // z-up, the root translation added back
  std::vector<std::uint32_t> rows;  // per vertex
  std::uint32_t featureCount = 0;
  std::vector<std::uint32_t> ids;  // per row
  std::vector<std::string> names, paths, sources, materials, layers;
};

std::string_view viewBytes(const DecodedTile& tile, std::uint32_t view) {
  const auto& v = tile.gltf["bufferViews"][view];
  EXPECT_EQ(v.value("byteOffset", 0u) % 8, 0u) << "property table views are 8-byte aligned";
  return std::string_view(tile.bin).substr(v.value("byteOffset", 0u),
                                           v["byteLength"].get<std::size_t>());
}

std::vector<std::string> strings(const DecodedTile& tile, const nlohmann::json& property,
                                 std::size_t count) {
  EXPECT_EQ(property["stringOffsetType"], "UINT32");
  const std::string_view values = viewBytes(tile, property["values"]);
  const std::string_view offsetBytes = viewBytes(tile, property["stringOffsets"]);
  EXPECT_EQ(offsetBytes.size(), 4 * (count + 1));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < count && 4 * (i + 2) <= offsetBytes.size(); ++i) {
    std::uint32_t from, to;
    std::memcpy(&from, offsetBytes.data() + 4 * i, 4);
    std::memcpy(&to, offsetBytes.data() + 4 * i + 4, 4);
    EXPECT_LE(from, to);
    EXPECT_LE(to, values.size());
    out.emplace_back(values.substr(from, to - from));
  }
  return out;
}

DecodedTile decodeTile(const fs::path& glb) {
  std::ifstream in(glb, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  DecodedTile tile;
  std::uint32_t jsonLength = 0, binLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  tile.gltf = nlohmann::json::parse(bytes.substr(20, jsonLength));
  std::memcpy(&binLength, bytes.data() + 20 + jsonLength, 4);
  tile.bin = bytes.substr(28 + jsonLength, binLength);
  const auto& primitive = tile.gltf["meshes"][0]["primitives"][0];
  const auto accessorBytes = [&](std::uint32_t a) {
    const auto& accessor = tile.gltf["accessors"][a];
    const auto& view = tile.gltf["bufferViews"][accessor["bufferView"].get<std::uint32_t>()];
    return tile.bin.data() + view.value("byteOffset", 0u) + accessor.value("byteOffset", 0u);
  };
  const std::uint32_t position = primitive["attributes"]["POSITION"];
  EXPECT_EQ(tile.gltf["accessors"][position]["componentType"], 5126);
  const std::size_t count = tile.gltf["accessors"][position]["count"];
  const auto& root = tile.gltf["nodes"][tile.gltf["scenes"][0]["nodes"][0].get<std::size_t>()];
  const auto t = root["translation"].get<std::array<double, 3>>();
  for (std::size_t v = 0; v < count; ++v) {
    float p[3];
    std::memcpy(p, accessorBytes(position) + 12 * v, 12);
    tile.world.push_back({p[0] + t[0], -(p[2] + t[2]), p[1] + t[1]});  // y-up back to z-up
  }
  if (!primitive.contains("extensions")) return tile;
  const auto& ids = primitive["extensions"]["EXT_mesh_features"]["featureIds"][0];
  tile.featureCount = ids["featureCount"];
  EXPECT_EQ(ids["attribute"], 0);
  EXPECT_EQ(ids["propertyTable"], 0);
  const std::uint32_t feature = primitive["attributes"]["_FEATURE_ID_0"];
  const int type = tile.gltf["accessors"][feature]["componentType"];
  for (std::size_t v = 0; v < count; ++v) {
    const char* at = accessorBytes(feature) + 4 * v;
    if (type == 5123) {
      std::uint16_t row;
      std::memcpy(&row, at, 2);
      tile.rows.push_back(row);
    } else {
      float row;
      std::memcpy(&row, at, 4);
      tile.rows.push_back(static_cast<std::uint32_t>(row));
    }
  }
  const auto& metadata = tile.gltf["extensions"]["EXT_structural_metadata"];
  EXPECT_EQ(metadata["schema"]["classes"]["part"]["properties"]["name"]["semantic"], "NAME");
  const auto& table = metadata["propertyTables"][0];
  EXPECT_EQ(table["class"], "part");
  const std::size_t rows = table["count"];
  const std::string_view idBytes = viewBytes(tile, table["properties"]["id"]["values"]);
  EXPECT_EQ(idBytes.size(), 4 * rows);
  tile.ids.resize(idBytes.size() / 4);
  std::memcpy(tile.ids.data(), idBytes.data(), idBytes.size());
  tile.names = strings(tile, table["properties"]["name"], rows);
  // A column of empty strings is left out (a buffer view may not be empty).
  const auto column = [&](const char* key) {
    return table["properties"].contains(key) ? strings(tile, table["properties"][key], rows)
                                             : std::vector<std::string>(rows);
  };
  tile.paths = column("path");
  tile.sources = column("source");
  tile.materials = column("material");
  tile.layers = column("layer");
  const auto used = tile.gltf["extensionsUsed"];
  EXPECT_NE(std::find(used.begin(), used.end(), "EXT_mesh_features"), used.end());
  EXPECT_NE(std::find(used.begin(), used.end(), "EXT_structural_metadata"), used.end());
  return tile;
}

// A few levels for a generated assembly of some hundred parts, float positions to decode.
TilesOptions assemblyOptions() {
  TilesOptions options;
  options.octree.errorSamples = 2000;
  options.input.trianglesPerChunk = 8192;
  options.quantize = false;
  return options;
}

// Tiles of a generated 600-part assembly: every vertex of every tile, leaves and the coarse
// parents that merged and dropped parts, names the part it came from (it lies in that part's
// box); the leaves hold every part; parts.json says which parts each level lost, exactly as the
// tiles show.
TEST(TileFeatures, EveryVertexOfEveryTileNamesItsPart) {
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "tile-features";
  fs::remove_all(root);
  fs::create_directories(root);
  const std::string input = (root / "cad.glb").string();
  ASSERT_TRUE(generateCad({.objects = 600, .seed = 9}, input).ok());
  Result<Model> model = readModel(input);
  ASSERT_TRUE(model.ok());
  Result<TilesStats> stats = writeTiles(input, (root / "tiles").string(), assemblyOptions());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->parts, model->objectCount());
  EXPECT_GT(stats->droppedSegments, 0u);

  std::map<int, std::set<std::uint32_t>> partsByLevel;
  std::size_t multiPartParents = 0;
  for (const auto& entry : fs::directory_iterator(root / "tiles" / "tiles")) {
    const DecodedTile tile = decodeTile(entry.path());
    const int level = std::stoi(entry.path().filename().string());
    ASSERT_EQ(tile.rows.size(), tile.world.size()) << entry.path();
    ASSERT_EQ(tile.ids.size(), tile.featureCount);
    ASSERT_EQ(tile.names.size(), tile.featureCount);
    EXPECT_TRUE(std::is_sorted(tile.ids.begin(), tile.ids.end()));
    for (std::size_t r = 0; r < tile.ids.size(); ++r) {
      ASSERT_LT(tile.ids[r], model->objectCount());
      EXPECT_EQ(tile.names[r], model->objectName(tile.ids[r]));
      EXPECT_EQ(tile.sources[r], "cad.glb");
      partsByLevel[level].insert(tile.ids[r]);
    }
    std::vector<std::uint8_t> rowUsed(tile.featureCount, 0);
    for (std::size_t v = 0; v < tile.world.size(); ++v) {
      ASSERT_LT(tile.rows[v], tile.featureCount);
      rowUsed[tile.rows[v]] = 1;
      const ObjectRecord& part = model->objects[tile.ids[tile.rows[v]]];
      Aabbd box{model->origin + toDouble(part.bounds.min),
                model->origin + toDouble(part.bounds.max)};
      const double slack = 1e-4 * (1 + length(box.size()));
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_GE(tile.world[v][axis], box.min[axis] - slack) << entry.path() << " vertex " << v;
        ASSERT_LE(tile.world[v][axis], box.max[axis] + slack) << entry.path() << " vertex " << v;
      }
    }
    EXPECT_EQ(std::count(rowUsed.begin(), rowUsed.end(), 0), 0) << "a row no vertex uses";
    if (level > 0 && tile.featureCount > 1) ++multiPartParents;
  }
  EXPECT_GT(multiPartParents, 0u);
  std::size_t withTriangles = 0;
  for (std::size_t o = 0; o < model->objectCount(); ++o)
    withTriangles += model->objects[o].triangleCount > 0 ? 1 : 0;
  EXPECT_EQ(partsByLevel[0].size(), withTriangles);

  std::ifstream in(root / "tiles" / kPartsFileName);
  const nlohmann::json parts = nlohmann::json::parse(in);
  EXPECT_EQ(parts["source"], "cad.glb");
  ASSERT_EQ(parts["parts"].size(), model->objectCount());
  EXPECT_EQ(parts["parts"][7]["name"], model->objectName(7));
  const auto box = parts["parts"][7]["bounds"].get<std::array<double, 6>>();
  const ObjectRecord& seventh = model->objects[7];
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(box[axis], model->origin[axis] + seventh.bounds.min[axis], 1e-9);
    EXPECT_NEAR(box[3 + axis], model->origin[axis] + seventh.bounds.max[axis], 1e-9);
  }
  ASSERT_EQ(parts["levels"].size(), static_cast<std::size_t>(stats->levels) + 1);
  std::size_t missingAtTop = 0;
  for (const auto& level : parts["levels"]) {
    const int l = level["level"];
    std::vector<std::uint32_t> expected;
    for (std::uint32_t o = 0; o < model->objectCount(); ++o)
      if (!partsByLevel[l].contains(o)) expected.push_back(o);
    EXPECT_EQ(level["missing"].get<std::vector<std::uint32_t>>(), expected) << "level " << l;
    missingAtTop = expected.size();
  }
  EXPECT_GT(missingAtTop, 0u);
  std::ifstream tilesetIn(root / "tiles" / "tileset.json");
  EXPECT_EQ(nlohmann::json::parse(tilesetIn)["asset"]["extras"]["parts"], kPartsFileName);
}

// A STEP assembly's CAD layers reach the tiles: every row of every tile's property table has its
// part's layer, and parts.json lists it beside the name.
TEST(TileFeatures, CadLayersReachEveryTileAndPartsJson) {
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "tile-layers";
  fs::remove_all(root);
  fs::create_directories(root);
  const std::string input = (root / "cad.step").string();
  ASSERT_TRUE(generateCad({.objects = 40, .seed = 4}, input).ok());
  Result<Model> model = readCad(input);
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_GT(model->layers.size(), 3u);
  Result<TilesStats> stats = writeTiles(input, (root / "tiles").string(), assemblyOptions());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  std::set<std::string> seen;
  std::size_t tiles = 0;
  for (const auto& entry : fs::directory_iterator(root / "tiles" / "tiles")) {
    ++tiles;
    const DecodedTile tile = decodeTile(entry.path());
    ASSERT_EQ(tile.layers.size(), tile.ids.size()) << entry.path();
    for (std::size_t r = 0; r < tile.ids.size(); ++r) {
      ASSERT_LT(tile.ids[r], model->objectCount());
      EXPECT_EQ(tile.layers[r], model->objectLayer(tile.ids[r])) << entry.path() << " row " << r;
      seen.insert(tile.layers[r]);
    }
  }
  EXPECT_GT(tiles, 2u);  // a tree of tiles, not one holding every part
  EXPECT_EQ(seen, std::set<std::string>(model->layers.begin(), model->layers.end()));
  std::ifstream in(root / "tiles" / kPartsFileName);
  const nlohmann::json parts = nlohmann::json::parse(in);
  ASSERT_EQ(parts["parts"].size(), model->objectCount());
  for (std::size_t o = 0; o < model->objectCount(); ++o)
    EXPECT_EQ(parts["parts"][o]["layer"], model->objectLayer(o)) << o;
}

// Parts keep their materials through a GLB and the tiles: glass (BLEND, alpha 0.12 in its
// colours) stays translucent at every level that still holds it, in a primitive of its own
// drawing only glass; metal keeps its metallic-roughness; the table names each part's material.
TEST(TileFeatures, EveryPartKeepsItsMaterialAtEveryLevel) {
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "tile-materials";
  fs::remove_all(root);
  fs::create_directories(root);
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 4}, (root / "plain.glb").string()).ok());
  Result<Model> model = readModel((root / "plain.glb").string());
  ASSERT_TRUE(model.ok());
  ASSERT_TRUE(model->hasColors());
  model->materials = {{.name = "glass",
                       .baseColor = {0.6f, 0.8f, 0.9f, 0.12f},
                       .roughness = 0.05f,
                       .alphaMode = AlphaMode::kBlend,
                       .doubleSided = true},
                      {.name = "steel", .metallic = 1, .roughness = 0.3f},
                      {.name = "lamp", .emissive = {1, 0.5f, 0}}};
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    ObjectRecord& object = model->objects[o];
    object.material = o % 4 == 3 ? kNoMaterial : static_cast<std::uint32_t>(o % 4);
    for (std::uint32_t v = 0; v < object.vertexCount; ++v)
      if (o % 4 == 0) model->colors[object.vertexOffset + v].a = 31;  // 0.12
  }
  const std::string input = (root / "cad.glb").string();
  ASSERT_TRUE(writeGlb(*model, input, {.doubleSided = false}).ok());
  Result<Model> back = readModel(input);
  ASSERT_TRUE(back.ok());
  // (Objects without a material got the writer's "default", which reads back as a fourth.)
  ASSERT_EQ(back->materials.size(), 4u);
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(back->materials[m].name, model->materials[m].name);
    EXPECT_EQ(back->materials[m].alphaMode, model->materials[m].alphaMode);
    EXPECT_EQ(back->materials[m].metallic, model->materials[m].metallic);
    EXPECT_EQ(back->materials[m].emissive, model->materials[m].emissive);
    EXPECT_EQ(back->materials[m].doubleSided, model->materials[m].doubleSided);
  }
  EXPECT_EQ(back->objects[4].material, 0u);
  EXPECT_EQ(back->materials[back->objects[3].material].name, "default");

  Result<TilesStats> stats = writeTiles(input, (root / "tiles").string(), assemblyOptions());
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  std::set<int> levelsWithGlass;
  for (const auto& entry : fs::directory_iterator(root / "tiles" / "tiles")) {
    const DecodedTile tile = decodeTile(entry.path());
    const std::vector<std::string>& materialNames = tile.materials;
    for (std::size_t r = 0; r < tile.ids.size(); ++r) {
      const std::uint32_t m = back->objects[tile.ids[r]].material;
      EXPECT_EQ(materialNames[r], m == kNoMaterial ? "" : back->materials[m].name);
    }
    std::set<std::string> seen;
    for (const auto& primitive : tile.gltf["meshes"][0]["primitives"]) {
      const auto& material = tile.gltf["materials"][primitive["material"].get<std::size_t>()];
      const std::string name = material.value("name", "");
      EXPECT_TRUE(seen.insert(name).second) << "two primitives with material " << name;
      // Every vertex this primitive draws is of a part with this material.
      const auto& accessor = tile.gltf["accessors"][primitive["indices"].get<std::size_t>()];
      const auto& view = tile.gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
      const char* at =
          tile.bin.data() + view.value("byteOffset", 0u) + accessor.value("byteOffset", 0u);
      const bool wide = accessor["componentType"] == 5125;
      for (std::size_t i = 0; i < accessor["count"].get<std::size_t>(); ++i) {
        std::uint32_t v = 0;
        std::memcpy(&v, at + (wide ? 4 : 2) * i, wide ? 4 : 2);
        const std::uint32_t m = back->objects[tile.ids[tile.rows[v]]].material;
        ASSERT_EQ(name, m == kNoMaterial ? "default" : back->materials[m].name) << entry.path();
      }
      if (name == "glass") {
        EXPECT_EQ(material["alphaMode"], "BLEND");
        EXPECT_EQ(material["doubleSided"], true);
        levelsWithGlass.insert(std::stoi(entry.path().filename().string()));
      } else {
        EXPECT_FALSE(material.contains("alphaMode")) << name;
      }
      if (name == "steel") {
        EXPECT_EQ(material["pbrMetallicRoughness"]["metallicFactor"], 1.0);
      }
      if (name == "lamp") {
        EXPECT_EQ(material["emissiveFactor"][1], 0.5);
      }
    }
  }
  EXPECT_EQ(levelsWithGlass.size(), static_cast<std::size_t>(stats->levels) + 1)
      << "glass is translucent at every level";
}

// An OBJ of two groups sharing a seam is a scan split in two by default: no parts, welded as
// one surface; asked for, its groups become parts that weld apart.
TEST(TileFeatures, ObjectsOfAScanBecomePartsOnlyWhenAsked) {
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "tile-features-obj";
  fs::remove_all(root);
  fs::create_directories(root);
  std::ofstream obj(root / "two.obj");
  obj << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
      << "o left\nf 1 2 3\nf 1 3 4\no right\nf 2 5 6\nf 2 6 3\n";
  obj.close();
  TilesOptions options;
  options.quantize = false;
  Result<TilesStats> scan = writeTiles((root / "two.obj").string(), (root / "a").string(), options);
  ASSERT_TRUE(scan.ok()) << scan.error().message;
  EXPECT_EQ(scan->parts, 0u);
  EXPECT_FALSE(fs::exists(root / "a" / kPartsFileName));
  options.input.parts = PartsMode::kOn;
  Result<TilesStats> parts =
      writeTiles((root / "two.obj").string(), (root / "b").string(), options);
  ASSERT_TRUE(parts.ok()) << parts.error().message;
  EXPECT_EQ(parts->parts, 2u);
  const DecodedTile welded = decodeTile(root / "a" / "tiles" / "0-0-0-0.glb");
  const DecodedTile apart = decodeTile(root / "b" / "tiles" / "0-0-0-0.glb");
  EXPECT_EQ(welded.world.size(), 6u);  // the seam's two vertices once
  EXPECT_EQ(apart.world.size(), 8u);   // once per part
  EXPECT_EQ(apart.names, (std::vector<std::string>{"left", "right"}));
}

// A mesh of one object (a scan) gets no features: nothing to pick, no bytes spent.
TEST(TileFeatures, AnInputOfOneObjectHasNone) {
  const test::TempDir temp;  // removed with the test
  const fs::path root = temp.path() / "tile-features-one";
  fs::remove_all(root);
  Result<TilesStats> stats =
      writeTiles(test::dataPath("meshes/horse.ply"), (root / "tiles").string(), TilesOptions{});
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->parts, 0u);
  EXPECT_FALSE(fs::exists(root / "tiles" / kPartsFileName));
  for (const auto& entry : fs::directory_iterator(root / "tiles" / "tiles")) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(bytes.find("EXT_mesh_features"), std::string::npos) << entry.path();
  }
}

}  // namespace
}  // namespace lodforge
