// §3.3 on the GPU against the CPU stream: after every frame of random walks, jumps and budget
// changes, the GPU copies hold exactly what StreamBuffer holds (its slots gathered in object
// order), and only the Δ crossed over.
#include "lodforge/render/gpu_stream.h"

#include <cstring>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/render/gpu_reform.h"
#include "lodforge/render/renderer.h"
#include "lodforge/render/shader.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "render/headless.h"
#include "runtime/compact_view.h"
#include "runtime/packages.h"

namespace lodforge {
namespace {

template <class T>
std::vector<std::uint32_t> words(std::span<const T> values) {
  std::vector<std::uint32_t> out(values.size_bytes() / 4);
  if (!out.empty()) std::memcpy(out.data(), values.data(), values.size_bytes());
  return out;
}

TEST(GpuStream, EveryFrameEqualsTheCpuStreamAndReadsOnlyTheDelta) {
  test::headlessContext();
  Random random(77);
  for (const char* key : {"engine", "motor", "cad", "crowd", "spider"}) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    const std::uint64_t full = scene.totalMaxVertices();
    const StreamCapacity capacity = StreamCapacity::forVertices(package, full);
    StreamBuffer cpu(package, capacity);
    auto gpu = GpuStream::create(package, capacity);
    ASSERT_TRUE(gpu.ok()) << gpu.error().message;
    auto reformer = GpuReformer::create(package, capacity);
    ASSERT_TRUE(reformer.ok());
    auto renderer = Renderer::create(package, capacity);
    ASSERT_TRUE(renderer.ok());
    auto path =
        orbitPath(test::packageBounds(package), {.frames = 10, .width = 320, .height = 240});
    const auto fly =
        flyThroughPath(test::packageBounds(package), {.frames = 6, .width = 320, .height = 240});
    path.insert(path.end(), fly.begin(), fly.end());
    Selection selection;
    for (std::size_t f = 0; f < path.size(); ++f) {
      // A drifting budget, with an unchanged frame now and then.
      const double share = f % 5 == 4 ? 0.0 : random.logUniform(0.005, 1.0);
      if (share > 0)
        selectTwoPass(scene, path[f],
                      std::max<std::uint64_t>(
                          1, static_cast<std::uint64_t>(share * static_cast<double>(full))),
                      {}, selection);
      auto a = cpu.update(selection.vertexCounts, selection.triangleCounts);
      auto b = gpu->update(selection.vertexCounts, selection.triangleCounts);
      ASSERT_TRUE(a.ok() && b.ok());
      EXPECT_EQ(b->verticesRead, a->verticesRead) << key << " frame " << f;
      EXPECT_EQ(b->trianglesRead, a->trianglesRead) << key << " frame " << f;
      if (share == 0) {
        EXPECT_EQ(b->verticesRead + b->trianglesRead, 0u);
      }
      ASSERT_EQ(gpu->vertexCount(), cpu.vertexCount());
      ASSERT_EQ(gpu->triangleCount(), cpu.triangleCount());
      // The GPU stream is compact (the paper's layout); the CPU one's slots, gathered, equal it.
      const test::CompactView view = test::compactView(cpu);
      EXPECT_EQ(readBufferWords(gpu->positionBuffer(), 3 * gpu->vertexCount()),
                words(std::span<const Vec3f>(view.positions)))
          << key << " frame " << f;
      if (package.header().hasNormals()) {
        EXPECT_EQ(readBufferWords(gpu->normalBuffer(), 3 * gpu->vertexCount()),
                  words(std::span<const Vec3f>(view.normals)));
      }
      if (package.header().hasUvs()) {
        EXPECT_EQ(readBufferWords(gpu->uvBuffer(), 2 * gpu->vertexCount()),
                  words(std::span<const Vec2f>(view.uvs)))
            << key << " frame " << f;
      }
      EXPECT_EQ(readBufferWords(gpu->sourceBuffer(), 3 * gpu->triangleCount()),
                words(std::span<const std::uint32_t>(view.source)))
          << key << " frame " << f;
      // Algorithm 2 on the GPU from the GPU's own source triangles.
      reformer->reform(*gpu, renderer->indexBuffer());
      EXPECT_EQ(GpuReformer::readIndices(renderer->indexBuffer(), gpu->triangleCount()),
                words(std::span<const std::uint32_t>(view.indices)))
          << key << " frame " << f;
    }
  }
}

TEST(GpuStream, OverCapacityIsRefusedAndTheFrameKept) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("motor");
  const LodScene scene = LodScene::fromPackage(package);
  const std::uint64_t capacityVertices = scene.totalMaxVertices() / 4;
  auto gpu = GpuStream::create(package, StreamCapacity::forVertices(package, capacityVertices));
  ASSERT_TRUE(gpu.ok());
  const Camera camera = orbitPath(test::packageBounds(package), {.frames = 1}).front();
  Selection small, big;
  selectTwoPass(scene, camera, capacityVertices, {}, small);
  selectTwoPass(scene, camera, capacityVertices * 2, {}, big);
  ASSERT_TRUE(gpu->update(small.vertexCounts, small.triangleCounts).ok());
  const auto before = readBufferWords(gpu->positionBuffer(), 3 * gpu->vertexCount());
  const auto refused = gpu->update(big.vertexCounts, big.triangleCounts);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kLimit);
  EXPECT_EQ(gpu->vertexCount(), small.totalVertices);
  EXPECT_EQ(readBufferWords(gpu->positionBuffer(), 3 * gpu->vertexCount()), before);
}

TEST(GpuStream, DrawsTheSameFramesAsTheCpuStream) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  const StreamCapacity capacity = StreamCapacity::forVertices(package, scene.totalMaxVertices());
  StreamBuffer cpu(package, capacity);
  auto gpu = GpuStream::create(package, capacity);
  auto reformer = GpuReformer::create(package, capacity);
  auto renderer = Renderer::create(package, capacity);
  auto target = Framebuffer::create(240, 180);
  ASSERT_TRUE(gpu.ok() && reformer.ok() && renderer.ok() && target.ok());
  Selection selection;
  for (const Camera& camera :
       orbitPath(test::packageBounds(package), {.frames = 4, .width = 240, .height = 180})) {
    selectTwoPass(scene, camera, scene.totalMaxVertices() / 8, {}, selection);
    ASSERT_TRUE(cpu.update(selection.vertexCounts, selection.triangleCounts).ok());
    ASSERT_TRUE(gpu->update(selection.vertexCounts, selection.triangleCounts).ok());
    target->bind();
    renderer->upload(cpu);
    renderer->draw(camera, {});
    const Image a = target->read();
    renderer->attach(*gpu);
    reformer->reform(*gpu, renderer->indexBuffer());
    renderer->draw(camera, {});
    const Image b = target->read();
    EXPECT_EQ(compareImages(a, b).maxDeltaE, 0.0);
  }
}

}  // namespace
}  // namespace lodforge
