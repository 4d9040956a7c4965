#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/io/mesh/gltf_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

using nlohmann::json;

// A GLB container around a JSON document and a binary chunk (both padded to 4 bytes).
std::string makeGlb(const json& document, std::string binary) {
  std::string text = document.dump();
  while (text.size() % 4) text += ' ';
  while (binary.size() % 4) binary += '\0';
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::uint32_t total =
      12 + 8 + std::uint32_t(text.size()) + (binary.empty() ? 0 : 8 + std::uint32_t(binary.size()));
  std::string out = "glTF" + u32(2) + u32(total) + u32(std::uint32_t(text.size())) + "JSON" + text;
  if (!binary.empty()) out += u32(std::uint32_t(binary.size())) + std::string("BIN\0", 4) + binary;
  return out;
}

template <class T>
std::string raw(std::initializer_list<T> values) {
  std::string out;
  for (T v : values) out.append(reinterpret_cast<const char*>(&v), sizeof v);
  return out;
}

// One triangle (positions at 0, indices at 36) used by several tests, with a document skeleton.
json triangleDocument() {
  return json{{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}, {"name", "part"}}}},
              {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
              {"buffers", {{{"byteLength", 44}}}},
              {"bufferViews",
               {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 6}}}},
              {"accessors",
               {{{"bufferView", 0},
                 {"componentType", 5126},
                 {"count", 3},
                 {"type", "VEC3"},
                 {"min", {0, 0, 0}},
                 {"max", {1, 1, 0}}},
                {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}}};
}
std::string triangleBinary() {
  return raw<float>({0, 0, 0, 1, 0, 0, 0, 1, 0}) + raw<std::uint16_t>({0, 1, 2});
}

Result<Model> readGlb(const std::string& bytes, const std::string& name = "test.glb") {
  return readGltfFromMemory(test::bytesOf(bytes), name, {.allowExternalFiles = false});
}

