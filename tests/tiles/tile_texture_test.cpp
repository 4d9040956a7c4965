#include "lodforge/tiles/tile_texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/tiles/tileset.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kTexels = 256;
constexpr double kSide = 10;  // the plane's side; its texture spans it once

// A checker of 8-texel squares, each a colour of its own (none black).
Image squares() {
  Image image(kTexels, kTexels);
  for (std::uint32_t y = 0; y < kTexels; ++y)
    for (std::uint32_t x = 0; x < kTexels; ++x) {
      std::uint8_t* p = &image.rgba[4 * (std::size_t{y} * kTexels + x)];
      const std::uint32_t sx = x / 8, sy = y / 8;
      p[0] = static_cast<std::uint8_t>(40 + sx * 6);
      p[1] = static_cast<std::uint8_t>(40 + sy * 6);
      p[2] = (sx + sy) % 2 ? 230 : 60;
      p[3] = 255;
    }
  return image;
}

// A gently waved plane of n x n quads, UVs from x and y, one textured material (embedded PNG).
Model texturedPlane(int n) {
  Model model;
  ModelBuilder builder(model);
  builder.beginObject("plane");
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = kSide * i / n, y = kSide * j / n;
      model.positions.push_back({static_cast<float>(x), static_cast<float>(y),
                                 static_cast<float>(0.3 * std::sin(x) * std::cos(y))});
      model.uvs.push_back({static_cast<float>(x / kSide), static_cast<float>(y / kSide)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto at = [&](int a, int b) { return static_cast<std::uint32_t>(b * (n + 1) + a); };
      builder.addTriangle(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      builder.addTriangle(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  builder.endObject();
  Result<std::vector<std::byte>> png = encodeImage(squares(), {.format = ImageFormat::kPng});
  EXPECT_TRUE(png.ok());
  ImageSource image{.name = "checker.png", .bytes = *png};
  EXPECT_TRUE(probeImage(image).ok());
  model.images.push_back(std::move(image));
  Material material;
  material.name = "photo";
  material.baseColorImage = 0;
  model.materials.push_back(material);
  model.objects[0].material = 0;
  EXPECT_TRUE(isConsistent(model));
  return model;
}

const std::uint8_t* texelAt(const Image& image, double u, double v) {
  const auto x = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(u * image.width)), 0,
                                          image.width - 1);
  const auto y = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(v * image.height)),
                                          0, image.height - 1);
  return &image.rgba[4 * (static_cast<std::size_t>(y) * image.width + static_cast<std::size_t>(x))];
}

// Away from a texel's edge by a tenth of a texel: where nearest sampling cannot flip.
bool wellInside(double u, std::uint32_t size) {
  const double t = u * size - std::floor(u * size);
  return t > 0.1 && t < 0.9;
}

// Tiles `input` and checks every tile: points inside each triangle sample, in the tile's
// texture, the texel of the source's mip level for the tile's level.
void expectRebakedTexelForTexel(const std::string& input, const test::TempDir& dir) {
  TilesOptions options;
  options.input.chunkSize = 2.6;  // 4 x 4 leaves, two levels above them
  options.textureEncoding = {.format = ImageFormat::kPng};
  Result<TilesStats> stats = writeTiles(input, dir.file("tiles"), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  ASSERT_GE(stats->levels, 2);
  // The source's mip levels, as the pyramid makes them.
  std::vector<Image> levels{squares()};
  while (levels.size() < 6) levels.push_back(halveImage(levels.back()));
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0, 1);
  std::size_t tiles = 0, compared = 0;
  for (const auto& entry : fs::directory_iterator(dir.file("tiles/tiles"))) {
    const auto level = static_cast<std::size_t>(std::stoi(entry.path().filename().string()));
    Result<Model> tile = readGltf(entry.path().string());
    ASSERT_TRUE(tile.ok()) << tile.error().message;
    ASSERT_EQ(tile->images.size(), 1u) << entry.path();
    Result<Image> page = decodeImage(tile->images[0]);
    ASSERT_TRUE(page.ok());
    ASSERT_TRUE(tile->hasUvs());
    ++tiles;
    const Image& source = levels[level];
    for (std::size_t o = 0; o < tile->objectCount(); ++o) {
      const auto indices = tile->objectIndices(o);
      const std::uint64_t base = tile->objects[o].vertexOffset;
      for (std::size_t t = 0; t < indices.size(); t += 3) {
        double a = unit(random), b = unit(random);
        if (a + b > 1) a = 1 - a, b = 1 - b;
        const double w[3] = {1 - a - b, a, b};
        Vec3d p;
        double u = 0, v = 0;
        for (std::size_t k = 0; k < 3; ++k) {
          p = p + toDouble(tile->positions[base + indices[t + k]]) * w[k];
          u += tile->uvs[base + indices[t + k]].x * w[k];
          v += tile->uvs[base + indices[t + k]].y * w[k];
        }
        p = p + tile->origin;
        // glTF is y-up: the plane's (x, y) are the tile's (x, -z).
        const double su = p.x / kSide, sv = -p.z / kSide;
        if (!wellInside(su, source.width) || !wellInside(sv, source.height) ||
            !wellInside(u, page->width) || !wellInside(v, page->height))
          continue;
        ASSERT_EQ(0, std::memcmp(texelAt(*page, u, v), texelAt(source, su, sv), 3))
            << entry.path() << " level " << level << " at " << su << "," << sv;
        ++compared;
      }
    }
  }
  EXPECT_EQ(tiles, stats->tiles);
  EXPECT_GT(compared, 2000u);
}

