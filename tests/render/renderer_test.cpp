// Headless renders on Mesa's llvmpipe (EGL surfaceless): what the renderer draws is checked by
// tolerant measures, not golden pixels.
#include "lodforge/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "lodforge/generate/scan.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "render/headless.h"
#include "runtime/packages.h"

namespace lodforge {
namespace {

// Share of pixels that differ from the background colour.
double coverage(const Image& image) {
  const auto background = DrawOptions{}.background;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    const std::uint8_t* p = &image.rgba[4 * i];
    covered += (p[0] != background[0] || p[1] != background[1] || p[2] != background[2]) ? 1u : 0u;
  }
  return static_cast<double>(covered) / static_cast<double>(image.pixelCount());
}

// Renders the stream buffer's contents as the camera sees them.
Image render(const Package& package, const StreamBuffer& buffer, const Camera& camera,
             ColorMode mode = ColorMode::kShaded) {
  auto renderer = Renderer::create(package, buffer.capacity());
  EXPECT_TRUE(renderer.ok()) << renderer.error().message;
  auto target = Framebuffer::create(camera.width, camera.height);
  EXPECT_TRUE(target.ok()) << target.error().message;
  renderer->upload(buffer);
  target->bind();
  renderer->draw(camera, {.colorMode = mode});
  return target->read();
}

TEST(Context, HeadlessOpenGl45) {
  GlContext& gl = test::headlessContext();
  EXPECT_FALSE(gl.renderer().empty());
  EXPECT_NE(gl.version().find("4."), std::string::npos) << gl.version();
  EXPECT_EQ(gl.glfwWindow(), nullptr);
  EXPECT_EQ(gl.platform(), "EGL surfaceless");  // Mesa's, tried first
}

// The device platform is how NVIDIA's driver opens headless; Mesa offers it too (its software
// device), so the path runs here. The shared context is made current again afterwards.
TEST(Context, TheDevicePlatformAlsoGivesOpenGl45) {
  GlContext& shared = test::headlessContext();
  {
    auto device = GlContext::headless(EglPlatform::kDevice);
    ASSERT_TRUE(device.ok()) << device.error().message;
    EXPECT_FALSE((*device)->renderer().empty());
    EXPECT_NE((*device)->version().find("4."), std::string::npos) << (*device)->version();
    EXPECT_EQ((*device)->platform(), "EGL device");
  }
  shared.makeCurrent();
  EXPECT_FALSE(shared.renderer().empty());
}

TEST(Renderer, ASquareCoversTheShareItsProjectionPredicts) {
  test::headlessContext();
  test::TempDir folder;
  // One square of side 2 in the z = 0 plane, seen straight down from height 4.
  const std::string ply = folder.file("square.ply");
  test::writeFile(ply,
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                  "end_header\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n");
  ASSERT_TRUE(buildPackage(ply, folder.file("square.lfp")).ok());
  auto package = Package::open(folder.file("square.lfp"));
  ASSERT_TRUE(package.ok());
  StreamBuffer buffer(*package, StreamCapacity::forVertices(*package, 4));
  const std::uint32_t vc[] = {4}, tc[] = {2};
  ASSERT_TRUE(buffer.update(vc, tc).ok());
  const Vec3d origin = package->origin();
  for (const auto& [width, height] : {std::pair{200u, 100u}, std::pair{320u, 240u}}) {
    const Camera camera = Camera::lookAt(Vec3d{0, 0, 4} - origin, Vec3d{0, 0, 0} - origin,
                                         {0, 1, 0}, 60, width, height);
    const Image image = render(*package, buffer, camera);
    // Half-extents of the image plane at depth 4 are 4 tan(30°) (vertical) and that times the
    // aspect (horizontal); the square's half-extent is 1.
    const double fy = 1 / (4 * std::tan(3.14159265358979 / 6));
    const double fx = fy / camera.aspect();
    const double expected = fx * fy;
    // Rasterisation may differ by one pixel row or column along each edge.
    const double edge = (2 * fx * width + 2 * fy * height) / (static_cast<double>(width) * height);
    EXPECT_NEAR(coverage(image), expected, edge) << width << "x" << height;
    // Centre covered, corners not.
    // A structured binding is captured by copy (clang 14 captures none by reference).
    const auto at = [&image, w = width](std::uint32_t x, std::uint32_t y) {
      return &image.rgba[4 * (y * w + x)];
    };
    const auto background = DrawOptions{}.background;
    EXPECT_NE(at(width / 2, height / 2)[0], background[0]);
    EXPECT_EQ(at(0, 0)[0], background[0]);
    EXPECT_EQ(at(width - 1, height - 1)[0], background[0]);
  }
}

TEST(Renderer, FullBudgetAfterCoherentFramesEqualsTheReferenceRender) {
  test::headlessContext();
  for (const char* key : {"engine", "cad"}) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    const std::uint64_t full = scene.totalMaxVertices();
    StreamBuffer coherent(package, StreamCapacity::forVertices(package, full));
    StreamBuffer reference(package, StreamCapacity::forVertices(package, full));
    std::vector<std::uint32_t> maxCounts(package.objectCount()),
        maxTriangles(package.objectCount());
    for (std::size_t i = 0; i < package.objectCount(); ++i) {
      maxCounts[i] = package.object(i).vertexCount;
      maxTriangles[i] = package.object(i).triangleCount;
    }
    ASSERT_TRUE(reference.update(maxCounts, maxTriangles).ok());
    Selection selection;
    const auto path =
        orbitPath(test::packageBounds(package), {.frames = 4, .width = 320, .height = 240});
    for (const Camera& camera : path) {
      // Lower budgets first, so the full frame is assembled from coherent updates.
      for (double share : {0.05, 0.2, 1.0}) {
        selectTwoPass(scene, camera, static_cast<std::uint64_t>(share * static_cast<double>(full)),
                      {}, selection);
        ASSERT_TRUE(coherent.update(selection.vertexCounts, selection.triangleCounts).ok());
      }
      ASSERT_EQ(selection.totalVertices, full);
      const Image a = render(package, coherent, camera);
      const Image b = render(package, reference, camera);
      const ImageDifference d = compareImages(a, b);
      EXPECT_EQ(d.maxDeltaE, 0.0) << key;
      // The generated assembly is long and thin: from the orbit it covers under 1 %.
      EXPECT_GT(coverage(b), 0.004) << key << ": the model should be in view";
    }
  }
}

