// The compute-shader reformation against the CPU path (Algorithm 2 in runtime/stream), on
// llvmpipe: identical index buffers for random selections.
#include "lodforge/render/gpu_reform.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "render/headless.h"
#include "runtime/packages.h"

namespace lodforge {
namespace {

TEST(GpuReform, EqualsTheCpuIndicesForRandomSelections) {
  test::headlessContext();
  Random random(2024);
  for (const char* key : {"engine", "motor", "cad", "crowd"}) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    const std::uint64_t full = scene.totalMaxVertices();
    StreamBuffer buffer(package, StreamCapacity::forVertices(package, full));
    auto renderer = Renderer::create(package, buffer.capacity());
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    auto reformer = GpuReformer::create(package, buffer.capacity());
    ASSERT_TRUE(reformer.ok()) << reformer.error().message;
    std::vector<std::uint32_t> vc(package.objectCount()), tc(package.objectCount());
    std::uint64_t checked = 0, gaps = 0;
    for (int round = 0; round < 12; ++round) {
      // Every object at a random level of its own (0, q..p), some rounds with most objects out.
      const double absent = round % 3 == 0 ? 0.8 : 0.1;
      for (std::size_t i = 0; i < vc.size(); ++i) {
        const auto& o = package.object(i);
        if (random.uniform(0, 1) < absent) {
          vc[i] = tc[i] = 0;
          continue;
        }
        vc[i] = o.minVertexCount +
                static_cast<std::uint32_t>(random.below(o.vertexCount - o.minVertexCount + 1));
        tc[i] = package.map(i)[vc[i] - o.minVertexCount];
      }
      ASSERT_TRUE(buffer.update(vc, tc).ok());
      renderer->upload(buffer, /*indices=*/false);
      // A marker in every word first: the gaps between slots must keep it (skipped, not
      // re-formed from whatever source lies there).
      const std::uint32_t marker = 0xFFFFFFFFu;
      glClearNamedBufferData(renderer->indexBuffer(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT,
                             &marker);
      reformer->reform(buffer, renderer->indexBuffer());
      const auto cpu = buffer.indices();
      const auto gpu = GpuReformer::readIndices(renderer->indexBuffer(), cpu.size() / 3);
      ASSERT_EQ(gpu.size(), cpu.size());
      std::vector<bool> held(gpu.size(), false);
      for (std::size_t i = 0; i < vc.size(); ++i) {
        const std::size_t first = 3 * buffer.triangleStart()[i], corners = 3 * std::size_t{tc[i]};
        ASSERT_TRUE(
            std::equal(gpu.begin() + first, gpu.begin() + first + corners, cpu.begin() + first))
            << key << " round " << round << " object " << i;
        std::fill(held.begin() + first, held.begin() + first + corners, true);
      }
      for (std::size_t w = 0; w < gpu.size(); ++w) {
        if (held[w]) continue;
        ASSERT_EQ(gpu[w], marker) << key << " round " << round << " word " << w;
        ++gaps;
      }
      checked += buffer.triangleCount();
    }
    EXPECT_GT(checked, 0u) << key;
    EXPECT_GT(gaps, 0u) << key;  // the slots did leave gaps
  }
}

TEST(GpuReform, RendersTheSameImageAsTheCpuPath) {
  test::headlessContext();
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  StreamBuffer buffer(package, StreamCapacity::forVertices(package, scene.totalMaxVertices()));
  auto renderer = Renderer::create(package, buffer.capacity());
  auto reformer = GpuReformer::create(package, buffer.capacity());
  ASSERT_TRUE(renderer.ok() && reformer.ok());
  auto target = Framebuffer::create(240, 180);
  ASSERT_TRUE(target.ok());
  Selection selection;
  for (const Camera& camera :
       orbitPath(test::packageBounds(package), {.frames = 3, .width = 240, .height = 180})) {
    selectTwoPass(scene, camera, scene.totalMaxVertices() / 10, {}, selection);
    ASSERT_TRUE(buffer.update(selection.vertexCounts, selection.triangleCounts).ok());
    target->bind();
    renderer->upload(buffer);
    renderer->draw(camera, {});
    const Image cpu = target->read();
    renderer->upload(buffer, /*indices=*/false);
    reformer->reform(buffer, renderer->indexBuffer());
    renderer->draw(camera, {});
    const Image gpu = target->read();
    EXPECT_EQ(compareImages(cpu, gpu).maxDeltaE, 0.0);
  }
}

}  // namespace
}  // namespace lodforge