TEST(GltfRead, RealCadAssembliesGiveOneObjectPerNodeInstance) {
  struct Case {
    const char* file;
    std::uint64_t objects, triangles;
  };
  for (const Case& c :
       {Case{"meshes/2CylinderEngine.glb", 67, 121'496}, Case{"meshes/as1_motor.glb", 35, 27'506},
        Case{"meshes/Motor-c.glb", 17, 30'682}}) {
    Result<Model> model = readGltf(test::dataPath(c.file));
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_EQ(model->objectCount(), c.objects) << c.file;
    EXPECT_EQ(model->triangleCount(), c.triangles) << c.file;
    EXPECT_TRUE(isConsistent(*model));
  }
}

// Each object's assembly path is its node's names from the scene root, as the file's own
// hierarchy gives them (read here straight from the GLB's JSON).
TEST(GltfRead, ObjectsKeepTheirPathInTheNodeTree) {
  const std::string path = test::dataPath("meshes/as1_motor.glb");
  const std::string bytes = test::readFile(path);
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  const nlohmann::json gltf = nlohmann::json::parse(bytes.substr(20, jsonLength));
  const auto& nodes = gltf["nodes"];
  std::vector<int> parent(nodes.size(), -1);
  for (std::size_t n = 0; n < nodes.size(); ++n)
    for (int child : nodes[n].value("children", std::vector<int>{}))
      parent[static_cast<std::size_t>(child)] = static_cast<int>(n);
  std::multiset<std::string> expected;
  std::size_t deep = 0;
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    if (!nodes[n].contains("mesh")) continue;
    std::string p;
    for (int at = static_cast<int>(n); at >= 0; at = parent[static_cast<std::size_t>(at)]) {
      const std::string name = nodes[static_cast<std::size_t>(at)].value("name", "");
      p = (name.empty() ? "node " + std::to_string(at) : name) + (p.empty() ? "" : "/" + p);
    }
    deep += std::count(p.begin(), p.end(), '/') >= 2 ? 1 : 0;
    expected.insert(p);
  }
  Result<Model> model = readGltf(path);
  ASSERT_TRUE(model.ok()) << model.error().message;
  std::multiset<std::string> found;
  for (std::size_t o = 0; o < model->objectCount(); ++o) found.emplace(model->objectPath(o));
  EXPECT_EQ(found, expected);
  EXPECT_GT(deep, 0u);  // a real tree, not a flat list
  EXPECT_TRUE(isConsistent(*model));
}

TEST(GltfRead, InstancedMeshesAreExpandedWithTheirOwnTransforms) {
  // 2CylinderEngine draws 29 meshes through 67 nodes: objects with equal triangle counts and
  // equal local shape exist, but at different places.
  Result<Model> model = readGltf(test::dataPath("meshes/2CylinderEngine.glb"));
  ASSERT_TRUE(model.ok());
  std::map<std::uint32_t, std::vector<std::size_t>> byTriangles;
  for (std::size_t o = 0; o < model->objectCount(); ++o)
    byTriangles[model->objects[o].triangleCount].push_back(o);
  bool sawInstances = false;
  for (const auto& [triangles, objects] : byTriangles) {
    if (objects.size() < 2) continue;
    sawInstances = true;
    const Aabb a = model->objects[objects[0]].bounds, b = model->objects[objects[1]].bounds;
    EXPECT_FALSE(a == b) << "instances should sit at different places";
  }
  EXPECT_TRUE(sawInstances);
  EXPECT_LT(byTriangles.size(), model->objectCount());
}

TEST(GltfRead, NodeTransformsMaterialsAndVertexColours) {
  json doc = triangleDocument();
  // Parent translates by (10, 0, 0); child scales by 2 and carries the mesh.
  doc["scenes"][0]["nodes"] = {1};
  doc["nodes"] = {{{"mesh", 0}, {"name", "child"}, {"scale", {2, 2, 2}}},
                  {{"name", "parent"}, {"translation", {10, 0, 0}}, {"children", {0}}}};
  doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 0.5, 0.0, 1.0}}}}}};
  doc["meshes"][0]["primitives"][0]["material"] = 0;
  // COLOR_0 as normalised unsigned bytes, multiplied by the base colour.
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 44}, {"byteLength", 12}});
  doc["accessors"].push_back({{"bufferView", 2},
                              {"componentType", 5121},
                              {"normalized", true},
                              {"count", 3},
                              {"type", "VEC4"}});
  doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 2;
  doc["buffers"][0]["byteLength"] = 56;
  std::string binary = triangleBinary() + std::string(2, '\0') +
                       raw<std::uint8_t>({255, 255, 255, 255, 0, 255, 0, 255, 255, 0, 0, 128});
  Result<Model> model = readGlb(makeGlb(doc, binary));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 1u);
  EXPECT_EQ(model->objectName(0), "child");
  EXPECT_EQ(toDouble(model->positions[1]) + model->origin, (Vec3d{12, 0, 0}));
  EXPECT_EQ(toDouble(model->positions[2]) + model->origin, (Vec3d{10, 2, 0}));
  ASSERT_TRUE(model->hasColors());
  EXPECT_EQ(model->colors[0], (Rgba8{255, 128, 0, 255}));
  EXPECT_EQ(model->colors[1], (Rgba8{0, 128, 0, 255}));
  EXPECT_EQ(model->colors[2], (Rgba8{255, 0, 0, 128}));
}

// A node's extras.layer (what lodforge's GLB writer keeps of a CAD layer) names its objects'
// layer, each distinct name once; an extras.layer that is not a string, or empty, is no layer.
TEST(GltfRead, NodeExtrasLayerIsTheObjectsLayer) {
  json doc = triangleDocument();
  doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 4};
  doc["nodes"] = {{{"mesh", 0}, {"name", "a"}, {"extras", {{"layer", "structure"}}}},
                  {{"mesh", 0}, {"name", "b"}, {"extras", {{"layer", 7}}}},
                  {{"mesh", 0}, {"name", "c"}, {"extras", {{"layer", "structure"}}}},
                  {{"mesh", 0}, {"name", "d"}, {"extras", {{"layer", ""}}}},
                  {{"mesh", 0}, {"name", "e"}, {"extras", {{"layer", "wiring"}}}}};
  Result<Model> model = readGlb(makeGlb(doc, triangleBinary()));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 5u);
  EXPECT_EQ(model->layers, (std::vector<std::string>{"structure", "wiring"}));
  const std::vector<std::string> expected = {"structure", "", "structure", "", "wiring"};
  for (std::size_t o = 0; o < 5; ++o) EXPECT_EQ(model->objectLayer(o), expected[o]) << o;
}