// A renderer that keeps its buffers between frames uploads only what each update wrote; it
// must draw every frame as a renderer given the whole arena does, compactions included.
TEST(Renderer, UploadingOnlyWhatChangedDrawsTheSameFrames) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  const std::uint64_t full = scene.totalMaxVertices();
  // A capacity near the budgets: the arena fills and compacts along the way.
  StreamBuffer buffer(package, StreamCapacity::forVertices(package, full * 3 / 10));
  auto kept = Renderer::create(package, buffer.capacity());
  ASSERT_TRUE(kept.ok()) << kept.error().message;
  auto target = Framebuffer::create(320, 240);
  ASSERT_TRUE(target.ok());
  const auto path =
      orbitPath(test::packageBounds(package), {.frames = 18, .width = 320, .height = 240});
  Selection selection;
  std::uint64_t partialFrames = 0, compactions = 0, sentBytes = 0, wholeBytes = 0;
  for (std::size_t f = 0; f < path.size(); ++f) {
    // Budgets ramping up twice: growing objects outgrow their slots until the arena is full.
    const double share = 0.03 + 0.27 * static_cast<double>(f % 6) / 5.0;
    selectTwoPass(scene, path[f], static_cast<std::uint64_t>(share * static_cast<double>(full)), {},
                  selection);
    Result<FrameStats> stats = buffer.update(selection.vertexCounts, selection.triangleCounts);
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    compactions += stats->compacted ? 1 : 0;
    kept->upload(buffer);
    target->bind();
    kept->draw(path[f], {});
    const Image a = target->read();
    const Image b = render(package, buffer, path[f]);  // a fresh renderer: the whole arena
    EXPECT_EQ(compareImages(a, b).maxDeltaE, 0.0) << "frame " << f;
    const std::uint64_t whole = buffer.positions().size_bytes() + buffer.normals().size_bytes() +
                                buffer.colors().size_bytes() + buffer.indices().size_bytes();
    if (f > 0 && kept->uploadedBytes() < whole) ++partialFrames;
    sentBytes += kept->uploadedBytes();
    wholeBytes += whole;
  }
  EXPECT_GT(compactions, 0u);
  EXPECT_GT(partialFrames, 0u);
  EXPECT_LT(sentBytes, wholeBytes / 2);
  // Nothing changed: only the draw commands and LOD ratios go again (67 objects: 1.6 KB).
  kept->upload(buffer);
  EXPECT_LT(kept->uploadedBytes(), 4096u);
  // Without the indices (the GPU reformer writes them) and back: the index buffer is not the
  // stream's any more, so everything goes again, and the frame is still drawn the same.
  kept->upload(buffer, /*indices=*/false);
  EXPECT_GE(kept->uploadedBytes(), buffer.positions().size_bytes());
  kept->upload(buffer);
  EXPECT_GE(kept->uploadedBytes(), buffer.positions().size_bytes() + buffer.indices().size_bytes());
  target->bind();
  kept->draw(path.back(), {});
  EXPECT_EQ(compareImages(target->read(), render(package, buffer, path.back())).maxDeltaE, 0.0);
}

