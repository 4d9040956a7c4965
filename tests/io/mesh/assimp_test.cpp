// The interchange formats through assimp: real files written by assimp's own exporters (Collada,
// FBX, 3DS) from a real assembly, and hand-written OFF, read back by readAssimp.
#include "lodforge/io/mesh/assimp_reader.h"

#include <cmath>

#include <assimp/material.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/model_io.h"
#include "test_support.h"

namespace lodforge {
namespace {

constexpr float kGlassAlpha = 0.12f;

// as1_motor.glb as assimp reads it, material `glass` made translucent (opacity 0.12), written
// by assimp's exporter for `format` ("collada", "fbx", "3ds").
void exportMotor(const std::string& format, const std::string& out, unsigned glass) {
  Assimp::Importer importer;
  const aiScene* read = importer.ReadFile(test::dataPath("meshes/as1_motor.glb"), 0);
  ASSERT_NE(read, nullptr) << importer.GetErrorString();
  ASSERT_LT(glass, read->mNumMaterials);
  aiMaterial* material = read->mMaterials[glass];
  const float opacity = kGlassAlpha;
  material->AddProperty(&opacity, 1, AI_MATKEY_OPACITY);
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(read, format, out), AI_SUCCESS) << exporter.GetErrorString();
}

struct Exported {
  const char* format;     // assimp's exporter id
  const char* extension;  // of the file written
  bool zUp;               // the format is z-up: assimp's exporter turns the scene a quarter
};
class AssimpFormats : public ::testing::TestWithParam<Exported> {};

// Every triangle of the assembly comes back, in the same place, with its node tree, and exactly
// the parts of the translucent material are BLEND (alpha in the vertex colours too).
TEST_P(AssimpFormats, TheMotorComesBackWithItsTreeAndItsGlass) {
  const auto [format, extension, zUp] = GetParam();
  Result<Model> original = readGltf(test::dataPath("meshes/as1_motor.glb"));
  ASSERT_TRUE(original.ok());
  test::TempDir dir;
  const std::string file = dir.file(std::string("motor.") + extension);
  const unsigned glass = 1;
  exportMotor(format, file, glass);
  ASSERT_EQ(formatFromPath(file), FileFormat::kAssimp);
  Result<Model> model = readModel(file);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(isConsistent(*model));
  EXPECT_EQ(model->triangleCount(), original->triangleCount());
  EXPECT_GE(model->objectCount(), original->objectCount());
  // The same place: the world boxes agree to a millionth of their size (turned a quarter about
  // x, y becoming -z, where the format is z-up).
  const Aabb a = original->bounds(), b = model->bounds();
  const double size = length(toDouble(a.max - a.min));
  const Vec3d min = original->origin + toDouble(a.min), max = original->origin + toDouble(a.max);
  const Vec3d expectedMin = zUp ? Vec3d{min.x, min.z, -max.y} : min;
  const Vec3d expectedMax = zUp ? Vec3d{max.x, max.z, -min.y} : max;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(expectedMin[k], model->origin[k] + b.min[k], 1e-6 * size) << k;
    EXPECT_NEAR(expectedMax[k], model->origin[k] + b.max[k], 1e-6 * size) << k;
  }
  // A tree: objects below named groups.
  std::size_t deep = 0;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const std::string_view path = model->objectPath(o);
    EXPECT_FALSE(path.empty()) << o;
    deep += path.find('/') != std::string_view::npos ? 1 : 0;
  }
  EXPECT_GT(deep, 0u);
  // The glass and nothing else is blended.
  std::size_t blended = 0;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const ObjectRecord& r = model->objects[o];
    ASSERT_NE(r.material, kNoMaterial) << o;
    const Material& m = model->materials[r.material];
    if (m.alphaMode != AlphaMode::kBlend) {
      EXPECT_EQ(m.baseColor[3], 1.0f) << m.name;
      continue;
    }
    ++blended;
    EXPECT_NEAR(m.baseColor[3], kGlassAlpha, 0.01) << m.name;
    EXPECT_TRUE(m.doubleSided);
    ASSERT_TRUE(model->hasColors());
    EXPECT_NEAR(model->colors[r.vertexOffset].a, 255 * kGlassAlpha, 3);
  }
  EXPECT_GT(blended, 0u);
  EXPECT_LT(blended, model->objectCount());
}

// assimp 5.2 cannot read back its own binary FBX; its ASCII FBX is what it round-trips.
INSTANTIATE_TEST_SUITE_P(Exported, AssimpFormats,
                         ::testing::Values(Exported{"collada", "dae", false},
                                           Exported{"fbxa", "fbx", false},
                                           Exported{"3ds", "3ds", true}));

