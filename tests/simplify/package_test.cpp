#include "lodforge/simplify/package.h"

#include <array>
#include <cstring>
#include <functional>
#include <set>

#include <gtest/gtest.h>

#include "lodforge/core/checksum.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/builder.h"
#include "lodforge/simplify/prepare.h"
#include "test_support.h"

namespace lodforge {
namespace {

std::vector<ProgressiveMesh> meshesOf(const Model& model) {
  std::vector<ProgressiveMesh> meshes;
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const PreparedObject p =
        prepareObject(model.objectPositions(o), {}, {}, model.objectIndices(o));
    meshes.push_back(buildProgressive(p.positions, p.indices, p.normals, p.colors));
  }
  return meshes;
}

TEST(Package, WrittenObjectsReadBackIdentically) {
  Result<Model> engine = readModel(test::dataPath("meshes/2CylinderEngine.glb"));
  ASSERT_TRUE(engine.ok());
  const std::vector<ProgressiveMesh> meshes = meshesOf(*engine);
  // Layers as a CAD reader gives them: a table, objects on one entry or none.
  const std::vector<std::string> layers = {"structure", "électrique; harness"};
  const auto layerOf = [](std::size_t o) {
    return o % 3 == 2 ? kNoLayer : static_cast<std::uint32_t>(o % 3);
  };
  test::TempDir dir;
  {
    Result<PackageWriter> writer = PackageWriter::create(dir.file("e.lfp"), {1, 2, 3}, true, false);
    ASSERT_TRUE(writer.ok());
    for (std::size_t o = 0; o < meshes.size(); ++o) {
      ASSERT_TRUE(
          writer
              ->add(meshes[o], {engine->objectName(o), Rgba8{10, 20, 30, 255},
                                engine->objectPath(o), engine->objects[o].material, layerOf(o)})
              .ok());
    }
    ASSERT_TRUE(writer->finish(engine->materials, layers).ok());
  }
  EXPECT_EQ(test::listFolder(dir.path()),
            std::vector<std::string>{"e.lfp"});  // no spill files left
  Result<Package> package = Package::open(dir.file("e.lfp"));
  ASSERT_TRUE(package.ok()) << package.error().message;
  ASSERT_EQ(package->objectCount(), meshes.size());
  EXPECT_EQ(package->origin(), (Vec3d{1, 2, 3}));
  EXPECT_TRUE(package->header().hasNormals());
  EXPECT_FALSE(package->header().hasColors());
  for (std::size_t o = 0; o < meshes.size(); ++o) {
    const ProgressiveMesh& m = meshes[o];
    EXPECT_EQ(package->objectName(o), engine->objectName(o));
    EXPECT_EQ(package->objectPath(o), engine->objectPath(o));
    EXPECT_EQ(package->objectMaterial(o), engine->objects[o].material);
    EXPECT_EQ(package->objectLayerIndex(o), layerOf(o));
    EXPECT_EQ(package->objectLayer(o), layerOf(o) == kNoLayer ? "" : layers[layerOf(o)]);
    EXPECT_EQ(package->object(o).minVertexCount, m.q);
    EXPECT_EQ(package->object(o).color, (Rgba8{10, 20, 30, 255}));
    EXPECT_TRUE(std::equal(m.positions.begin(), m.positions.end(), package->positions(o).begin()));
    EXPECT_TRUE(std::equal(m.normals.begin(), m.normals.end(), package->normals(o).begin()));
    EXPECT_TRUE(std::equal(m.triangles.begin(), m.triangles.end(), package->triangles(o).begin()));
    EXPECT_TRUE(std::equal(m.ecol.begin(), m.ecol.end(), package->ecol(o).begin()));
    EXPECT_TRUE(std::equal(m.map.begin(), m.map.end(), package->map(o).begin()));
    EXPECT_TRUE(std::equal(m.error.begin(), m.error.end(), package->error(o).begin()));
  }
  // The engine's assembly tree and its materials, every field of them.
  EXPECT_NE(engine->objectPath(0), "");
  ASSERT_GT(engine->materials.size(), 1u);
  ASSERT_EQ(package->materialCount(), engine->materials.size());
  for (std::size_t m = 0; m < engine->materials.size(); ++m)
    EXPECT_EQ(package->material(m), engine->materials[m]) << m;
  ASSERT_EQ(package->layerCount(), layers.size());
  for (std::size_t l = 0; l < layers.size(); ++l) EXPECT_EQ(package->layer(l), layers[l]);
  // Sections start on 64-byte boundaries.
  for (const PackageSectionEntry& e : package->header().sections) EXPECT_EQ(e.offset % 64, 0u);
}

class Corrupted : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(buildPackage(test::dataPath("meshes/as1_motor.glb"), dir.file("m.lfp")).ok());
    bytes = test::readFile(dir.file("m.lfp"));
    ASSERT_TRUE(open(bytes).ok());
  }
  Result<Package> open(const std::string& data, const PackageOpenOptions& options = {}) {
    // Package data must be 8-byte aligned, as an mmap would be.
    buffer.assign(data.size() / 8 + 1, 0);
    std::memcpy(buffer.data(), data.data(), data.size());
    return Package::fromBytes({reinterpret_cast<const std::byte*>(buffer.data()), data.size()},
                              "m.lfp", options);
  }
  const PackageHeader& header() const {
    return *reinterpret_cast<const PackageHeader*>(bytes.data());
  }
  // Rewrites a section's checksum and the header's, as a forger would.
  void reseal(std::string& data) {
    auto* h = reinterpret_cast<PackageHeader*>(data.data());
    for (auto& e : h->sections) {
      if (e.offset <= data.size() && e.bytes <= data.size() - e.offset)
        e.checksum =
            checksum64({reinterpret_cast<const std::byte*>(data.data()) + e.offset, e.bytes});
    }
    h->headerChecksum = checksum64(
        {reinterpret_cast<const std::byte*>(data.data()), offsetof(PackageHeader, headerChecksum)});
  }
  test::TempDir dir;
  std::string bytes;
  std::vector<std::uint64_t> buffer;
};