TEST(Renderer, LowerBudgetsStayWithinStatedImageDifference) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  const std::uint64_t full = scene.totalMaxVertices();
  const auto path =
      orbitPath(test::packageBounds(package), {.frames = 3, .width = 320, .height = 240});
  StreamBuffer reference(package, StreamCapacity::forVertices(package, full));
  StreamBuffer reduced(package, StreamCapacity::forVertices(package, full));
  Selection selection;
  for (const Camera& camera : path) {
    selectTwoPass(scene, camera, full, {}, selection);
    ASSERT_TRUE(reference.update(selection.vertexCounts, selection.triangleCounts).ok());
    const Image truth = render(package, reference, camera);
    double previous = 0;
    // Bounds: the share of pixels above the just-noticeable ΔE 2.3 (measured 2026-11 on
    // llvmpipe; the bounds leave about 2x headroom).
    for (const auto& [share, bound] :
         {std::pair{0.5, 0.05}, std::pair{0.2, 0.10}, std::pair{0.05, 0.25}}) {
      selectTwoPass(scene, camera, static_cast<std::uint64_t>(share * static_cast<double>(full)),
                    {}, selection);
      ASSERT_TRUE(reduced.update(selection.vertexCounts, selection.triangleCounts).ok());
      const ImageDifference d = compareImages(render(package, reduced, camera), truth);
      EXPECT_LT(d.shareAbove, bound) << "budget " << share;
      EXPECT_GT(d.shareAbove, 0.0) << "budget " << share << ": a reduced model should differ";
      EXPECT_GE(d.shareAbove + 0.01, previous) << "fewer vertices should not look better";
      previous = d.shareAbove;
    }
  }
}

TEST(Renderer, ColourModesDiffer) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  StreamBuffer buffer(package, StreamCapacity::forVertices(package, scene.totalMaxVertices()));
  const Camera camera =
      orbitPath(test::packageBounds(package), {.frames = 1, .width = 160, .height = 120}).front();
  Selection selection;
  selectTwoPass(scene, camera, scene.totalMaxVertices() / 4, {}, selection);
  ASSERT_TRUE(buffer.update(selection.vertexCounts, selection.triangleCounts).ok());
  std::vector<Image> images;
  for (ColorMode mode :
       {ColorMode::kShaded, ColorMode::kObject, ColorMode::kLodRatio, ColorMode::kNormal})
    images.push_back(render(package, buffer, camera, mode));
  for (std::size_t i = 0; i < images.size(); ++i) {
    // Same silhouette in every mode.
    EXPECT_NEAR(coverage(images[i]), coverage(images[0]), 1e-9);
    for (std::size_t j = i + 1; j < images.size(); ++j) EXPECT_NE(images[i].rgba, images[j].rgba);
  }
  EXPECT_EQ(parseColorMode("lod").value(), ColorMode::kLodRatio);
  EXPECT_FALSE(parseColorMode("rainbow").ok());
}

