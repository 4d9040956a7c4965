#include "lodforge/io/points/xyz_reader.h"

#include <cmath>

#include <gtest/gtest.h>

#include "lodforge/io/points/point_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

using test::bytesOf;

PointBatch readAll(const std::string& text, XyzLayout* layout = nullptr, std::size_t batch = 2) {
  Result<XyzReader> reader = XyzReader::fromMemory(bytesOf(text), "t.xyz", batch);
  EXPECT_TRUE(reader.ok()) << (reader.ok() ? "" : reader.error().message);
  PointBatch all, part;
  if (!reader.ok()) return all;
  if (layout) *layout = reader->layout();
  while (true) {
    Result<bool> more = reader->next(part);
    EXPECT_TRUE(more.ok()) << (more.ok() ? "" : more.error().message);
    if (!more.ok() || !*more) break;
    EXPECT_EQ(part.first, all.size());
    all.positions.insert(all.positions.end(), part.positions.begin(), part.positions.end());
    all.normals.insert(all.normals.end(), part.normals.begin(), part.normals.end());
    all.colors.insert(all.colors.end(), part.colors.begin(), part.colors.end());
  }
  return all;
}

TEST(XyzReader, DetectsSeparatorsAndColumns) {
  XyzLayout layout;
  // Spaces and tabs, three columns, comments and blank lines between.
  PointBatch p = readAll("# scan\n1 2 3\n\n4\t5  6\n// end\n7 8 9.5e1\n", &layout);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(layout.separator, ' ');
  EXPECT_DOUBLE_EQ(p.positions[2].z, 95);
  EXPECT_TRUE(p.colors.empty());
  EXPECT_TRUE(p.normals.empty());
  // CSV with colours 0-255.
  p = readAll("1.5,2,3,255,128,0\n4,5,6,10,20,30\n", &layout);
  EXPECT_EQ(layout.separator, ',');
  ASSERT_EQ(p.colors.size(), 2u);
  EXPECT_EQ(p.colors[0].g, 128);
  EXPECT_TRUE(p.normals.empty());
  // Six columns that are a normal.
  p = readAll("0;0;0;0;0;1\n1;0;0;1.2;1.6;0\n", &layout);
  EXPECT_EQ(layout.separator, ';');
  ASSERT_EQ(p.normals.size(), 2u);
  EXPECT_FLOAT_EQ(p.normals[0].z, 1);
  EXPECT_FLOAT_EQ(p.normals[1].y, 0.8f);  // normalised
  // PTS: a count line, then x y z intensity r g b.
  p = readAll("2\n1 2 3 -1200 10 20 30\n4 5 6 300 40 50 60\n", &layout);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p.colors[1].b, 60);
  // Nine columns: colour and normal.
  p = readAll("1 2 3 9 8 7 0 1 0\n", &layout);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.colors[0].r, 9);
  EXPECT_FLOAT_EQ(p.normals[0].y, 1);
}

TEST(XyzReader, MapsNamedColumnsAndUnitColours) {
  XyzLayout layout;
  const PointBatch p =
      readAll("//X,Y,Z,Red,Green,Blue,Nx,Ny,Nz,extra\n1,2,3,0.5,0.25,1.0,0,0,1,7\n", &layout);
  // CloudCompare's names line ("//X,...") maps the columns like a plain one.
  EXPECT_TRUE(layout.hasHeader);
  EXPECT_EQ(layout.columns, 10u);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.colors[0].g, 64);
  const PointBatch q =
      readAll("x,y,z,red,green,blue,nx,ny,nz,extra\n1,2,3,0.5,0.25,1.0,0,0,1,7\n", &layout);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_TRUE(layout.unitColors);
  EXPECT_EQ(q.colors[0].r, 128);
  EXPECT_EQ(q.colors[0].b, 255);
  EXPECT_FLOAT_EQ(q.normals[0].z, 1);
  // Columns in another order.
  const PointBatch r = readAll("z y x\n1 2 3\n", &layout);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_DOUBLE_EQ(r.positions[0].x, 3);
  EXPECT_DOUBLE_EQ(r.positions[0].z, 1);
}

// Through PointReader, in batches of the size asked for.
TEST(XyzReader, ReadsTheRealKitten) {
  Result<PointReader> reader =
      PointReader::open(test::dataPath("points/kitten.xyz"), {.batchPoints = 1'000});
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_TRUE(reader->info().hasNormals);
  EXPECT_FALSE(reader->info().hasColors);
  std::size_t count = 0, batches = 0;
  PointBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    ASSERT_TRUE(more.ok());
    if (!*more) break;
    count += batch.size();
    ++batches;
    EXPECT_LE(batch.size(), 1'000u);
    for (const Vec3f& n : batch.normals) EXPECT_NEAR(length(n), 1.0f, 1e-5f);
  }
  EXPECT_EQ(count, 5'210u);
  EXPECT_EQ(batches, 6u);
}

void expectBad(const std::string& text, std::string_view position, std::string_view fragment) {
  Result<XyzReader> reader = XyzReader::fromMemory(bytesOf(text), "bad.xyz");
  Status status = reader.status();
  PointBatch batch;
  while (status.ok()) {
    Result<bool> more = reader->next(batch);
    status = more.status();
    if (more.ok() && !*more) break;
  }
  ASSERT_FALSE(status.ok()) << "accepted: " << text;
  EXPECT_EQ(status.kind(), ErrorKind::kBadInput);
  EXPECT_NE(status.message().find(position), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(fragment), std::string::npos) << status.message();
}

TEST(XyzReader, RefusesBadLinesNamingTheLine) {
  expectBad("1 2 3\n4 5\n", "bad.xyz:2:", "2 values where the file has 3 columns");
  expectBad("1 2 3\n4 five 6\n", "bad.xyz:2:", "'five' is not a number");
  expectBad("1 2 3\n\n# c\n4 nan 6\n", "bad.xyz:4:", "not a finite number");
  expectBad("1 2 3\n4 5 inf\n", "bad.xyz:2:", "not a finite number");
  expectBad("1 2 3 4 5\n", "bad.xyz:1:", "5 columns");
  expectBad("a b c\nd e f\n", "bad.xyz:2:", "expected numbers");
  expectBad("u v w\n1 2 3\n", "bad.xyz:1:", "no x, y and z");
}

}  // namespace
}  // namespace lodforge