TEST_F(Corrupted, AnyFlippedByteInAnySectionIsCaughtByItsChecksum) {
  for (std::uint32_t s = 0; s < kPackageSections; ++s) {
    const PackageSectionEntry& e = header().sections[s];
    if (e.bytes == 0) continue;
    std::string copy = bytes;
    copy[e.offset + e.bytes / 2] ^= 0x40;
    Result<Package> p = open(copy);
    ASSERT_FALSE(p.ok()) << packageSectionName(static_cast<PackageSection>(s));
    EXPECT_NE(
        p.error().message.find(std::string(packageSectionName(static_cast<PackageSection>(s))) +
                               "' checksum mismatch"),
        std::string::npos)
        << p.error().message;
  }
  std::string header = bytes;
  header[40] ^= 1;
  EXPECT_NE(open(header).error().message.find("byte 504: header checksum mismatch"),
            std::string::npos);
}

TEST_F(Corrupted, TruncationMagicAndVersionAreRejected) {
  for (std::size_t cut :
       {std::size_t{0}, std::size_t{7}, std::size_t{300}, bytes.size() / 2, bytes.size() - 1}) {
    Result<Package> p = open(bytes.substr(0, cut));
    ASSERT_FALSE(p.ok()) << cut;
    EXPECT_EQ(p.error().kind, ErrorKind::kBadInput);
    EXPECT_EQ(p.error().message.rfind("m.lfp: byte ", 0), 0u) << p.error().message;
  }
  std::string text = bytes;
  text[4] = '\n';  // a text-mode transfer turning CR LF into LF would do this
  EXPECT_NE(open(text).error().message.find("not a lodforge package"), std::string::npos);
  std::string version = bytes;
  reinterpret_cast<PackageHeader*>(version.data())->version = 99;
  reseal(version);
  EXPECT_NE(open(version).error().message.find("package version 99"), std::string::npos);
}

