// Packages the runtime tests share: real CAD models from ../shared/data and a generated
// assembly, each built once per test program by the real builder.
#pragma once

#include <map>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/generate/cad.h"
#include "lodforge/simplify/builder.h"
#include "lodforge/simplify/package.h"
#include "test_support.h"

namespace lodforge::test {

class RuntimePackages {
 public:
  // "engine" (2CylinderEngine.glb), "motor" (as1_motor.glb), "horse" (one scanned mesh),
  // "spider" (19 textured objects over 4 JPEGs, an OBJ),
  // "cad" (a generated assembly of 1,500 parts), "crowd" (20,000 copies of the motor's small
  // parts).
  static const Package& get(const std::string& key) {
    static RuntimePackages instance;
    auto it = instance.packages_.find(key);
    if (it == instance.packages_.end())
      it = instance.packages_.emplace(key, instance.build(key)).first;
    return *it->second;
  }

 private:
  std::unique_ptr<Package> build(const std::string& key) {
    std::string input;
    if (key == "engine")
      input = dataPath("meshes/2CylinderEngine.glb");
    else if (key == "motor")
      input = dataPath("meshes/as1_motor.glb");
    else if (key == "horse")
      input = dataPath("meshes/horse.ply");
    else if (key == "spider")
      input = dataPath("textured/spider/spider.obj");
    else if (key == "crowd")
      return crowd();
    else {
      input = folder_.file("cad.ply");
      const auto generated = generateCad({.objects = 1500, .seed = 7}, input);
      EXPECT_TRUE(generated.ok()) << generated.error().message;
    }
    const std::string output = folder_.file(key + ".lfp");
    const auto built = buildPackage(input, output);
    EXPECT_TRUE(built.ok()) << built.error().message;
    auto package = Package::open(output);
    EXPECT_TRUE(package.ok()) << package.error().message;
    return std::make_unique<Package>(std::move(package).value());
  }
  // 20,000 objects (enough that selection's parallel partition runs in several chunks): the
  // motor's small parts, copied with random offsets and scales over a wide field.
  std::unique_ptr<Package> crowd() {
    const Package& engine = get("motor");
    std::vector<ProgressiveMesh> parts;
    for (std::size_t o = 0; o < engine.objectCount(); ++o) {
      if (engine.object(o).vertexCount > 160) continue;  // small parts keep the file small
      ProgressiveMesh& m = parts.emplace_back();
      m.q = engine.object(o).minVertexCount;
      m.positions.assign(engine.positions(o).begin(), engine.positions(o).end());
      m.normals.assign(engine.normals(o).begin(), engine.normals(o).end());
      m.triangles.assign(engine.triangles(o).begin(), engine.triangles(o).end());
      m.ecol.assign(engine.ecol(o).begin(), engine.ecol(o).end());
      m.map.assign(engine.map(o).begin(), engine.map(o).end());
      m.error.assign(engine.error(o).begin(), engine.error(o).end());
    }
    const std::string output = folder_.file("crowd.lfp");
    auto writer = PackageWriter::create(output, engine.origin(), true, false);
    EXPECT_TRUE(writer.ok()) << writer.error().message;
    Random random(99);
    for (std::size_t k = 0; k < 20'000; ++k) {
      ProgressiveMesh m = parts[random.below(parts.size())];
      const float scale = static_cast<float>(random.logUniform(0.05, 3));
      const Vec3f offset{static_cast<float>(random.uniform(-20, 20)),
                         static_cast<float>(random.uniform(-20, 20)),
                         static_cast<float>(random.uniform(-2, 2))};
      for (Vec3f& p : m.positions) p = p * scale + offset;
      const Status added = writer->add(m, {.name = "part"});
      EXPECT_TRUE(added.ok()) << added.message();
    }
    const Status finished = writer->finish();
    EXPECT_TRUE(finished.ok()) << finished.message();
    auto package = Package::open(output);
    EXPECT_TRUE(package.ok()) << package.error().message;
    return std::make_unique<Package>(std::move(package).value());
  }

  TempDir folder_;
  std::map<std::string, std::unique_ptr<Package>> packages_;
};

// Bounds of a package relative to its origin (the frame cameras live in).
inline Aabbd packageBounds(const Package& package) {
  Aabbd bounds;
  const auto& h = package.header();
  bounds.add(Vec3d{h.boundsMin[0], h.boundsMin[1], h.boundsMin[2]});
  bounds.add(Vec3d{h.boundsMax[0], h.boundsMax[1], h.boundsMax[2]});
  return bounds;
}

}  // namespace lodforge::test