// Mean chroma (largest minus smallest channel) of the covered pixels: 0 for a grey model under
// the headlight, large for the generated scan's photo-like greens and browns.
double meanChroma(const Image& image) {
  const auto background = DrawOptions{}.background;
  double sum = 0, n = 0;
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    const std::uint8_t* p = &image.rgba[4 * i];
    if (p[0] == background[0] && p[1] == background[1] && p[2] == background[2]) continue;
    sum += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
    n += 1;
  }
  return n > 0 ? sum / n : 0.0;
}

TEST(Renderer, TexturedLevelsStayCloseToTheFullResolutionTexturedRender) {
  test::headlessContext();
  test::TempDir folder;
  ASSERT_TRUE(generateScan({.triangles = 40'000, .textureSize = 1024, .atlases = 4},
                           folder.file("scan.ply"))
                  .ok());
  ASSERT_TRUE(buildPackage(folder.file("scan.ply"), folder.file("scan.lfp")).ok());
  auto package = Package::open(folder.file("scan.lfp"));
  ASSERT_TRUE(package.ok());
  ASSERT_EQ(package->imageCount(), 4u);
  const LodScene scene = LodScene::fromPackage(*package);
  const std::uint64_t full = scene.totalMaxVertices();
  StreamBuffer reference(*package, StreamCapacity::forVertices(*package, full));
  StreamBuffer reduced(*package, StreamCapacity::forVertices(*package, full));
  Selection selection;
  for (const Camera& camera :
       orbitPath(test::packageBounds(*package), {.frames = 2, .width = 320, .height = 240})) {
    selectTwoPass(scene, camera, full, {}, selection);
    ASSERT_TRUE(reference.update(selection.vertexCounts, selection.triangleCounts).ok());
    const Image truth = render(*package, reference, camera);
    // The texture is drawn (the objects' base colour is grey).
    EXPECT_GT(meanChroma(truth), 15.0);
    EXPECT_GT(coverage(truth), 0.1);
    double previous = 0;
    for (const auto& [share, bound] :
         {std::pair{0.5, 0.05}, std::pair{0.2, 0.10}, std::pair{0.05, 0.25}}) {
      const auto budget = static_cast<std::uint64_t>(share * static_cast<double>(full));
      selectTwoPass(scene, camera, budget, {}, selection);
      // Whole counts only (no point half collapsed), so at most the budget.
      EXPECT_LE(selection.totalVertices, budget);
      EXPECT_GT(selection.totalVertices, budget * 9 / 10);
      for (std::size_t i = 0; i < package->objectCount(); ++i) {
        const std::uint32_t v = selection.vertexCounts[i];
        if (v != 0) {
          EXPECT_EQ(package->wholeAt(i, v), v);
        }
      }
      ASSERT_TRUE(reduced.update(selection.vertexCounts, selection.triangleCounts).ok());
      const ImageDifference d = compareImages(render(*package, reduced, camera), truth);
      std::printf("budget %.2f: %.4f of pixels above dE 2.3, mean dE %.2f\n", share, d.shareAbove,
                  d.meanDeltaE);
      EXPECT_LT(d.shareAbove, bound) << "budget " << share;
      EXPECT_GT(d.shareAbove, 0.0) << "budget " << share << ": a reduced model should differ";
      EXPECT_GE(d.shareAbove + 0.01, previous) << "fewer vertices should not look better";
      previous = d.shareAbove;
    }
  }
}

}  // namespace
}  // namespace lodforge