TEST(GltfRead, MirroringTransformsKeepTrianglesFacingTheirNormals) {
  json doc = triangleDocument();
  doc["nodes"][0]["scale"] = {-1, 1, 1};
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 44}, {"byteLength", 36}});
  doc["accessors"].push_back(
      {{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2;
  doc["buffers"][0]["byteLength"] = 80;
  const std::string binary =
      triangleBinary() + std::string(2, '\0') + raw<float>({0, 0, 1, 0, 0, 1, 0, 0, 1});
  Result<Model> model = readGlb(makeGlb(doc, binary));
  ASSERT_TRUE(model.ok()) << model.error().message;
  const auto& p = model->positions;
  const auto& i = model->indices;
  const Vec3f faceNormal = cross(p[i[1]] - p[i[0]], p[i[2]] - p[i[0]]);
  EXPECT_GT(dot(faceNormal, model->normals[0]), 0.0f);
  EXPECT_EQ(model->normals[0], (Vec3f{0, 0, 1}));
}

TEST(GltfRead, StripsFansSparseAccessorsAndNonIndexedPrimitives) {
  json doc = triangleDocument();
  // Four positions; the strip 0 1 2 3 gives (0 1 2) and (2 1 3); the non-indexed fan (0 1 2 3)
  // gives (0 1 2) and (0 2 3). A sparse accessor moves vertex 3 of a zero base accessor.
  doc["buffers"][0]["byteLength"] = 48 + 4 + 12;
  doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                        {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 4}},
                        {{"buffer", 0}, {"byteOffset", 52}, {"byteLength", 12}}};
  doc["accessors"] = {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
                      {{"componentType", 5126},
                       {"count", 4},
                       {"type", "VEC3"},
                       {"sparse",
                        {{"count", 1},
                         {"indices", {{"bufferView", 1}, {"componentType", 5125}}},
                         {"values", {{"bufferView", 2}}}}}}};
  doc["meshes"] = {{{"primitives",
                     {{{"attributes", {{"POSITION", 0}}}, {"mode", 5}},
                      {{"attributes", {{"POSITION", 1}}}, {"mode", 6}}}}}};
  const std::string binary = raw<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}) +
                             raw<std::uint32_t>({3}) + raw<float>({7, 8, 9});
  Result<Model> model = readGlb(makeGlb(doc, binary));
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 4u);
  EXPECT_EQ(std::vector<std::uint32_t>(model->indices.begin(), model->indices.begin() + 6),
            (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
  EXPECT_EQ(std::vector<std::uint32_t>(model->indices.begin() + 6, model->indices.end()),
            (std::vector<std::uint32_t>{4, 5, 6, 4, 6, 7}));
  EXPECT_EQ(model->positions[7], (Vec3f{7, 8, 9}));
  EXPECT_EQ(model->positions[5], (Vec3f{0, 0, 0}));
}

TEST(GltfRead, PointAndLinePrimitivesAreReportedNotDroppedInSilence) {
  // The triangle, plus its three corners again as a point primitive and as a line strip, and
  // two of them as an indexed loop (a CAD export's edges share the faces' vertices): the
  // triangle is read, and the warnings count the corners that were not.
  json doc = triangleDocument();
  doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 0}}}, {"mode", 0}});
  doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 0}}}, {"mode", 1}});
  doc["meshes"][0]["primitives"].push_back(
      {{"attributes", {{"POSITION", 0}}}, {"mode", 3}, {"indices", 2}});  // 2 of the 3 corners
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 4}});
  doc["accessors"].push_back(
      {{"bufferView", 2}, {"componentType", 5123}, {"count", 2}, {"type", "SCALAR"}});
  std::vector<std::string> warnings;
  Result<Model> model =
      readGltfFromMemory(test::bytesOf(makeGlb(doc, triangleBinary())), "edges.glb",
                         {.allowExternalFiles = false, .warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 1u);
  EXPECT_EQ(model->vertexCount(), 3u);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0], "edges.glb: 1 point primitive (3 corners) not read: only triangles are");
  EXPECT_EQ(warnings[1], "edges.glb: 2 line primitives (5 corners) not read: only triangles are");
  // Triangles alone: no warning.
  warnings.clear();
  ASSERT_TRUE(readGltfFromMemory(test::bytesOf(makeGlb(triangleDocument(), triangleBinary())),
                                 "plain.glb", {.allowExternalFiles = false, .warnings = &warnings})
                  .ok());
  EXPECT_TRUE(warnings.empty());
}

