#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "lodforge/io/mesh/obj_writer.h"
#include "test_support.h"

namespace lodforge {
namespace {

Result<Model> readObjText(const std::string& text) {
  return readObjFromMemory(test::bytesOf(text), "test.obj");
}

TEST(ObjRead, BunnyHasItsTrianglesAsOneObject) {
  Result<Model> bunny = readObj(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(bunny.ok()) << bunny.error().message;
  EXPECT_EQ(bunny->objectCount(), 1u);
  EXPECT_EQ(bunny->triangleCount(), 69'451u);
  // The file lists 35,947 vertices; only the 34,834 that faces use are kept.
  EXPECT_EQ(bunny->vertexCount(), 34'834u);
  EXPECT_TRUE(isConsistent(*bunny));
}

TEST(ObjRead, ObjectsAndGroupsBecomeObjects) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
      "o first\nf 1 2 3\nf 1 3 4\n"
      "g second\nf 1 2 5\n"
      "o third\nf -5 -4 -1\n";  // relative indices
  Result<Model> model = readObjText(text);
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 3u);
  EXPECT_EQ(model->objectName(0), "first");
  EXPECT_EQ(model->objectName(1), "second");
  EXPECT_EQ(model->objectName(2), "third");
  EXPECT_EQ(model->objects[0].triangleCount, 2u);
  EXPECT_EQ(model->objects[0].vertexCount, 4u);
  EXPECT_EQ(model->objects[2].vertexCount, 3u);
  const auto third = model->objectPositions(2);
  EXPECT_EQ(third[model->objectIndices(2)[2]], (Vec3f{0, 0, 1}));
}

TEST(ObjRead, PolygonsAreFanTriangulatedKeepingWinding) {
  Result<Model> model = readObjText("v 0 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4 5\n");
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 3u);
  for (std::size_t t = 0; t < 3; ++t) {
    const auto& p = model->positions;
    const auto& i = model->indices;
    EXPECT_GT(cross(p[i[3 * t + 1]] - p[i[3 * t]], p[i[3 * t + 2]] - p[i[3 * t]]).z, 0.0f);
  }
}

TEST(ObjRead, NormalsColoursAndAttributeSplits) {
  // Two faces share vertex 2 but give it different normals: it is split.
  const std::string text =
      "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 1 1 0 1 1 1\n"
      "vn 0 0 1\nvn 0 0 -1\n"
      "f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n";
  Result<Model> model = readObjText(text);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 6u);
  ASSERT_TRUE(model->hasNormals());
  ASSERT_TRUE(model->hasColors());
  EXPECT_EQ(model->normals[0], (Vec3f{0, 0, 1}));
  EXPECT_EQ(model->normals[3], (Vec3f{0, 0, -1}));
  EXPECT_EQ(model->colors[0], (Rgba8{255, 0, 0, 255}));
  EXPECT_EQ(model->colors[1], (Rgba8{0, 255, 0, 255}));
}

TEST(ObjRead, MissingNormalsInAnObjectAreComputed) {
  Result<Model> model = readObjText("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nf 1//1 2 3\n");
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_TRUE(model->hasNormals());
  for (const Vec3f& n : model->normals) EXPECT_EQ(n, (Vec3f{0, 0, 1}));
}

TEST(ObjRead, MaterialDiffuseColourBecomesVertexColour) {
  test::TempDir dir;
  test::writeFile(dir.file("parts.mtl"), "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  test::writeFile(dir.file("parts.obj"),
                  "mtllib parts.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                  "usemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\n");
  Result<Model> model = readObj(dir.file("parts.obj"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_TRUE(model->hasColors());
  EXPECT_EQ(model->vertexCount(), 6u);  // vertices 2 and 3 appear in both colours
  const auto& i = model->indices;
  EXPECT_EQ(model->colors[i[0]], (Rgba8{255, 0, 0, 255}));
  EXPECT_EQ(model->colors[i[3]], (Rgba8{0, 0, 255, 255}));
}

TEST(ObjRead, LinesAndPointsBesideFacesAreReportedNotDroppedInSilence) {
  // An edges-only group between face groups (tinyobjloader drops such a group at the next `g`)
  // and a line before a material change (it re-adds that one at each later change): each
  // element is counted once, from the text.
  test::TempDir dir;
  test::writeFile(dir.file("edges.obj"),
                  "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                  "g faces\nf 1 2 3\n"
                  "g edges\nl 1 2 3\nl 3 4\n"
                  "g more\nl 1 4\nusemtl a\nf 1 3 4\nusemtl b\nf 2 3 4\np 2\n");
  std::vector<std::string> warnings;
  Result<Model> model = readObj(dir.file("edges.obj"), &warnings);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->triangleCount(), 3u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(": 3 line elements (7 vertices) and 1 point not read"),
            std::string::npos)
      << warnings[0];
  // Faces alone: no warning.
  test::writeFile(dir.file("plain.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  warnings.clear();
  ASSERT_TRUE(readObj(dir.file("plain.obj"), &warnings).ok());
  EXPECT_TRUE(warnings.empty());
}

TEST(ObjRoundTrip, WriterOutputReadsBack) {
  Result<Model> bunny = readObj(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(bunny.ok());
  Model model = std::move(bunny.value());
  model.normals.resize(model.vertexCount());
  computeVertexNormals(model.positions, model.indices, model.normals);
  model.colors.assign(model.vertexCount(), Rgba8{10, 200, 30, 255});
  test::TempDir dir;
  ASSERT_TRUE(writeObj(model, dir.file("bunny.obj")).ok());
  Result<Model> back = readObj(dir.file("bunny.obj"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->triangleCount(), model.triangleCount());
  EXPECT_EQ(back->vertexCount(), model.vertexCount());
  EXPECT_EQ(back->positions, model.positions);  // shortest round-trip text: exact
  EXPECT_EQ(back->indices, model.indices);
  EXPECT_EQ(back->colors, model.colors);
  for (std::size_t v = 0; v < model.vertexCount(); ++v)
    ASSERT_EQ(back->normals[v], model.normals[v]);
}

TEST(ObjRead, VerticesWithoutFacesAreOneObjectOfAllOfThem) {
  // As a PLY without faces reads: one object named after the file, no triangles.
  Result<Model> model = readObjText("# points\nv 0 0 0\nv 1.5 2 3\nv -1 0 4\n");
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 3u);
  EXPECT_EQ(model->triangleCount(), 0u);
  ASSERT_EQ(model->objectCount(), 1u);
  EXPECT_EQ(model->objectName(0), "test");
  EXPECT_EQ(model->objects[0].vertexCount, 3u);
  EXPECT_EQ(model->positions[1], (Vec3f{1.5f, 2, 3}));
  EXPECT_FALSE(model->hasColors());
  EXPECT_TRUE(isConsistent(*model));
  // Vertex colours are kept.
  Result<Model> colored = readObjText("v 0 0 0 1 0 0\nv 1 0 0 0 0 1\n");
  ASSERT_TRUE(colored.ok()) << colored.error().message;
  ASSERT_TRUE(colored->hasColors());
  EXPECT_EQ(colored->colors[1], (Rgba8{0, 0, 255, 255}));
  // Far from the origin: positions are kept relative to the model's origin.
  Result<Model> far = readObjText("v 500000 4000000 10\nv 500001 4000000 10\n");
  ASSERT_TRUE(far.ok()) << far.error().message;
  EXPECT_EQ(far->origin + toDouble(far->positions[1]), (Vec3d{500001, 4000000, 10}));
  // An empty file has no objects.
  Result<Model> empty = readObjText("# nothing\n");
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->objectCount(), 0u);
}

TEST(ObjBadInput, AVertexFileCutAnywhereReadsItsWholeLinesOrNamesTheCutLine) {
  const std::string text = "v 1.25 -2.5 3\nv 4 5 6\nv 1.5 2.0 7.75\nv 8 9 10\n";
  for (std::size_t size = 0; size <= text.size(); ++size) {
    const std::string cut = text.substr(0, size);
    // Lines with three numbers so far: a cut inside a number still leaves a number.
    std::uint64_t lines = 0, complete = 0;
    for (std::size_t start = 0; start < cut.size(); ++lines) {
      std::size_t end = cut.find('\n', start);
      if (end == std::string::npos) end = cut.size();
      const std::string_view line = std::string_view(cut).substr(start, end - start);
      std::size_t words = 0;
      for (std::size_t i = 0; i < line.size(); ++i)
        words += line[i] != ' ' && (i == 0 || line[i - 1] == ' ');
      complete += words == 4;
      start = end + 1;
    }
    Result<Model> model = readObjText(cut);
    if (lines > complete) {  // the last line lacks a coordinate
      ASSERT_FALSE(model.ok()) << "cut at " << size;
      EXPECT_EQ(model.error().kind, ErrorKind::kBadInput);
      EXPECT_NE(model.error().message.find(fmt::format("test.obj:{}: ", lines)), std::string::npos)
          << "cut at " << size << ": " << model.error().message;
    } else {
      ASSERT_TRUE(model.ok()) << "cut at " << size << ": " << model.error().message;
      EXPECT_EQ(model->vertexCount(), complete) << "cut at " << size;
    }
  }
}

TEST(ObjBadInput, ErrorsNameTheLine) {
  struct Case {
    const char* text;
    const char* expected;
  };
  for (const Case& c :
       {Case{"v 0 0 0\nv nan 1 2\nv 0 1 0\nf 1 2 3\n",
             "test.obj:2: expected a finite number, found 'nan'"},
        Case{"v 0 0 0\nv 1e999 1 2\n", "test.obj:2: expected a finite number, found '1e999'"},
        Case{"v 0 0 0\nv one 1 2\n", "test.obj:2: expected a finite number, found 'one'"},
        Case{"v 0 0\n", "test.obj:1: 'v' needs three coordinates"},
        Case{"v 0 0 0\nv 1.5 2.0", "test.obj:2: 'v' needs three coordinates"},
        Case{"v 0 0 0\nv 1.5 2.0 -", "test.obj:2: expected a finite number, found '-'"},
        Case{"v 0 0 0\nv 1.5 2.0 1e", "test.obj:2: expected a finite number, found '1e'"},
        Case{"vn 0 0 inf\n", "test.obj:1: expected a finite number"},
        Case{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# c\nf 1 2 9\n",
             "test.obj:6: face refers to vertex 9 but the file has 3 vertices"},
        Case{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//4 2//4 3//4\n",
             "test.obj:4: face refers to normal 4"},
        Case{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -7\n", "test.obj:4: face refers to vertex -3"},
        Case{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4"}}) {
    Result<Model> model = readObjText(c.text);
    ASSERT_FALSE(model.ok()) << c.text;
    EXPECT_EQ(model.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(model.error().message.find(c.expected), std::string::npos) << model.error().message;
  }
}

}  // namespace
}  // namespace lodforge