// A forged change to a package and the words its refusal must contain.
struct Case {
  const char* what;
  std::function<void(std::string&)> damage;
  const char* expected;
};

TEST_F(Corrupted, ForgedContentIsCaughtEvenWithValidChecksums) {
  // With checksums recomputed (or not verified), the structure checks still stand between a
  // bad file and an out-of-bounds read.
  const auto& h = header();
  const std::uint64_t ecolAt = h.sections[static_cast<std::uint32_t>(PackageSection::kEcol)].offset;
  const std::uint64_t trianglesAt =
      h.sections[static_cast<std::uint32_t>(PackageSection::kTriangles)].offset;
  const std::uint64_t objectsAt =
      h.sections[static_cast<std::uint32_t>(PackageSection::kObjects)].offset;
  const std::uint64_t mapAt = h.sections[static_cast<std::uint32_t>(PackageSection::kMap)].offset;
  const std::uint64_t assemblyAt =
      h.sections[static_cast<std::uint32_t>(PackageSection::kAssembly)].offset;
  const std::uint64_t materialsAt =
      h.sections[static_cast<std::uint32_t>(PackageSection::kMaterials)].offset;
  const std::uint64_t objectLayersAt =
      h.sections[static_cast<std::uint32_t>(PackageSection::kObjectLayers)].offset;
  ASSERT_GT(h.sections[static_cast<std::uint32_t>(PackageSection::kMaterials)].bytes, 0u);
  const Case cases[] = {
      {"ecol points up",
       [&](std::string& d) {
         const auto& o = *reinterpret_cast<const PackageObject*>(d.data() + objectsAt);
         auto* ecol = reinterpret_cast<std::uint32_t*>(d.data() + ecolAt);
         ecol[o.vertexCount - 1] =
             o.vertexCount - 1;  // the last collapsed vertex pointing at itself
       },
       "breaks the decreasing chains"},
      {"corner out of range",
       [&](std::string& d) {
         *reinterpret_cast<std::uint32_t*>(d.data() + trianglesAt) = 1u << 30;
       },
       "triangle corner"},
      {"object beyond the vertices",
       [&](std::string& d) {
         reinterpret_cast<PackageObject*>(d.data() + objectsAt)->vertexOffset = 1ull << 40;
       },
       "object 0: vertices outside the section"},
      {"q above p",
       [&](std::string& d) {
         auto* o = reinterpret_cast<PackageObject*>(d.data() + objectsAt);
         o->minVertexCount = o->vertexCount + 1;
       },
       "q > p"},
      {"map decreases",
       [&](std::string& d) {
         auto* m = reinterpret_cast<std::uint32_t*>(d.data() + mapAt);
         std::swap(m[0], m[1]);
         m[1] = 0;
       },
       "object 0"},
      {"material past the table",
       [&](std::string& d) {
         reinterpret_cast<PackageAssembly*>(d.data() + assemblyAt)[1].material = 1000;
       },
       "object 1: material 1000 of"},
      {"layer past the table",
       [&](std::string& d) { reinterpret_cast<std::uint32_t*>(d.data() + objectLayersAt)[2] = 7; },
       "object 2: layer 7 of 0"},
      {"path outside the names",
       [&](std::string& d) {
         reinterpret_cast<PackageAssembly*>(d.data() + assemblyAt)->pathLength = 1u << 30;
       },
       "object 0: assembly path outside"},
      {"unknown alpha mode",
       [&](std::string& d) {
         reinterpret_cast<PackageMaterial*>(d.data() + materialsAt)->alphaMode = 7;
       },
       "material 0: alpha mode"},
      {"material name outside the names",
       [&](std::string& d) {
         reinterpret_cast<PackageMaterial*>(d.data() + materialsAt)->nameOffset = 1ull << 40;
       },
       "material 0: name outside"},
      {"section outside the file",
       [&](std::string& d) {
         reinterpret_cast<PackageHeader*>(d.data())
             ->sections[static_cast<std::uint32_t>(PackageSection::kError)]
             .offset = 1ull << 40;
       },
       "section 'error'"},
  };
  for (const Case& c : cases) {
    std::string copy = bytes;
    c.damage(copy);
    reseal(copy);
    for (bool verify : {true, false}) {
      Result<Package> p = open(copy, {.verifyChecksums = verify});
      ASSERT_FALSE(p.ok()) << c.what;
      EXPECT_NE(p.error().message.find(c.expected), std::string::npos)
          << c.what << ": " << p.error().message;
    }
  }
}

