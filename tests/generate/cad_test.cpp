#include "lodforge/generate/cad.h"

#include <algorithm>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/mesh.h"
#include "lodforge/io/cad/cad_reader.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(Cad, GlbAndPlyHoldTheSameAssembly) {
  test::TempDir dir;
  Result<GenerateStats> glb = generateCad({.objects = 800, .seed = 4}, dir.file("a.glb"));
  Result<GenerateStats> ply = generateCad({.objects = 800, .seed = 4}, dir.file("a.ply"));
  ASSERT_TRUE(glb.ok()) << glb.error().message;
  ASSERT_TRUE(ply.ok()) << ply.error().message;
  EXPECT_EQ(glb->triangles, ply->triangles);
  EXPECT_EQ(glb->vertices, ply->vertices);
  Result<Model> fromGlb = readGltf(dir.file("a.glb"));
  Result<Model> fromPly = readPly(dir.file("a.ply"));
  ASSERT_TRUE(fromGlb.ok()) << fromGlb.error().message;
  ASSERT_TRUE(fromPly.ok()) << fromPly.error().message;
  ASSERT_EQ(fromGlb->objectCount(), 800u);
  ASSERT_EQ(fromPly->objectCount(), 800u);  // every object id 0..799 present
  EXPECT_EQ(fromGlb->triangleCount(), glb->triangles);
  for (std::size_t o = 0; o < 800; ++o) {
    ASSERT_EQ(fromGlb->objects[o].triangleCount, fromPly->objects[o].triangleCount) << o;
    const Aabb a = fromGlb->objects[o].bounds, b = fromPly->objects[o].bounds;
    ASSERT_NEAR(a.min.x, b.min.x, 1e-3f) << o;
    ASSERT_NEAR(a.max.z, b.max.z, 1e-3f) << o;
  }
}

// The STEP assembly (B-rep through OpenCASCADE) is the GLB's: the same parts in the same order,
// each where the GLB has it (boxes agree to the chord error of the GLB's tessellation), the
// catalogue bolts shared shapes.
TEST(Cad, StepHoldsTheGlbsAssemblyAsBrep) {
  test::TempDir dir;
  const CadOptions options{.objects = 120, .seed = 9};
  ASSERT_TRUE(generateCad(options, dir.file("a.glb")).ok());
  Result<GenerateStats> step = generateCad(options, dir.file("a.step"));
  ASSERT_TRUE(step.ok()) << step.error().message;
  EXPECT_EQ(step->objects, 120u);
  EXPECT_EQ(test::listFolder(dir.path()), (std::vector<std::string>{"a.glb", "a.step"}));
  Result<Model> mesh = readGltf(dir.file("a.glb"));
  CadReadStats stats;
  Result<Model> brep = readCad(dir.file("a.step"), {}, nullptr, &stats);
  ASSERT_TRUE(mesh.ok());
  ASSERT_TRUE(brep.ok()) << brep.error().message;
  ASSERT_EQ(brep->objectCount(), mesh->objectCount());
  EXPECT_LT(stats.shapes, stats.instances);  // bolts placed more than once
  EXPECT_EQ(stats.depth, 3u);                // root, sub-assemblies of 100 parts, parts
  // Every part on its kind's layer.
  const std::map<std::string, std::string> layerOfKind = {
      {"bolt", "fasteners"},    {"tube", "tubing"},    {"box", "housings"}, {"bracket", "brackets"},
      {"plate", "sheet metal"}, {"beam", "structure"}, {"rod", "rods"}};
  std::size_t bolts = 0;
  for (std::size_t o = 0; o < mesh->objectCount(); ++o) {
    const std::string name(mesh->objectName(o));
    EXPECT_EQ(brep->objectLayer(o), layerOfKind.at(name.substr(0, name.find('_')))) << name;
    const std::string_view path = brep->objectPath(o);
    EXPECT_NE(path.find(fmt::format("/group {:05}/", o / 100)), std::string_view::npos) << path;
    if (name.rfind("bolt_", 0) == 0) {
      EXPECT_EQ(brep->objectName(o).rfind("bolt M", 0), 0u) << brep->objectName(o);
      ++bolts;
    } else {
      EXPECT_EQ(brep->objectName(o), name);
    }
    const Aabb a = mesh->objects[o].bounds, b = brep->objects[o].bounds;
    const double size = length(toDouble(a.max - a.min));
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(mesh->origin[k] + a.min[k], brep->origin[k] + b.min[k], 0.03 * size) << name;
      EXPECT_NEAR(mesh->origin[k] + a.max[k], brep->origin[k] + b.max[k], 0.03 * size) << name;
    }
  }
  EXPECT_GT(bolts, 0u);
}

