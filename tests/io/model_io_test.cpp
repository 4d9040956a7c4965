#include "lodforge/io/model_io.h"

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

TEST(ModelIo, FormatComesFromTheExtension) {
  EXPECT_EQ(formatFromPath("a.PLY"), FileFormat::kPly);
  EXPECT_EQ(formatFromPath("dir.v2/part.glb"), FileFormat::kGlb);
  EXPECT_EQ(formatFromPath("x.gltf"), FileFormat::kGltf);
  EXPECT_EQ(formatFromPath("x.obj"), FileFormat::kObj);
  EXPECT_EQ(formatFromPath("x.stl"), FileFormat::kStl);
  EXPECT_EQ(formatFromPath("x.fbx"), FileFormat::kAssimp);
  EXPECT_EQ(formatFromPath("house.IFC"), FileFormat::kAssimp);
  EXPECT_EQ(formatFromPath("x.vtk"), FileFormat::kUnknown);
  EXPECT_FALSE(canWrite(FileFormat::kAssimp));
  EXPECT_FALSE(canWrite(FileFormat::kGltf));
  EXPECT_TRUE(canRead(FileFormat::kGltf));
}

TEST(ModelIo, UnknownFormatsAreUsageErrors) {
  Result<Model> model = readModel("model.vtk");
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().kind, ErrorKind::kUsage);
  EXPECT_EQ(exitCodeFor(model.status()), 2);
  EXPECT_EQ(writeModel(Model{}, "out.gltf").kind(), ErrorKind::kUsage);
}

TEST(ModelIo, EveryWritableFormatCarriesTheTrianglesThrough) {
  Result<Model> engine = readModel(test::dataPath("meshes/2CylinderEngine.glb"));
  ASSERT_TRUE(engine.ok());
  test::TempDir dir;
  for (const char* name : {"e.ply", "e.glb", "e.obj", "e.stl"}) {
    ASSERT_TRUE(writeModel(*engine, dir.file(name)).ok()) << name;
    Result<Model> back = readModel(dir.file(name));
    ASSERT_TRUE(back.ok()) << name << ": " << back.error().message;
    EXPECT_EQ(back->triangleCount(), engine->triangleCount()) << name;
    // Binary STL has no objects; the others keep them all.
    EXPECT_EQ(back->objectCount(), std::string(name) == "e.stl" ? 1u : engine->objectCount())
        << name;
    const Aabb a = engine->bounds(), b = back->bounds();
    EXPECT_NEAR(a.longestSide(), b.longestSide(), 1e-3) << name;
  }
}

}  // namespace
}  // namespace lodforge
