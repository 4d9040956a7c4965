// Progressive build versus meshoptimizer, side by side in one run (docs/BENCHMARKS.md):
//   bench_simplify [--quality] MODEL...
// For each model (all objects, welded as `lodforge build` welds them): our progressive build
// on 1 and 2 threads, meshopt_simplify down to its minimum (borders locked, as ours are) on 1
// thread, in input triangles per second; with --quality, the symmetric Hausdorff and RMS
// distance to the original at 50 %, 10 % and 1 % of the triangles for both (single-object
// models), relative to the bounding-box diagonal.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <meshoptimizer.h>
#include <tbb/parallel_for.h>

#include "lodforge/core/distance.h"
#include "lodforge/core/threads.h"
#include "lodforge/core/units.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/prepare.h"
#include "lodforge/simplify/progressive.h"
#include "lodforge/simplify/reform.h"

namespace lodforge {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::vector<ProgressiveMesh> buildAll(const std::vector<PreparedObject>& objects) {
  std::vector<ProgressiveMesh> meshes(objects.size());
  tbb::parallel_for(
      std::size_t{0}, objects.size(),
      [&](std::size_t i) {
        meshes[i] = buildProgressive(objects[i].positions, objects[i].indices, objects[i].normals,
                                     objects[i].colors);
      },
      tbb::simple_partitioner());
  return meshes;
}

// Our mesh with about `triangles` triangles: the vertex count whose map is closest.
std::vector<std::uint32_t> oursAt(const ProgressiveMesh& mesh, std::uint64_t triangles,
                                  std::uint32_t& n) {
  n = mesh.q;
  for (std::uint32_t v = mesh.q; v <= mesh.vertexCount(); ++v) {
    n = v;
    if (mesh.trianglesAt(v) >= triangles) break;
  }
  std::vector<std::uint32_t> out(3 * std::size_t{mesh.trianglesAt(n)});
  reformObject(std::span(mesh.triangles).first(out.size()), mesh.ecol, n, 0, out);
  return out;
}

void run(const std::string& path, bool quality) {
  Result<Model> model = readModel(path);
  if (!model) {
    fmt::print(stderr, "{}\n", model.error().message);
    std::exit(1);
  }
  std::vector<PreparedObject> objects(model->objectCount());
  std::uint64_t triangles = 0;
  for (std::size_t o = 0; o < objects.size(); ++o) {
    objects[o] = prepareObject(model->objectPositions(o), {}, {}, model->objectIndices(o),
                               {.normals = false});
    triangles += objects[o].indices.size() / 3;
  }
  const std::string name = std::filesystem::path(path).filename().string();

  // Best of `repeats` runs each, interleaved, so a busy moment of the machine hits both alike.
  const int repeats = triangles > 5'000'000 ? 1 : 5;
  double ours1 = 1e30, ours2 = 1e30, meshopt = 1e30;
  std::vector<ProgressiveMesh> meshes;
  std::uint64_t meshoptMin = 0;
  std::vector<unsigned> scratch;
  for (int r = 0; r < repeats; ++r) {
    {
      const ThreadLimit one(1);
      const auto start = Clock::now();
      meshes = buildAll(objects);
      ours1 = std::min(ours1, seconds(start));
    }
    {
      const ThreadLimit two(2);
      const auto start = Clock::now();
      meshes = buildAll(objects);
      ours2 = std::min(ours2, seconds(start));
    }
    // meshoptimizer to its minimum, one thread (it has no threading of its own).
    meshoptMin = 0;
    const auto start = Clock::now();
    for (const PreparedObject& o : objects) {
      scratch.resize(o.indices.size());
      meshoptMin += meshopt_simplify(scratch.data(), o.indices.data(), o.indices.size(),
                                     &o.positions[0].x, o.positions.size(), sizeof(Vec3f), 0, 1e30f,
                                     meshopt_SimplifyLockBorder, nullptr) /
                    3;
    }
    meshopt = std::min(meshopt, seconds(start));
  }
  std::uint64_t oursMin = 0;
  for (const auto& m : meshes) oursMin += m.trianglesAt(m.q);
  const double rate1 = static_cast<double>(triangles) / ours1,
               rate2 = static_cast<double>(triangles) / ours2;
  const double rateMeshopt = static_cast<double>(triangles) / meshopt;
  fmt::print("| {} | {} | {} | {:.0f} K/s | {:.0f} K/s | {:.0f} K/s | {:.2f} | {} | {} |\n", name,
             formatCount(objects.size()), formatCount(triangles), rate1 / 1e3, rate2 / 1e3,
             rateMeshopt / 1e3, rate1 / rateMeshopt, formatCount(oursMin), formatCount(meshoptMin));
  std::fflush(stdout);

  if (!quality || objects.size() != 1) return;
  const PreparedObject& o = objects[0];
  const ProgressiveMesh& mesh = meshes[0];
  Aabb box;
  for (const Vec3f& p : o.positions) box.add(p);
  const double diagonal = length(toDouble(box.size()));
  for (double share : {0.5, 0.1, 0.01}) {
    const auto target =
        static_cast<std::uint64_t>(share * static_cast<double>(o.indices.size() / 3));
    std::uint32_t n = 0;
    const std::vector<std::uint32_t> ours = oursAt(mesh, target, n);
    std::vector<unsigned> theirs(o.indices.size());
    theirs.resize(meshopt_simplify(theirs.data(), o.indices.data(), o.indices.size(),
                                   &o.positions[0].x, o.positions.size(), sizeof(Vec3f), 3 * target,
                                   1e30f, meshopt_SimplifyLockBorder, nullptr));
    const SurfaceDistance a = surfaceDistance(mesh.positions, ours, mesh.positions, mesh.triangles);
    const SurfaceDistance b = surfaceDistance(o.positions, theirs, o.positions, o.indices);
    fmt::print(
        "|   {} at {:g} % | ours {} tri: Hausdorff {:.3e}, RMS {:.3e} | meshopt {} tri: Hausdorff "
        "{:.3e}, RMS {:.3e} | "
        "ratio {:.2f} / {:.2f} |\n",
        name, share * 100, formatCount(ours.size() / 3), a.hausdorff / diagonal, a.rms / diagonal,
        formatCount(theirs.size() / 3), b.hausdorff / diagonal, b.rms / diagonal,
        a.hausdorff / b.hausdorff, a.rms / b.rms);
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace lodforge

int main(int argc, char** argv) {
  bool quality = false;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quality")
      quality = true;
    else
      paths.push_back(arg);
  }
  if (paths.empty()) {
    std::fprintf(stderr, "usage: bench_simplify [--quality] MODEL...\n");
    return 2;
  }
  fmt::print(
      "| model | objects | triangles | ours, 1 thread | ours, 2 threads | meshopt, 1 thread | "
      "ours/meshopt (1 thread) | "
      "ours min tri | meshopt min tri |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& path : paths) lodforge::run(path, quality);
}