TEST(Cad, PartsVaryWidelyInKindSizeAndTessellation) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 3000, .seed = 1}, dir.file("a.glb")).ok());
  Result<Model> model = readGltf(dir.file("a.glb"));
  ASSERT_TRUE(model.ok());
  std::map<std::string, int> kinds;
  std::uint32_t fewest = ~0u, most = 0;
  float smallest = 1e9f, largest = 0;
  std::uint64_t openParts = 0;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const std::string name(model->objectName(o));
    kinds[name.substr(0, name.find('_'))]++;
    fewest = std::min(fewest, model->objects[o].triangleCount);
    most = std::max(most, model->objects[o].triangleCount);
    smallest = std::min(smallest, model->objects[o].bounds.longestSide());
    largest = std::max(largest, model->objects[o].bounds.longestSide());
    if (name.starts_with("plate") && countBoundaryEdges(model->objectIndices(o)) > 0) ++openParts;
  }
  EXPECT_EQ(kinds.size(), 7u);
  for (const auto& [kind, count] : kinds) EXPECT_GT(count, 100) << kind;
  EXPECT_GT(most, 100 * fewest);                        // tessellation over two orders of magnitude
  EXPECT_GT(largest, 500 * smallest);                   // sizes from millimetres to metres
  EXPECT_EQ(openParts, std::uint64_t(kinds["plate"]));  // plates with holes are open sheets
  // The assembly spans a fuselage and wings.
  const Aabb box = model->bounds();
  EXPECT_GT(box.size().x, 60.0f);
  EXPECT_GT(box.size().y, 50.0f);
}

TEST(Cad, StandardBoltsAreInstancedInGlb) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 2000, .seed = 2}, dir.file("a.glb")).ok());
  const std::string bytes = test::readFile(dir.file("a.glb"));
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  const auto document = nlohmann::json::parse(bytes.substr(20, jsonLength));
  const std::size_t nodes = document["nodes"].size() - 1;  // minus the root
  EXPECT_EQ(nodes, 2000u);
  EXPECT_LT(document["meshes"].size(), nodes - 400);  // ~30% bolts share 24 catalogue meshes
  std::set<int> used;
  for (const auto& node : document["nodes"]) {
    if (node.contains("mesh")) used.insert(node["mesh"].get<int>());
  }
  EXPECT_EQ(used.size(), document["meshes"].size());
}

TEST(Cad, DeterministicAndSeedDependent) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 7}, dir.file("a.ply")).ok());
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 7}, dir.file("b.ply")).ok());
  ASSERT_TRUE(generateCad({.objects = 300, .seed = 8}, dir.file("c.ply")).ok());
  EXPECT_EQ(test::readFile(dir.file("a.ply")), test::readFile(dir.file("b.ply")));
  EXPECT_NE(test::readFile(dir.file("a.ply")), test::readFile(dir.file("c.ply")));
}

TEST(Cad, DetailScalesTessellation) {
  test::TempDir dir;
  Result<GenerateStats> coarse =
      generateCad({.objects = 500, .seed = 3, .detail = 0.5}, dir.file("c.ply"));
  Result<GenerateStats> fine =
      generateCad({.objects = 500, .seed = 3, .detail = 2.0}, dir.file("f.ply"));
  ASSERT_TRUE(coarse.ok() && fine.ok());
  EXPECT_GT(fine->triangles, 2 * coarse->triangles);
}

}  // namespace
}  // namespace lodforge