TEST(TileTexture, EveryTileRebakesTheSourceTexelForTexelAtItsLevel) {
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(texturedPlane(64), dir.file("plane.glb")).ok());
  expectRebakedTexelForTexel(dir.file("plane.glb"), dir);
}

TEST(TileTexture, AStreamedPlyIsRebakedTheSameWay) {
  // The plane as MeshLab writes a textured PLY: corner coordinates per face, the texture beside.
  test::TempDir dir;
  const Model plane = texturedPlane(64);
  test::writeFile(dir.file("checker.png"),
                  std::string_view(reinterpret_cast<const char*>(plane.images[0].bytes.data()),
                                   plane.images[0].bytes.size()));
  PlyLayout layout{.vertexCount = plane.vertexCount(),
                   .faceCount = plane.triangleCount(),
                   .faceUvs = true,
                   .comments = {"TextureFile checker.png"}};
  Result<PlyWriter> writer = PlyWriter::create(dir.file("plane.ply"), layout);
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->writeVertices(plane.positions, {}, {}).ok());
  std::vector<Vec2f> corners;
  for (std::uint32_t v : plane.indices) corners.push_back(plane.uvs[v]);
  const std::vector<std::uint32_t> textures(plane.triangleCount(), 0);
  ASSERT_TRUE(writer->writeTriangles(plane.indices, {}, corners, textures).ok());
  ASSERT_TRUE(writer->finish().ok());
  expectRebakedTexelForTexel(dir.file("plane.ply"), dir);
}

// Two quads of one streamed PLY sharing an edge (vertex coordinates per vertex), one red and
// one blue texture: every tile's pages keep each face's own texture.
TEST(TileTexture, AStreamedVertexSharedByTwoTexturesKeepsEach) {
  test::TempDir dir;
  for (const auto& [name, rgb] :
       {std::pair{"red.png", std::array<std::uint8_t, 3>{220, 20, 20}},
        std::pair{"blue.png", std::array<std::uint8_t, 3>{20, 20, 220}}}) {
    Image image(8, 8);
    for (std::size_t i = 0; i < image.pixelCount(); ++i) {
      std::copy(rgb.begin(), rgb.end(), &image.rgba[4 * i]);
      image.rgba[4 * i + 3] = 255;
    }
    Result<std::vector<std::byte>> png = encodeImage(image, {.format = ImageFormat::kPng});
    ASSERT_TRUE(png.ok());
    test::writeFile(dir.file(name),
                    std::string_view(reinterpret_cast<const char*>(png->data()), png->size()));
  }
  const std::string header =
      "ply\nformat ascii 1.0\ncomment TextureFile red.png\ncomment TextureFile blue.png\n"
      "element vertex 6\nproperty float x\nproperty float y\nproperty float z\nproperty float s\n"
      "property float t\nelement face 4\nproperty list uchar int vertex_indices\n"
      "property int texnumber\nend_header\n"
      "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n2 0 0 0 0\n2 1 0 0 1\n";
  test::writeFile(dir.file("two.ply"), header + "3 0 1 2 0\n3 0 2 3 0\n3 1 4 5 1\n3 1 5 2 1\n");
  Result<TilesStats> stats = writeTiles(dir.file("two.ply"), dir.file("tiles"), {});
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  Result<Model> tile = readGltf(dir.file("tiles/tiles/0-0-0-0.glb"));
  ASSERT_TRUE(tile.ok());
  ASSERT_EQ(tile->images.size(), 2u);  // red and blue, each with its faces
  std::size_t red = 0, blue = 0;
  for (const ImageSource& image : tile->images) {
    Result<Image> texels = decodeImage(image);
    ASSERT_TRUE(texels.ok());
    (texels->rgba[0] > texels->rgba[2] ? red : blue) += 1;
  }
  EXPECT_EQ(red, 1u);
  EXPECT_EQ(blue, 1u);
  // A texnumber past the TextureFile lines is refused streamed as it is read whole.
  test::writeFile(dir.file("stray.ply"), header + "3 0 1 2 0\n3 0 2 3 0\n3 1 4 5 2\n3 1 5 2 1\n");
  Result<TilesStats> stray = writeTiles(dir.file("stray.ply"), dir.file("stray"), {});
  ASSERT_FALSE(stray.ok());
  EXPECT_NE(stray.error().message.find("texnumber 2 but the file names 2 textures"),
            std::string::npos)
      << stray.error().message;
}

TEST(TileTexture, PagesOfASourceWithAlphaArePng) {
  TextureTable table;
  table.images.push_back(ImageSource{
      .name = "a", .format = ImageFormat::kPng, .width = 4, .height = 4, .channels = 4});
  table.images.push_back(ImageSource{
      .name = "b", .format = ImageFormat::kJpeg, .width = 4, .height = 4, .channels = 3});
  table.materials.resize(2);
  table.materials[0].baseColorImage = 0;
  table.materials[1].baseColorImage = 1;
  TileTexturing texturing;
  texturing.table = &table;
  AtlasPage page;
  page.material = 0;
  EXPECT_EQ(pageEncoding(texturing, page).format, ImageFormat::kPng);
  page.material = 1;
  EXPECT_EQ(pageEncoding(texturing, page).format, ImageFormat::kJpeg);
  texturing.encode.format = ImageFormat::kWebp;  // WebP keeps alpha itself
  page.material = 0;
  EXPECT_EQ(pageEncoding(texturing, page).format, ImageFormat::kWebp);
}

}  // namespace
}  // namespace lodforge
