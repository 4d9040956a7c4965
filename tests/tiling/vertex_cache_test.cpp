#include "lodforge/tiling/vertex_cache.h"

#include <fcntl.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

struct Written {
  Vec3d position;
  Rgba8 color;
  Vec3f normal;
  Vec2f uv;
};

// Records in `layout` to a work file, read back through a cache smaller than the file (so
// blocks are evicted and read again), with one normal accumulated on the way.
void roundTrip(const VertexLayout& layout, const std::vector<Written>& vertices) {
  test::TempDir dir;
  const std::string path = dir.file("vertices.bin");
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  std::vector<std::byte> bytes(vertices.size() * layout.bytes());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Written& v = vertices[i];
    writeVertexRecord(bytes.data() + i * layout.bytes(), layout, v.position, v.color, v.normal,
                      v.uv);
  }
  ASSERT_EQ(::write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  VertexCache cache(fd, vertices.size(), 4 * (std::uint64_t{1} << 14) * layout.bytes(), layout);
  ASSERT_TRUE(cache.addNormal(7, {0, 0, 2}));
  for (std::size_t i = 0; i < vertices.size(); i += 997) {
    CutCorner c;
    ASSERT_TRUE(cache.fetch(i, c));
    const Written& v = vertices[i];
    EXPECT_EQ(c.position, v.position) << i;
    EXPECT_EQ(c.color.r, v.color.r);
    EXPECT_EQ(c.color.a, v.color.a);
    EXPECT_NEAR(c.normal.z, v.normal.z, 1e-6f) << i;
    if (layout.uvs) {
      EXPECT_EQ(c.uv.x, v.uv.x);
      EXPECT_EQ(c.uv.y, v.uv.y);
    }
    EXPECT_EQ(c.source, i);
  }
  CutCorner past;
  EXPECT_FALSE(cache.fetch(vertices.size(), past));
  ASSERT_TRUE(cache.flush());
  // The sum reached the file: a fresh cache reads it back.
  VertexCache again(fd, vertices.size(), 4 * (std::uint64_t{1} << 14) * layout.bytes(), layout);
  CutCorner seven;
  ASSERT_TRUE(again.fetch(7, seven));
  const Vec3f expected = normalizeOr(vertices[7].normal + Vec3f{0, 0, 2}, {});
  EXPECT_NEAR(seven.normal.x, expected.x, 1e-6f);
  EXPECT_NEAR(seven.normal.z, expected.z, 1e-6f);
  EXPECT_EQ(seven.position, vertices[7].position);
  ::close(fd);
}

std::vector<Written> someVertices(bool floatExact) {
  std::vector<Written> out;
  for (std::uint32_t i = 0; i < 300'000; ++i) {
    const double x = floatExact ? static_cast<double>(static_cast<float>(i * 0.37))
                                : 6'400'000.0 + i * 0.001;  // needs a double
    out.push_back({{x, -0.5 * i, 1.0 / 3.0 * (floatExact ? 0.0 : 1.0)},
                   {static_cast<std::uint8_t>(i), 2, 3, 255},
                   normalizeOr(Vec3f{1, static_cast<float>(i % 5), 1}, {}),
                   {0.25f * static_cast<float>(i % 4), 0.5f}});
  }
  return out;
}

// Float positions (a float PLY) take 28 bytes a vertex instead of 40 and come back exactly.
TEST(VertexCache, FloatAndDoubleRecordsComeBackExactly) {
  EXPECT_EQ((VertexLayout{.floatPositions = true}.bytes()), 28u);
  EXPECT_EQ(VertexLayout{}.bytes(), 40u);
  EXPECT_EQ((VertexLayout{.floatPositions = true, .uvs = true}.bytes()), 36u);
  roundTrip({.floatPositions = true}, someVertices(true));
  roundTrip({.floatPositions = true, .uvs = true}, someVertices(true));
  roundTrip({}, someVertices(false));
  roundTrip({.uvs = true}, someVertices(false));
}

}  // namespace
}  // namespace lodforge