// A file that draws only points (our point tiles, a scan exported as glTF) is a point set, read
// as a PLY without faces is; an indexed point primitive is not read, and says so.
TEST(GltfRead, AFileOfPointsAloneIsReadAsAPointSet) {
  json doc = triangleDocument();
  doc["meshes"][0]["primitives"][0] = {{"attributes", {{"POSITION", 0}}}, {"mode", 0}};
  std::vector<std::string> warnings;
  Result<Model> model =
      readGltfFromMemory(test::bytesOf(makeGlb(doc, triangleBinary())), "points.glb",
                         {.allowExternalFiles = false, .warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 0u);
  ASSERT_EQ(model->vertexCount(), 3u);
  EXPECT_EQ(toDouble(model->positions[1]) + model->origin, (Vec3d{1, 0, 0}));
  EXPECT_TRUE(warnings.empty());
  doc["meshes"][0]["primitives"][0]["indices"] = 1;
  model = readGltfFromMemory(test::bytesOf(makeGlb(doc, triangleBinary())), "indexed.glb",
                             {.allowExternalFiles = false, .warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 0u);
  EXPECT_EQ(warnings, (std::vector<std::string>{
                          "indexed.glb: 1 point primitive (3 corners) not read: only unindexed, "
                          "uncompressed point primitives with positions are"}));
}

TEST(GltfRead, GpuInstancingExpandsIntoObjects) {
  json doc = triangleDocument();
  doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  doc["nodes"][0]["extensions"] = {
      {"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", 2}}}}}};
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 44}, {"byteLength", 36}});
  doc["accessors"].push_back(
      {{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  doc["buffers"][0]["byteLength"] = 80;
  const std::string binary =
      triangleBinary() + std::string(2, '\0') + raw<float>({0, 0, 0, 5, 0, 0, 0, 0, 5});
  Result<Model> model = readGlb(makeGlb(doc, binary));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 3u);
  EXPECT_EQ(model->objectName(2), "part#2");
  EXPECT_EQ(toDouble(model->objectPositions(2)[0]) + model->origin, (Vec3d{0, 0, 5}));
}

TEST(GltfRead, SeparateJsonWithExternalBufferBesideIt) {
  test::TempDir dir;
  json doc = triangleDocument();
  doc["buffers"][0]["uri"] = "triangle.bin";
  doc["buffers"][0]["byteLength"] = 42;  // no GLB padding in a plain file
  test::writeFile(dir.file("triangle.bin"), triangleBinary());
  test::writeFile(dir.file("triangle.gltf"), doc.dump(1));
  Result<Model> model = readGltf(dir.file("triangle.gltf"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 1u);
  // From memory, external files are refused (fuzzing must not read the disk).
  const std::string text = doc.dump();
  EXPECT_FALSE(
      readGltfFromMemory(test::bytesOf(text), "m.gltf", {.allowExternalFiles = false}).ok());
}

TEST(GltfRead, DracoCompressedPrimitivesAreDecoded) {
  // A 10 x 10 grid encoded by libdraco's own encoder into KHR_draco_mesh_compression.
  constexpr int n = 10;
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(2 * n * n);
  const int position =
      builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  int face = 0;
  std::vector<std::array<Vec3f, 3>> triangles;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Vec3f a{float(i), float(j), 0}, b{float(i + 1), float(j), 0},
          c{float(i + 1), float(j + 1), 1}, d{float(i), float(j + 1), 0};
      for (const auto& t : {std::array<Vec3f, 3>{a, b, c}, std::array<Vec3f, 3>{a, c, d}}) {
        builder.SetAttributeValuesForFace(position, draco::FaceIndex(face++), &t[0], &t[1], &t[2]);
        triangles.push_back(t);
      }
    }
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  ASSERT_TRUE(mesh);
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 16);
  draco::EncoderBuffer buffer;
  ASSERT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &buffer).ok());
  const std::string compressed(buffer.data(), buffer.size());
  const int uniqueId = int(mesh->attribute(position)->unique_id());

  json doc = triangleDocument();
  doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  doc["buffers"] = {{{"byteLength", compressed.size()}}};
  doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", compressed.size()}}};
  doc["accessors"] = {{{"componentType", 5126},
                       {"count", mesh->num_points()},
                       {"type", "VEC3"},
                       {"min", {0, 0, 0}},
                       {"max", {n, n, 1}}},
                      {{"componentType", 5125}, {"count", 6 * n * n}, {"type", "SCALAR"}}};
  doc["meshes"][0]["primitives"][0]["extensions"] = {
      {"KHR_draco_mesh_compression",
       {{"bufferView", 0}, {"attributes", {{"POSITION", uniqueId}}}}}};
  Result<Model> model = readGlb(makeGlb(doc, compressed));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->triangleCount(), triangles.size());
  // Draco may reorder; compare the triangles as a multiset of (rounded) corner triples.
  auto key = [](Vec3f a, Vec3f b, Vec3f c) {
    std::array<std::array<long, 3>, 3> corners;
    int k = 0;
    for (Vec3f p : {a, b, c})
      corners[std::size_t(k++)] = {std::lround(p.x * 1000), std::lround(p.y * 1000),
                                   std::lround(p.z * 1000)};
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    return corners;
  };
  std::multiset<std::array<std::array<long, 3>, 3>> expected, decoded;
  for (const auto& t : triangles) expected.insert(key(t[0], t[1], t[2]));
  for (std::size_t t = 0; t < model->triangleCount(); ++t) {
    const auto& p = model->positions;
    const auto& i = model->indices;
    decoded.insert(key(p[i[3 * t]], p[i[3 * t + 1]], p[i[3 * t + 2]]));
  }
  EXPECT_EQ(decoded, expected);
}

