#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>

#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/io/mesh/glb_container.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

struct Glb {
  nlohmann::json document;
  std::uint32_t totalLength = 0, jsonLength = 0, binLength = 0;
};

Glb parseGlb(const std::string& bytes) {
  Glb glb;
  std::uint32_t header[5];
  std::memcpy(header, bytes.data(), 20);
  EXPECT_EQ(header[0], 0x46546C67u);
  EXPECT_EQ(header[1], 2u);
  glb.totalLength = header[2];
  glb.jsonLength = header[3];
  glb.document = nlohmann::json::parse(bytes.substr(20, glb.jsonLength));
  if (bytes.size() > 20 + glb.jsonLength)
    std::memcpy(&glb.binLength, bytes.data() + 20 + glb.jsonLength, 4);
  return glb;
}

Model randomModel(std::uint64_t seed, int objects, int verticesPerObject) {
  Random random(seed);
  Model model;
  ModelBuilder builder(model);
  for (int o = 0; o < objects; ++o) {
    builder.beginObject(fmt::format("part-{}", o));
    for (int v = 0; v < verticesPerObject; ++v) {
      builder.addVertex({float(random.uniform(-3, 3)), float(random.uniform(-3, 3)),
                         float(random.uniform(-3, 3))});
      model.normals.push_back(normalizeOr(
          Vec3f{float(random.uniform(-1, 1)), float(random.uniform(-1, 1)), 1}, Vec3f{}));
      model.colors.push_back(
          {std::uint8_t(random.below(256)), 100, std::uint8_t(random.below(256)), 255});
    }
    for (int t = 0; t < verticesPerObject; ++t) {
      const auto a = std::uint32_t(random.below(std::uint64_t(verticesPerObject)));
      builder.addTriangle(a, (a + 1) % std::uint32_t(verticesPerObject),
                          (a + 2) % std::uint32_t(verticesPerObject));
    }
  }
  builder.endObject();
  return model;
}

TEST(GlbWrite, ModelRoundTripsThroughOurReader) {
  Model model = randomModel(1, 4, 30);
  model.origin = {637000, 5106000, 100};  // geo-scale: the root node carries the translation
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(model, dir.file("m.glb")).ok());
  Result<Model> back = readGltf(dir.file("m.glb"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->objectCount(), 4u);
  EXPECT_EQ(back->indices, model.indices);
  EXPECT_EQ(back->colors, model.colors);
  for (std::size_t o = 0; o < 4; ++o) EXPECT_EQ(back->objectName(o), model.objectName(o));
  for (std::size_t v = 0; v < model.vertexCount(); ++v) {
    const Vec3d a = model.origin + toDouble(model.positions[v]),
                b = back->origin + toDouble(back->positions[v]);
    ASSERT_NEAR(a.x, b.x, 1e-6);
    ASSERT_NEAR(a.y, b.y, 1e-6);
    ASSERT_NEAR(a.z, b.z, 1e-6);
    ASSERT_NEAR(dot(back->normals[v], model.normals[v]), 1.0f, 1e-6f);
  }
}