TEST(Package, ATexturedModelKeepsItsWedgesMaterialsAndImages) {
  const std::string input = test::dataPath("textured/spider/spider.obj");
  Result<Model> spider = readModel(input);
  ASSERT_TRUE(spider.ok()) << spider.error().message;
  ASSERT_GT(spider->images.size(), 1u);
  test::TempDir dir;
  ASSERT_TRUE(buildPackage(input, dir.file("s.lfp")).ok());
  Result<Package> package = Package::open(dir.file("s.lfp"));
  ASSERT_TRUE(package.ok()) << package.error().message;
  ASSERT_TRUE(package->header().hasUvs());
  // Materials with their textures and wraps, and every image's bytes as the file holds them.
  ASSERT_EQ(package->materialCount(), spider->materials.size());
  for (std::size_t m = 0; m < spider->materials.size(); ++m)
    EXPECT_EQ(package->material(m), spider->materials[m]) << m;
  ASSERT_EQ(package->imageCount(), spider->images.size());
  for (std::size_t k = 0; k < spider->images.size(); ++k) {
    const ImageSource stored = package->image(k);
    EXPECT_EQ(stored.name, spider->images[k].name);
    EXPECT_EQ(stored.format, spider->images[k].format);
    EXPECT_EQ(stored.width, spider->images[k].width);
    const std::string file = test::readFile(spider->images[k].path);
    ASSERT_EQ(stored.bytes.size(), file.size()) << stored.name;
    EXPECT_EQ(std::memcmp(stored.bytes.data(), file.data(), file.size()), 0) << stored.name;
  }
  // Each object's full level holds exactly the input's (position, coordinates) pairs.
  ASSERT_EQ(package->objectCount(), spider->objectCount());
  std::size_t partial = 0;
  for (std::size_t o = 0; o < spider->objectCount(); ++o) {
    std::set<std::array<float, 5>> given, stored;
    const ObjectRecord& r = spider->objects[o];
    for (std::uint32_t v = 0; v < r.vertexCount; ++v) {
      const Vec3f p = spider->positions[r.vertexOffset + v];
      const Vec2f uv = spider->uvs[r.vertexOffset + v];
      given.insert({p.x, p.y, p.z, uv.x, uv.y});
    }
    for (std::uint32_t v = 0; v < package->object(o).vertexCount; ++v) {
      const Vec3f p = package->positions(o)[v];
      const Vec2f uv = package->uvs(o)[v];
      stored.insert({p.x, p.y, p.z, uv.x, uv.y});
    }
    EXPECT_EQ(stored, given) << spider->objectName(o);
    // Some counts are not whole: seam points have several wedges, which leave together.
    const PackageObject& object = package->object(o);
    for (std::uint32_t n = object.minVertexCount; n <= object.vertexCount; ++n)
      partial += package->wholeAt(o, n) != n ? 1u : 0u;
  }
  EXPECT_GT(partial, 0u);
}