TEST(GltfBadInput, ErrorsSayWhereAndWhat) {
  struct Case {
    const char* name;
    std::string bytes;
    const char* expected;
  };
  json outOfRange = triangleDocument();
  outOfRange["accessors"][0]["count"] = 4;  // 48 bytes in a 36-byte view
  json badIndex = triangleDocument();
  std::string badIndexBinary = triangleBinary();
  badIndexBinary[36 + 4] = 9;  // third index = 9
  json cycle = triangleDocument();
  cycle["nodes"] = {{{"mesh", 0}, {"children", {1}}}, {{"children", {0}}}};
  json noPosition = triangleDocument();
  noPosition["meshes"][0]["primitives"][0]["attributes"] = json::object({{"NORMAL", 0}});
  json missingAccessor = triangleDocument();
  missingAccessor["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 7;
  json missingIndices = triangleDocument();
  missingIndices["meshes"][0]["primitives"][0]["indices"] = 7;
  json huge = triangleDocument();
  huge["accessors"][0] = {{"componentType", 5126},
                          {"count", 1'000'000'000'000ull},
                          {"type", "VEC3"},
                          {"sparse",
                           {{"count", 0},
                            {"indices", {{"bufferView", 1}, {"componentType", 5125}}},
                            {"values", {{"bufferView", 0}}}}}};
  std::string nanBinary = triangleBinary();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nanBinary.data() + 16, &nan, 4);
  std::string glb = makeGlb(triangleDocument(), triangleBinary());
  std::string badVersion = glb;
  badVersion[4] = 3;
  const Case cases[] = {
      {"not gltf", "hello", "byte 0: neither GLB (magic 'glTF') nor glTF JSON"},
      {"bad version", badVersion, "byte 4: GLB version 3 (expected 2)"},
      {"truncated", glb.substr(0, glb.size() - 8), "byte 8: GLB header says"},
      {"short header", glb.substr(0, 14), "GLB ends inside its 20-byte header"},
      {"accessor overrun", makeGlb(outOfRange, triangleBinary()),
       "mesh 0 primitive 0 POSITION (accessor 0): 4 elements of 12 bytes (stride 12) starting at "
       "byte 0 do not fit in "
       "bufferView 0 (36 bytes), file byte"},
      {"index out of range", makeGlb(badIndex, badIndexBinary),
       "index 9 out of range (3 vertices)"},
      {"cycle", makeGlb(cycle, triangleBinary()), "appears twice in the hierarchy"},
      {"no position", makeGlb(noPosition, triangleBinary()),
       "mesh 0 primitive 0: no POSITION attribute"},
      {"missing accessor", makeGlb(missingAccessor, triangleBinary()),
       "mesh 0 primitive 0 NORMAL: accessor 7 does not exist"},
      {"missing indices", makeGlb(missingIndices, triangleBinary()),
       "primitive indices accessor out of bounds"},
      {"huge count", makeGlb(huge, triangleBinary()),
       "1000000000000 elements without a bufferView"},
      {"nan", makeGlb(triangleDocument(), nanBinary), "POSITION 1 is not finite"},
      {"broken json", "{\"asset\": {\"version\": ", "test.glb"},
  };
  for (const Case& c : cases) {
    Result<Model> model = readGlb(c.bytes);
    ASSERT_FALSE(model.ok()) << c.name;
    EXPECT_EQ(model.error().kind, ErrorKind::kBadInput) << c.name;
    EXPECT_NE(model.error().message.find(c.expected), std::string::npos)
        << c.name << ": " << model.error().message;
    EXPECT_EQ(model.error().message.rfind("test.glb", 0), 0u) << model.error().message;
  }
}

}  // namespace
}  // namespace lodforge