// tests/data/ifc/house.ifc (hand-written IFC2X3): a wall styled opaque and a glass pane whose
// IfcSurfaceStyleRendering has transparency 0.88. The glass is BLEND at alpha 0.12, the wall
// opaque, both placed under the project's spatial tree.
TEST(AssimpRead, TheGlassOfAnIfcHouseIsBlended) {
  Result<Model> model = readModel(test::testDataPath("ifc/house.ifc"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->triangleCount(), 24u);  // two boxes
  int glass = -1, wall = -1;
  for (std::size_t o = 0; o < 2; ++o) {
    const std::string name(model->objectName(o));
    if (name.find("Glass") != std::string::npos) glass = static_cast<int>(o);
    if (name.find("Wall") != std::string::npos) wall = static_cast<int>(o);
    EXPECT_NE(model->objectPath(o).find('/'), std::string_view::npos) << model->objectPath(o);
  }
  ASSERT_GE(glass, 0);
  ASSERT_GE(wall, 0);
  const Material& pane = model->materials[model->objects[static_cast<std::size_t>(glass)].material];
  const Material& brick = model->materials[model->objects[static_cast<std::size_t>(wall)].material];
  EXPECT_EQ(pane.alphaMode, AlphaMode::kBlend);
  EXPECT_NEAR(pane.baseColor[3], 0.12, 1e-3);
  EXPECT_TRUE(pane.doubleSided);
  EXPECT_EQ(brick.alphaMode, AlphaMode::kOpaque);
  EXPECT_EQ(brick.baseColor[3], 1.0f);
  EXPECT_EQ(model->colors[model->objects[static_cast<std::size_t>(glass)].vertexOffset].a, 31);
}

TEST(AssimpRead, OffQuadsBecomeTriangles) {
  test::TempDir dir;
  test::writeFile(dir.file("cube.off"),
                  "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                  "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  Result<Model> model = readModel(dir.file("cube.off"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->objectCount(), 1u);
  EXPECT_EQ(model->triangleCount(), 12u);
  const Aabb box = model->bounds();
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(static_cast<float>(model->origin[k]) + box.min[k], 0.0f);
    EXPECT_FLOAT_EQ(static_cast<float>(model->origin[k]) + box.max[k], 1.0f);
  }
  EXPECT_TRUE(isConsistent(*model));
  // OFF has no colours: assimp's grey DefaultMaterial is no colour of the file's.
  EXPECT_TRUE(model->colors.empty());
  EXPECT_TRUE(model->materials.empty());
  EXPECT_EQ(model->objects[0].material, kNoMaterial);
}

TEST(AssimpRead, PointAndLineFacesAreReportedNotDroppedInSilence) {
  // An OFF square (two triangles) with a two-corner face (an edge) and a one-corner face.
  test::TempDir dir;
  test::writeFile(dir.file("edges.off"),
                  "OFF\n4 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n2 0 2\n1 3\n");
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warnings = &warnings;
  Result<Model> model = readModel(dir.file("edges.off"), options);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 2u);
  ASSERT_EQ(model->objectCount(), 1u);
  // Named as without the edges: the point and line meshes assimp sorts out are not numbered.
  EXPECT_EQ(model->objectName(0).find('#'), std::string_view::npos) << model->objectName(0);
  EXPECT_TRUE(model->colors.empty());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 point and line faces not read"), std::string::npos) << warnings[0];
}

// Files assimp cannot read are bad input naming the file; a scene without triangles too.
TEST(AssimpRead, BadFilesAreBadInputNamingTheFile) {
  test::TempDir dir;
  exportMotor("collada", dir.file("whole.dae"), 0);
  const std::string whole = test::readFile(dir.file("whole.dae"));
  test::writeFile(dir.file("cut.dae"), whole.substr(0, whole.size() / 2));
  test::writeFile(dir.file("garbage.fbx"), std::string(4096, '\x7f'));
  test::writeFile(dir.file("empty.off"), "OFF\n0 0 0\n");
  test::writeFile(dir.file("lines.off"), "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  for (const char* name : {"cut.dae", "garbage.fbx", "empty.off", "lines.off", "missing.3ds"}) {
    Result<Model> model = readModel(dir.file(name));
    ASSERT_FALSE(model.ok()) << name;
    EXPECT_EQ(model.error().message.rfind(dir.file(name), 0), 0u) << model.error().message;
    if (std::string(name) != "missing.3ds") {
      EXPECT_EQ(model.error().kind, ErrorKind::kBadInput) << model.error().message;
    }
  }
}

}  // namespace
}  // namespace lodforge