TEST_F(Corrupted, ATexturedPackagesWholeCountsImagesAndTexturesAreChecked) {
  ASSERT_TRUE(buildPackage(test::dataPath("textured/spider/spider.obj"), dir.file("t.lfp")).ok());
  bytes = test::readFile(dir.file("t.lfp"));
  ASSERT_TRUE(open(bytes).ok());
  const auto& h = header();
  const auto at = [&](PackageSection s) {
    return h.sections[static_cast<std::uint32_t>(s)].offset;
  };
  // The first object's whole table (any package's), and an object with a count that is not
  // whole (a seam point's wedges), and where that count sits in the table.
  const auto* objects =
      reinterpret_cast<const PackageObject*>(bytes.data() + at(PackageSection::kObjects));
  const auto* whole =
      reinterpret_cast<const std::uint32_t*>(bytes.data() + at(PackageSection::kWhole));
  const auto levelsOf = [](const PackageObject& o) { return o.vertexCount - o.minVertexCount + 1; };
  const std::uint32_t levels = levelsOf(objects[0]), q = objects[0].minVertexCount;
  ASSERT_GE(levels, 3u);
  std::size_t seamed = 0, inside = 0;  // the object, and its first count that is not whole
  for (; seamed < h.objectCount; ++seamed) {
    const PackageObject& o = objects[seamed];
    for (inside = 0; inside < levelsOf(o); ++inside)
      if (whole[o.levelOffset + inside] != o.minVertexCount + inside) break;
    if (inside < levelsOf(o)) break;
  }
  ASSERT_LT(seamed, h.objectCount) << "some object should have a count that is not whole";
  const std::string seamedObject = fmt::format("object {}: whole count", seamed);
  const auto wholeAt = [&](std::string& d) {
    return reinterpret_cast<std::uint32_t*>(d.data() + at(PackageSection::kWhole));
  };
  const Case cases[] = {
      // (The full mesh is whole, so `inside + 1` is a level of the same object.)
      {"a count pointing at one that is not whole",
       [&](std::string& d) {
         const PackageObject& o = objects[seamed];
         wholeAt(d)[o.levelOffset + inside + 1] =
             o.minVertexCount + static_cast<std::uint32_t>(inside);
       },
       seamedObject.c_str()},
      {"whole counts decreasing", [&](std::string& d) { wholeAt(d)[1] = q + 1, wholeAt(d)[2] = q; },
       "object 0: whole count"},
      {"the full mesh not whole",
       [&](std::string& d) { wholeAt(d)[levels - 1] = wholeAt(d)[levels - 2]; },
       "object 0: the full mesh is not a whole count"},
      {"a whole count above its level",
       [&](std::string& d) {
         const auto& o =
             *reinterpret_cast<const PackageObject*>(d.data() + at(PackageSection::kObjects));
         reinterpret_cast<std::uint32_t*>(d.data() + at(PackageSection::kWhole))[0] =
             o.minVertexCount + 1;
       },
       "object 0: whole count"},
      {"image bytes outside the section",
       [&](std::string& d) {
         reinterpret_cast<PackageImage*>(d.data() + at(PackageSection::kImages))->dataBytes = 1ull
                                                                                              << 40;
       },
       "image 0: bytes outside"},
      {"unknown image format",
       [&](std::string& d) {
         reinterpret_cast<PackageImage*>(d.data() + at(PackageSection::kImages))->format = 77;
       },
       "image 0: unknown image format"},
      {"texture past the images",
       [&](std::string& d) {
         reinterpret_cast<PackageMaterial*>(d.data() + at(PackageSection::kMaterials))
             ->baseColorImage = 99;
       },
       "material 0: texture image outside"},
      {"unknown wrap mode",
       [&](std::string& d) {
         reinterpret_cast<PackageMaterial*>(d.data() + at(PackageSection::kMaterials))->wrapT = 9;
       },
       "material 0: a wrap mode"},
  };
  for (const Case& c : cases) {
    std::string copy = bytes;
    c.damage(copy);
    reseal(copy);
    Result<Package> p = open(copy);
    ASSERT_FALSE(p.ok()) << c.what;
    EXPECT_NE(p.error().message.find(c.expected), std::string::npos)
        << c.what << ": " << p.error().message;
  }
}

}  // namespace
}  // namespace lodforge