// The container as the reader's rewrites put it together: the JSON padded with spaces, the
// lengths in the header, the chunks after it as given; and what the check refuses, at its byte.
TEST(GlbContainer, AssembledFilesPassTheCheckAndDamagedOnesAreRefusedAtTheirByte) {
  const std::string bin = "abcdefgh";  // 8 bytes: a BIN chunk needs no padding
  const std::array<std::uint32_t, 2> binHead = binChunkHead(bin.size());
  const std::string chunks = std::string(reinterpret_cast<const char*>(binHead.data()), 8) + bin;
  for (const std::string json : {"{}", R"({"asset":{"version":"2.0"}})", "{\"a\":1}"}) {
    const std::string glb = glbWithJson(json, {chunks}, "t.glb").value();
    const auto bytes = std::as_bytes(std::span<const char>(glb));
    std::uint64_t binOffset = 0, binLength = 0;
    ASSERT_TRUE(checkGlbContainer(bytes, "t.glb", binOffset, binLength).ok()) << json;
    const Glb parsed = parseGlb(glb);
    EXPECT_EQ(parsed.totalLength, glb.size());
    EXPECT_EQ(parsed.jsonLength % 4, 0u);
    EXPECT_EQ(parsed.jsonLength, (json.size() + 3) / 4 * 4);
    EXPECT_EQ(glb.substr(20 + json.size(), parsed.jsonLength - json.size()),
              std::string(parsed.jsonLength - json.size(), ' '));
    EXPECT_EQ(binLength, bin.size());
    EXPECT_EQ(glb.substr(binOffset, binLength), bin);
    // A file cut short, whose header still gives the whole length: refused at that length.
    const auto cut = bytes.first(bytes.size() - 1);
    const Status shortened = checkGlbContainer(cut, "t.glb", binOffset, binLength);
    EXPECT_EQ(shortened.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(shortened.error().message.find("byte 8"), std::string::npos)
        << shortened.error().message;
    // The same with the header mended: the BIN chunk runs past the end, at its header's byte.
    std::string mended = glb.substr(0, glb.size() - 1);
    const std::uint32_t length = static_cast<std::uint32_t>(mended.size());
    std::memcpy(mended.data() + 8, &length, 4);
    const Status binCut = checkGlbContainer(std::as_bytes(std::span<const char>(mended)), "t.glb",
                                            binOffset, binLength);
    EXPECT_EQ(binCut.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(
        binCut.error().message.find(fmt::format("byte {}: BIN chunk", 20 + parsed.jsonLength)),
        std::string::npos)
        << binCut.error().message;
  }
  // A rewrite past the 4 GiB a GLB's lengths can say is refused, not wrapped (the chunks' view
  // is never read: its length is refused first).
  const Result<std::string> tooLong =
      glbWithJson("{}", {std::string_view(bin.data(), std::size_t{0xFFFFFFFF})}, "t.glb");
  ASSERT_FALSE(tooLong.ok());
  EXPECT_EQ(tooLong.error().kind, ErrorKind::kLimit);
}

TEST(GlbWrite, LayoutIsAlignedWithBoundsAndTheRightIndexWidth) {
  // One object needs 32-bit indices (70,000 vertices), the others 16-bit.
  Model model = randomModel(2, 2, 100);
  Model big = randomModel(3, 1, 70'000);
  ModelBuilder builder(model);
  builder.beginObject("big");
  model.positions.insert(model.positions.end(), big.positions.begin(), big.positions.end());
  model.normals.insert(model.normals.end(), big.normals.begin(), big.normals.end());
  model.colors.insert(model.colors.end(), big.colors.begin(), big.colors.end());
  model.indices.insert(model.indices.end(), big.indices.begin(), big.indices.end());
  builder.beginObject("empty");  // no triangles: a node without a mesh
  builder.endObject();
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(model, dir.file("m.glb")).ok());
  const std::string bytes = test::readFile(dir.file("m.glb"));
  const Glb glb = parseGlb(bytes);
  EXPECT_EQ(glb.totalLength, bytes.size());
  EXPECT_EQ(glb.jsonLength % 4, 0u);
  EXPECT_EQ(glb.binLength % 4, 0u);
  for (const auto& view : glb.document["bufferViews"])
    EXPECT_EQ(view["byteOffset"].get<std::uint64_t>() % 4, 0u);
  const auto& accessors = glb.document["accessors"];
  const auto& meshes = glb.document["meshes"];
  ASSERT_EQ(meshes.size(), 3u);
  EXPECT_EQ(accessors[meshes[0]["primitives"][0]["indices"].get<int>()]["componentType"], 5123);
  EXPECT_EQ(accessors[meshes[2]["primitives"][0]["indices"].get<int>()]["componentType"], 5125);
  // POSITION min/max are the exact float bounds.
  const auto& position = accessors[meshes[0]["primitives"][0]["attributes"]["POSITION"].get<int>()];
  const Aabb bounds = computeBounds(model.objectPositions(0));
  EXPECT_EQ(position["min"][0].get<float>(), bounds.min.x);
  EXPECT_EQ(position["max"][2].get<float>(), bounds.max.z);
  const auto& nodes = glb.document["nodes"];
  EXPECT_FALSE(nodes[3].contains("mesh"));
  EXPECT_EQ(nodes[3]["name"], "empty");
}

TEST(GlbWrite, MeshoptCompressedViewsDecodeToTheUncompressedBytes) {
  // The glTF validator cannot look inside EXT_meshopt_compression; decode every view here and
  // compare it with the same file written uncompressed.
  test::TempDir dir;
  for (const int vertices : {300, 70'000}) {  // 16- and 32-bit indices
    const Model model = randomModel(11, 1, vertices);
    ASSERT_TRUE(writeGlb(model, dir.file("plain.glb")).ok());
    ASSERT_TRUE(writeGlb(model, dir.file("packed.glb"), {.meshoptCompression = true}).ok());
    const std::string plainBytes = test::readFile(dir.file("plain.glb"));
    const std::string packedBytes = test::readFile(dir.file("packed.glb"));
    EXPECT_LT(packedBytes.size(), plainBytes.size());
    const Glb plain = parseGlb(plainBytes), packed = parseGlb(packedBytes);
    EXPECT_EQ(packed.document["extensionsRequired"][0], "EXT_meshopt_compression");
    const auto& plainViews = plain.document["bufferViews"];
    const auto& packedViews = packed.document["bufferViews"];
    ASSERT_EQ(plainViews.size(), packedViews.size());
    const char* plainBin = plainBytes.data() + 20 + plain.jsonLength + 8;
    const char* packedBin = packedBytes.data() + 20 + packed.jsonLength + 8;
    for (std::size_t v = 0; v < plainViews.size(); ++v) {
      const auto& ext = packedViews[v]["extensions"]["EXT_meshopt_compression"];
      const std::size_t count = ext["count"], stride = ext["byteStride"];
      const std::size_t length = plainViews[v]["byteLength"];
      ASSERT_EQ(count * stride, length);
      std::vector<unsigned char> decoded(length);
      const auto* source =
          reinterpret_cast<const unsigned char*>(packedBin) + ext["byteOffset"].get<std::size_t>();
      const std::size_t sourceLength = ext["byteLength"];
      const int result =
          ext["mode"] == "TRIANGLES"
              ? meshopt_decodeIndexBuffer(decoded.data(), count, stride, source, sourceLength)
              : meshopt_decodeVertexBuffer(decoded.data(), count, stride, source, sourceLength);
      ASSERT_EQ(result, 0) << "view " << v;
      const char* original = plainBin + plainViews[v]["byteOffset"].get<std::size_t>();
      if (ext["mode"] == "ATTRIBUTES") {
        EXPECT_EQ(std::memcmp(decoded.data(), original, length), 0) << "view " << v;
        continue;
      }
      // The index codec may rotate a triangle's corners (winding kept): compare triangles.
      const auto index = [&](const void* base, std::size_t i) -> std::uint32_t {
        std::uint32_t value = 0;
        std::memcpy(&value, static_cast<const char*>(base) + i * stride, stride);
        return value;
      };
      for (std::size_t t = 0; t < count; t += 3) {
        const std::array<std::uint32_t, 3> a = {index(original, t), index(original, t + 1),
                                                index(original, t + 2)};
        const std::array<std::uint32_t, 3> b = {
            index(decoded.data(), t), index(decoded.data(), t + 1), index(decoded.data(), t + 2)};
        const bool same =
            b == a || b == std::array{a[1], a[2], a[0]} || b == std::array{a[2], a[0], a[1]};
        ASSERT_TRUE(same) << "triangle " << t / 3;
      }
    }
  }
}

// The same file rebuilt around a changed JSON document (BIN chunk unchanged).
std::string withDocument(const std::string& bytes, const nlohmann::json& document) {
  const Glb glb = parseGlb(bytes);
  std::string text = document.dump();
  while (text.size() % 4 != 0) text += ' ';
  const std::string rest = bytes.substr(20 + glb.jsonLength);
  const std::uint32_t header[5] = {0x46546C67u, 2, std::uint32_t(20 + text.size() + rest.size()),
                                   std::uint32_t(text.size()), 0x4E4F534Au};
  return std::string(reinterpret_cast<const char*>(header), 20) + text + rest;
}

// Corners of each triangle turned to start at its least index: the index codec may rotate them.
std::vector<std::array<std::uint32_t, 3>> rotatedTriangles(std::span<const std::uint32_t> indices) {
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<std::uint32_t, 3> c = {indices[t], indices[t + 1], indices[t + 2]};
    while (c[0] != std::min({c[0], c[1], c[2]})) c = {c[1], c[2], c[0]};
    triangles.push_back(c);
  }
  return triangles;
}

TEST(GlbRead, MeshoptCompressedFilesReadAsTheUncompressedOnes) {
  // Our reader decodes EXT_meshopt_compression (tinygltf alone refuses the fallback buffer):
  // positions, normals, colours and triangles as the uncompressed file gives them (quantised:
  // QuantizedMeshesReadBackWithinHalfAGridStep; point tiles: the CLI's info test).
  test::TempDir dir;
  const Model model = randomModel(31, 2, 500);
  ASSERT_TRUE(writeGlb(model, dir.file("plain.glb")).ok());
  ASSERT_TRUE(writeGlb(model, dir.file("packed.glb"), {.meshoptCompression = true}).ok());
  Result<Model> plain = readGltf(dir.file("plain.glb"));
  Result<Model> packed = readGltf(dir.file("packed.glb"));
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  ASSERT_TRUE(packed.ok()) << packed.error().message;
  ASSERT_EQ(packed->objectCount(), plain->objectCount());
  EXPECT_EQ(packed->positions, plain->positions);
  EXPECT_EQ(packed->normals, plain->normals);
  EXPECT_EQ(packed->colors, plain->colors);
  for (std::size_t o = 0; o < plain->objectCount(); ++o)
    EXPECT_EQ(rotatedTriangles(packed->objectIndices(o)),
              rotatedTriangles(plain->objectIndices(o)));
}

TEST(GlbRead, AFileThatOnlyNamesTheExtensionIsReadAsItIs) {
  // Nothing compressed, the name in extensionsUsed: not rewritten, read as before.
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(randomModel(6, 1, 50), dir.file("plain.glb")).ok());
  const std::string bytes = test::readFile(dir.file("plain.glb"));
  nlohmann::json document = parseGlb(bytes).document;
  document["extensionsUsed"].push_back("EXT_meshopt_compression");
  Result<Model> plain = readGltfFromMemory(test::bytesOf(bytes), "p.glb");
  Result<Model> named = readGltfFromMemory(test::bytesOf(withDocument(bytes, document)), "n.glb");
  ASSERT_TRUE(plain.ok()) << plain.error().message;
  ASSERT_TRUE(named.ok()) << named.error().message;
  EXPECT_EQ(named->positions, plain->positions);
  EXPECT_EQ(named->indices, plain->indices);
}

TEST(GlbRead, DamagedMeshoptViewsAreBadInputNamingTheView) {
  test::TempDir dir;
  ASSERT_TRUE(
      writeGlb(randomModel(5, 1, 300), dir.file("packed.glb"), {.meshoptCompression = true}).ok());
  const std::string bytes = test::readFile(dir.file("packed.glb"));
  const Glb glb = parseGlb(bytes);
  const auto damaged = [&](const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json document = glb.document;
    change(document["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]);
    const std::string changed = withDocument(bytes, document);
    Result<Model> model = readGltfFromMemory(test::bytesOf(changed), "d.glb");
    EXPECT_FALSE(model.ok());
    return model.ok() ? std::string() : model.error().message;
  };
  // A stream cut short does not decode: named at its byte in the file.
  std::string message =
      damaged([](nlohmann::json& e) { e["byteLength"] = e["byteLength"].get<int>() - 8; });
  EXPECT_NE(message.find("d.glb: byte "), std::string::npos) << message;
  EXPECT_NE(message.find("does not decode"), std::string::npos) << message;
  message = damaged([](nlohmann::json& e) { e["count"] = 100'000'000; });
  EXPECT_NE(message.find("cannot come from"), std::string::npos) << message;
  message = damaged([](nlohmann::json& e) { e["mode"] = "SPARSE"; });
  EXPECT_NE(message.find("bufferViews[0].extensions.EXT_meshopt_compression: unknown mode"),
            std::string::npos)
      << message;
  message = damaged([](nlohmann::json& e) { e["byteStride"] = 6; });
  EXPECT_NE(message.find("byteStride 6"), std::string::npos) << message;
  message = damaged([](nlohmann::json& e) { e["byteOffset"] = 1u << 30; });
  EXPECT_NE(message.find("of the BIN chunk runs past its end"), std::string::npos) << message;
  // Views sharing one stream could decode without end: together they may not pass 64 times
  // the BIN chunk, which no real file does.
  nlohmann::json document = glb.document;
  const nlohmann::json first = document["bufferViews"][0];
  const std::size_t copies = 64 * glb.binLength / (first["byteLength"].get<std::size_t>()) + 2;
  for (std::size_t i = 0; i < copies; ++i) document["bufferViews"].push_back(first);
  Result<Model> shared = readGltfFromMemory(test::bytesOf(withDocument(bytes, document)), "d.glb");
  ASSERT_FALSE(shared.ok());
  EXPECT_NE(shared.error().message.find("more than 64 times the BIN chunk"), std::string::npos)
      << shared.error().message;
  message = damaged([](nlohmann::json& e) { e["byteOffset"] = -8; });
  EXPECT_NE(message.find("byteOffset is not an offset"), std::string::npos) << message;
  // The view around a stream must describe what it decodes to (the extension's MUSTs), and no
  // plain view may read the fallback buffer, which holds no data.
  const auto refused = [&](const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json changed = glb.document;
    change(changed);
    Result<Model> model = readGltfFromMemory(test::bytesOf(withDocument(bytes, changed)), "d.glb");
    EXPECT_FALSE(model.ok());
    return model.ok() ? std::string() : model.error().message;
  };
  message = refused([](nlohmann::json& d) {
    d["bufferViews"][0]["byteStride"] = 16;  // the stream's is 12 or 8
  });
  EXPECT_NE(message.find("bufferViews[0]: byteStride 16 but its"), std::string::npos) << message;
  message = refused([](nlohmann::json& d) { d["bufferViews"][0]["byteLength"] = 4; });
  EXPECT_NE(message.find("bufferViews[0]: byteLength 4 but its"), std::string::npos) << message;
  message = refused([](nlohmann::json& d) {
    nlohmann::json plain = d["bufferViews"][0];
    plain.erase("extensions");
    d["bufferViews"].push_back(plain);
  });
  EXPECT_NE(message.find("which holds no data"), std::string::npos) << message;
  message = refused([](nlohmann::json& d) { d["buffers"][0]["byteLength"] = 1u << 30; });
  EXPECT_NE(message.find("buffer 0 declares 1073741824 bytes but the BIN chunk holds"),
            std::string::npos)
      << message;
  message = damaged([](nlohmann::json& e) { e["filter"] = "OCTAHEDRAL"; });
  EXPECT_NE(message.find("filter OCTAHEDRAL"), std::string::npos) << message;
}

TEST(GlbWrite, QuantizedMeshesReadBackWithinHalfAGridStep) {
  // KHR_mesh_quantization: 16-bit positions on a grid over the mesh's box, 8-bit normals. Read
  // back through our reader (which applies node transforms), every position is within half a
  // step per axis and every normal within a degree; a mesh placed by its own transform keeps it.
  const Model model = randomModel(21, 2, 2'000);
  test::TempDir dir;
  const Mat4d moved = Mat4d::translation({10, -4, 2}) * Mat4d::scale({2, 2, 2});
  const auto write = [&](const std::string& path, bool quantized, bool meshopt) {
    Result<GlbWriter> writer = GlbWriter::create(path, {.meshoptCompression = meshopt});
    ASSERT_TRUE(writer.ok());
    for (std::size_t o = 0; o < 2; ++o) {
      GlbMeshData data;
      data.positions = model.objectPositions(o);
      const ObjectRecord& record = model.objects[o];
      data.normals = std::span(model.normals).subspan(record.vertexOffset, record.vertexCount);
      data.indices = model.objectIndices(o);
      data.quantized = quantized;
      Result<std::uint32_t> mesh = writer->addMesh(data, model.objectName(o));
      ASSERT_TRUE(mesh.ok());
      writer->addNode(model.objectName(o), *mesh, o == 1 ? &moved : nullptr);
    }
    ASSERT_TRUE(writer->finish().ok());
  };
  for (const bool meshopt : {false, true}) {
    const std::string path = dir.file(meshopt ? "packed.glb" : "plain.glb");
    write(path, true, meshopt);
    write(dir.file("float.glb"), false, meshopt);
    const std::string bytes = test::readFile(path);
    const Glb glb = parseGlb(bytes);
    EXPECT_EQ(glb.document["extensionsRequired"].back(), "KHR_mesh_quantization");
    const auto& attributes = glb.document["meshes"][0]["primitives"][0]["attributes"];
    const auto& position = glb.document["accessors"][attributes["POSITION"].get<int>()];
    const auto& normal = glb.document["accessors"][attributes["NORMAL"].get<int>()];
    EXPECT_EQ(position["componentType"], 5123);
    EXPECT_EQ(normal["componentType"], 5120);
    EXPECT_TRUE(normal["normalized"].get<bool>());
    if (!meshopt) {  // padded elements: the views say their stride
      EXPECT_EQ(glb.document["bufferViews"][position["bufferView"].get<int>()]["byteStride"], 8);
      EXPECT_EQ(glb.document["bufferViews"][normal["bufferView"].get<int>()]["byteStride"], 4);
    }
    EXPECT_LT(static_cast<double>(bytes.size()),
              0.75 * static_cast<double>(std::filesystem::file_size(dir.file("float.glb"))));
    Result<Model> back = readGltf(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->objectCount(), 2u);
    if (!meshopt) {
      EXPECT_EQ(back->indices, model.indices);
    }
    for (std::size_t o = 0; o < 2; ++o) {  // the index codec may rotate a triangle's corners
      EXPECT_EQ(rotatedTriangles(back->objectIndices(o)), rotatedTriangles(model.objectIndices(o)));
      const Aabb box = computeBounds(model.objectPositions(o));
      const double step = glbQuantizationStep(Aabbd{toDouble(box.min), toDouble(box.max)});
      const double tolerance = (o == 1 ? 2.0 : 1.0) * (0.5 * step + 1e-5);
      const ObjectRecord& record = model.objects[o];
      for (std::uint32_t v = 0; v < record.vertexCount; ++v) {
        const Vec3d original = toDouble(model.positions[record.vertexOffset + v]);
        const Vec3d want = o == 1 ? moved.transformPoint(original) : original;
        const Vec3d got = back->origin + toDouble(back->positions[record.vertexOffset + v]);
        ASSERT_NEAR(got.x, want.x, tolerance) << "object " << o << " vertex " << v;
        ASSERT_NEAR(got.y, want.y, tolerance);
        ASSERT_NEAR(got.z, want.z, tolerance);
        const Vec3f n = normalizeOr(back->normals[record.vertexOffset + v], Vec3f{});
        ASSERT_GT(dot(n, model.normals[record.vertexOffset + v]), std::cos(1.0 * 3.14159265 / 180));
      }
    }
  }
}

TEST(GlbWrite, PackedNormalsGiveTheBytesTheWriterPacksItself) {
  // Callers that kept glbPackNormal's bytes (point tiles' work records) pass them instead of
  // floats: the file must be the same byte for byte.
  const Model model = randomModel(33, 1, 3'000);
  std::vector<Vec3f> normals = model.normals;
  normals[0] = {0, 0, 0};  // zero and unnormalised normals too
  normals[1] = {3, -4, 12};
  std::vector<std::array<std::int8_t, 4>> packed;
  for (const Vec3f& n : normals) packed.push_back(glbPackNormal(n));
  EXPECT_EQ(packed[0], (std::array<std::int8_t, 4>{0, 0, 127, 0}));     // the fallback, +z
  EXPECT_EQ(packed[1], (std::array<std::int8_t, 4>{29, -39, 117, 0}));  // (3, −4, 12) / 13
  test::TempDir dir;
  const auto write = [&](const std::string& path, bool bytes) {
    Result<GlbWriter> writer = GlbWriter::create(path, {});
    ASSERT_TRUE(writer.ok());
    GlbMeshData data;
    data.positions = model.positions;
    if (bytes)
      data.packedNormals = packed;
    else
      data.normals = normals;
    data.indices = model.indices;
    data.quantized = true;
    Result<std::uint32_t> mesh = writer->addMesh(data, "m");
    ASSERT_TRUE(mesh.ok());
    writer->addNode("m", *mesh, nullptr);
    ASSERT_TRUE(writer->finish().ok());
  };
  write(dir.file("floats.glb"), false);
  write(dir.file("bytes.glb"), true);
  EXPECT_EQ(test::readFile(dir.file("floats.glb")), test::readFile(dir.file("bytes.glb")));
}

TEST(GlbWrite, SpillingToDiskGivesTheSameFile) {
  const Model model = randomModel(4, 20, 500);
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(model, dir.file("memory.glb")).ok());
  GlbWriteOptions spill;
  spill.spillBytes = 4096;
  ASSERT_TRUE(writeGlb(model, dir.file("spilled.glb"), spill).ok());
  EXPECT_EQ(test::readFile(dir.file("memory.glb")), test::readFile(dir.file("spilled.glb")));
  EXPECT_EQ(test::listFolder(dir.path()).size(), 2u);  // the spill file is gone
}

TEST(GlbWrite, InstancedMeshesAndTransforms) {
  test::TempDir dir;
  Result<GlbWriter> writer = GlbWriter::create(dir.file("inst.glb"));
  ASSERT_TRUE(writer.ok());
  const std::vector<Vec3f> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<std::uint32_t> indices = {0, 1, 2};
  const std::uint32_t red = writer->addMaterial({1, 0, 0, 1}, "red");
  Result<std::uint32_t> mesh = writer->addMesh({positions, {}, {}, indices}, "tri", red);
  ASSERT_TRUE(mesh.ok());
  for (int i = 0; i < 3; ++i) {
    const Mat4d place = Mat4d::translation({double(i) * 10, 0, 0});
    writer->addNode(fmt::format("copy {}", i), *mesh, &place);
  }
  ASSERT_TRUE(writer->finish().ok());
  Result<Model> back = readGltf(dir.file("inst.glb"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->objectCount(), 3u);
  EXPECT_EQ(toDouble(back->objectPositions(2)[1]) + back->origin, (Vec3d{21, 0, 0}));
  EXPECT_EQ(back->colors[0], (Rgba8{255, 0, 0, 255}));
  const Glb glb = parseGlb(test::readFile(dir.file("inst.glb")));
  EXPECT_EQ(glb.document["meshes"].size(), 1u);
}

TEST(GlbWrite, RealModelsRoundTrip) {
  test::TempDir dir;
  for (const char* file : {"meshes/horse.ply", "meshes/2CylinderEngine.glb"}) {
    const std::string path = test::dataPath(file);
    Result<Model> model = fileExtension(path) == "ply" ? readPly(path) : readGltf(path);
    ASSERT_TRUE(model.ok()) << model.error().message;
    ASSERT_TRUE(writeGlb(*model, dir.file("copy.glb")).ok());
    Result<Model> back = readGltf(dir.file("copy.glb"));
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->objectCount(), model->objectCount());
    EXPECT_EQ(back->indices, model->indices);
    EXPECT_EQ(back->positions.size(), model->positions.size());
    for (std::size_t v = 0; v < model->vertexCount(); ++v) {
      const Vec3d a = model->origin + toDouble(model->positions[v]),
                  b = back->origin + toDouble(back->positions[v]);
      ASSERT_LT(length(a - b), 1e-4 * (1 + length(a))) << file << " vertex " << v;
    }
  }
}

TEST(GlbWrite, UnwritableDestinationIsAnIoError) {
  const Model model = randomModel(5, 1, 10);
  const Status status = writeGlb(model, "/nonexistent-folder/out.glb");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.kind(), ErrorKind::kIo);
}

}  // namespace
}  // namespace lodforge
