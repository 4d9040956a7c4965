// The CAD paper's Fig. 7 claim, measured (docs/BENCHMARKS.md):
//   bench_render [--size WxH] [--frames N] [--pictures DIR] PACKAGE[@orbit|@fly]...
// Along each package's path, renders the full-detail reference and, for N = 1 %, 5 % and 20 % of
// the full vertex count, the two-pass selection and the first pass alone (Eq. 2-3), headless on
// OpenGL; prints per mode the image difference to the reference (share of pixels with CIE76
// ΔE > 2.3, mean ΔE, PSNR) and how many of the visible objects — and of the visible small ones,
// the half with the smaller box diagonals — are drawn at all. With --pictures, one frame per
// package at 5 % side by side: reference | two-pass | first pass.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "lodforge/core/units.h"
#include "lodforge/render/context.h"
#include "lodforge/render/image.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "lodforge/runtime/stream.h"

namespace lodforge {
namespace {

struct ModeFigures {
  double shareAbove = 0, meanDeltaE = 0, psnr = 0;
  double drawnShare = 0, smallDrawnShare = 0;  // of the visible (small) objects
  std::uint64_t vertices = 0;
};

Image sideBySide(const std::vector<Image>& images) {
  std::uint32_t width = 0, height = 0;
  for (const Image& i : images) {
    width += i.width;
    height = std::max(height, i.height);
  }
  Image out(width, height);
  std::uint32_t x0 = 0;
  for (const Image& i : images) {
    for (std::uint32_t y = 0; y < i.height; ++y)
      std::copy_n(&i.rgba[4 * std::size_t{y} * i.width], 4 * std::size_t{i.width},
                  &out.rgba[4 * (std::size_t{y} * width + x0)]);
    x0 += i.width;
  }
  return out;
}

int run(int argc, char** argv) {
  std::uint32_t width = 640, height = 480;
  std::size_t frames = 8;
  std::string pictures;
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size" && i + 1 < argc) {
      std::sscanf(argv[++i], "%ux%u", &width, &height);
    } else if (a == "--frames" && i + 1 < argc) {
      frames = std::stoul(argv[++i]);
    } else if (a == "--pictures" && i + 1 < argc) {
      pictures = argv[++i];
    } else {
      inputs.push_back(a);
    }
  }
  if (inputs.empty()) {
    std::fprintf(
        stderr,
        "usage: bench_render [--size WxH] [--frames N] [--pictures DIR] PACKAGE[@orbit|@fly]...\n");
    return 2;
  }
  auto gl = GlContext::headless();
  if (!gl) {
    std::fprintf(stderr, "%s\n", gl.error().message.c_str());
    return 1;
  }
  auto target = Framebuffer::create(width, height);
  if (!target) return 1;
  if (!pictures.empty()) std::filesystem::create_directories(pictures);
  std::printf("%zu frames per path at %ux%u on %s (llvmpipe: CPU rendering)\n\n", frames, width,
              height, (*gl)->renderer().c_str());
  std::printf(
      "| model | path | N | mode | ΔE>2.3 | mean ΔE | PSNR dB | visible objects drawn | small "
      "visible drawn |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& input : inputs) {
    const std::size_t at = input.rfind('@');
    const std::string file = at == std::string::npos ? input : input.substr(0, at);
    const std::string pathName = at == std::string::npos ? "orbit" : input.substr(at + 1);
    auto package = Package::open(file);
    if (!package) {
      std::fprintf(stderr, "%s\n", package.error().message.c_str());
      return 2;
    }
    const LodScene scene = LodScene::fromPackage(*package);
    const std::uint64_t full = scene.totalMaxVertices();
    const auto& h = package->header();
    Aabbd bounds;
    bounds.add(Vec3d{h.boundsMin[0], h.boundsMin[1], h.boundsMin[2]});
    bounds.add(Vec3d{h.boundsMax[0], h.boundsMax[1], h.boundsMax[2]});
    const PathOptions options{.frames = frames, .width = width, .height = height};
    const std::vector<Camera> cameras =
        pathName == "fly" ? flyThroughPath(bounds, options) : orbitPath(bounds, options);
    // Small: the half of the objects with the smaller box diagonals.
    std::vector<float> diagonals(package->objectCount());
    for (std::size_t i = 0; i < diagonals.size(); ++i)
      diagonals[i] = 2 * std::sqrt(scene.hx[i] * scene.hx[i] + scene.hy[i] * scene.hy[i] +
                                   scene.hz[i] * scene.hz[i]);
    std::vector<float> sorted = diagonals;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const float median = sorted[sorted.size() / 2];

    StreamBuffer buffer(*package, StreamCapacity::forVertices(*package, full));
    auto renderer = Renderer::create(*package, buffer.capacity());
    if (!renderer) return 1;
    const auto draw = [&](const Camera& camera) {
      renderer->upload(buffer);
      target->bind();
      renderer->draw(camera, {});
      return target->read();
    };
    // References: every object at full detail.
    std::vector<std::uint32_t> maxV(package->objectCount()), maxT(package->objectCount());
    for (std::size_t i = 0; i < maxV.size(); ++i) {
      maxV[i] = package->object(i).vertexCount;
      maxT[i] = package->object(i).triangleCount;
    }
    std::vector<Image> references;
    if (!buffer.update(maxV, maxT)) return 1;
    for (const Camera& camera : cameras) references.push_back(draw(camera));

    const std::size_t pictureFrame = cameras.size() / 3;
    std::vector<Image> picture{references[pictureFrame]};
    const std::string name = std::filesystem::path(file).stem().string();
    for (const double percent : {1.0, 5.0, 20.0}) {
      const auto budget =
          static_cast<std::uint64_t>(std::llround(percent / 100 * static_cast<double>(full)));
      for (const bool firstPassOnly : {false, true}) {
        ModeFigures m;
        Selection selection;
        for (std::size_t f = 0; f < cameras.size(); ++f) {
          selectTwoPass(scene, cameras[f], budget, {.firstPassOnly = firstPassOnly}, selection);
          if (!buffer.update(selection.vertexCounts, selection.triangleCounts)) return 1;
          const Image image = draw(cameras[f]);
          const ImageDifference d = compareImages(image, references[f]);
          m.shareAbove += d.shareAbove;
          m.meanDeltaE += d.meanDeltaE;
          m.psnr += std::isinf(d.psnr) ? 99 : d.psnr;
          m.vertices += selection.totalVertices;
          std::size_t visible = 0, drawn = 0, smallVisible = 0, smallDrawn = 0;
          for (std::size_t i = 0; i < selection.vertexCounts.size(); ++i) {
            if (!(selection.importance[i] > 0)) continue;
            const bool small = diagonals[i] < median;
            const bool shown = selection.vertexCounts[i] > 0;
            ++visible;
            drawn += shown;
            smallVisible += small;
            smallDrawn += small && shown;
          }
          m.drawnShare += visible ? static_cast<double>(drawn) / static_cast<double>(visible) : 1;
          m.smallDrawnShare +=
              smallVisible ? static_cast<double>(smallDrawn) / static_cast<double>(smallVisible)
                           : 1;
          if (percent == 5.0 && f == pictureFrame) picture.push_back(image);
        }
        const double n = static_cast<double>(cameras.size());
        std::printf("| %s | %s | %g %% | %s | %.2f %% | %.2f | %.1f | %.0f %% | %.0f %% |\n",
                    name.c_str(), pathName.c_str(), percent,
                    firstPassOnly ? "first pass only" : "two-pass", 100 * m.shareAbove / n,
                    m.meanDeltaE / n, m.psnr / n, 100 * m.drawnShare / n,
                    100 * m.smallDrawnShare / n);
        std::fflush(stdout);
      }
    }
    if (!pictures.empty()) {
      const std::string out =
          (std::filesystem::path(pictures) / (name + "-" + pathName + "-5pct.png")).string();
      if (!writePng(out, sideBySide(picture))) return 1;
    }
  }
  return 0;
}

}  // namespace
}  // namespace lodforge

int main(int argc, char** argv) {
  return lodforge::run(argc, argv);
}
