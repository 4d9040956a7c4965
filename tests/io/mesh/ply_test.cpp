#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "test_support.h"

namespace lodforge {
namespace {

// --- a small PLY encoder, independent of the writer under test --------------------------------

struct Prop {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool list = false;
  PlyType countType = PlyType::kUint8;
};
using Values = std::vector<std::vector<double>>;  // per element: per property, a list of values

struct PlySpec {
  PlyFormat format = PlyFormat::kBinaryLittleEndian;
  std::vector<Prop> vertexProps;
  Values vertices;                   // one value per scalar property, in order
  std::string faceElement = "face";  // or "tristrips"
  std::vector<Prop> faceProps;
  std::vector<Values> faces;  // per face: per property, its values (lists have several)
  std::string extraElements;  // appended header text (elements with no data)
};

void encodeValue(std::string& out, PlyFormat format, PlyType type, double value) {
  if (format == PlyFormat::kAscii) {
    if (type == PlyType::kFloat32 || type == PlyType::kFloat64)
      out += fmt::format("{} ", value);
    else
      out += fmt::format("{} ", static_cast<long long>(value));
    return;
  }
  unsigned char bytes[8];
  std::size_t size = plyTypeSize(type);
  switch (type) {
    case PlyType::kInt8: {
      auto v = static_cast<std::int8_t>(value);
      std::memcpy(bytes, &v, 1);
      break;
    }
    case PlyType::kUint8: {
      auto v = static_cast<std::uint8_t>(value);
      std::memcpy(bytes, &v, 1);
      break;
    }
    case PlyType::kInt16: {
      auto v = static_cast<std::int16_t>(value);
      std::memcpy(bytes, &v, 2);
      break;
    }
    case PlyType::kUint16: {
      auto v = static_cast<std::uint16_t>(value);
      std::memcpy(bytes, &v, 2);
      break;
    }
    case PlyType::kInt32: {
      auto v = static_cast<std::int32_t>(value);
      std::memcpy(bytes, &v, 4);
      break;
    }
    case PlyType::kUint32: {
      auto v = static_cast<std::uint32_t>(value);
      std::memcpy(bytes, &v, 4);
      break;
    }
    case PlyType::kFloat32: {
      auto v = static_cast<float>(value);
      std::memcpy(bytes, &v, 4);
      break;
    }
    case PlyType::kFloat64:
      std::memcpy(bytes, &value, 8);
      break;
  }
  if (format == PlyFormat::kBinaryBigEndian) std::reverse(bytes, bytes + size);
  out.append(reinterpret_cast<const char*>(bytes), size);
}

std::string encodePly(const PlySpec& spec) {
  std::string out =
      fmt::format("ply\nformat {} 1.0\ncomment test file\n", plyFormatName(spec.format));
  auto declare = [&](const std::vector<Prop>& props) {
    for (const Prop& p : props) {
      if (p.list)
        out += fmt::format("property list {} {} {}\n", plyTypeName(p.countType),
                           plyTypeName(p.type), p.name);
      else
        out += fmt::format("property {} {}\n", plyTypeName(p.type), p.name);
    }
  };
  out += fmt::format("element vertex {}\n", spec.vertices.size());
  declare(spec.vertexProps);
  if (!spec.faceProps.empty()) {
    out += fmt::format("element {} {}\n", spec.faceElement, spec.faces.size());
    declare(spec.faceProps);
  }
  out += spec.extraElements;
  out += "end_header\n";
  for (const auto& v : spec.vertices) {
    for (std::size_t i = 0; i < spec.vertexProps.size(); ++i)
      encodeValue(out, spec.format, spec.vertexProps[i].type, v[0 + i]);
    if (spec.format == PlyFormat::kAscii) out += "\n";
  }
  for (const Values& face : spec.faces) {
    for (std::size_t i = 0; i < spec.faceProps.size(); ++i) {
      const Prop& p = spec.faceProps[i];
      if (p.list) encodeValue(out, spec.format, p.countType, static_cast<double>(face[i].size()));
      for (double value : face[i]) encodeValue(out, spec.format, p.type, value);
    }
    if (spec.format == PlyFormat::kAscii) out += "\n";
  }
  return out;
}

Result<Model> readPlyText(const std::string& text, const std::string& name = "test.ply") {
  return readPlyFromMemory(test::bytesOf(text), name);
}

// A grid of integer coordinates (3x3 quads unless told) as quads: every PLY type can hold them
// exactly.
PlySpec gridSpec(PlyFormat format, PlyType coordinate, PlyType countType, PlyType indexType,
                 int quadsPerSide = 3) {
  const int side = quadsPerSide + 1;
  PlySpec spec;
  spec.format = format;
  spec.vertexProps = {{"x", coordinate}, {"y", coordinate}, {"z", coordinate}};
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i)
      spec.vertices.push_back({double(i), double(j), double((i + j) % 3)});
  }
  spec.faceProps = {{"vertex_indices", indexType, true, countType}};
  for (int j = 0; j < quadsPerSide; ++j) {
    for (int i = 0; i < quadsPerSide; ++i) {
      const double a = j * side + i;
      spec.faces.push_back({{a, a + 1, a + side + 1, a + side}});
    }
  }
  return spec;
}

TEST(PlyRead, EveryFormatAndScalarTypeGivesTheSameMesh) {
  const PlyType types[] = {PlyType::kInt8,  PlyType::kUint8,  PlyType::kInt16,   PlyType::kUint16,
                           PlyType::kInt32, PlyType::kUint32, PlyType::kFloat32, PlyType::kFloat64};
  const PlyType indexTypes[] = {PlyType::kUint8, PlyType::kInt16, PlyType::kUint16, PlyType::kInt32,
                                PlyType::kUint32};
  for (PlyFormat format :
       {PlyFormat::kAscii, PlyFormat::kBinaryLittleEndian, PlyFormat::kBinaryBigEndian}) {
    for (PlyType coordinate : types) {
      for (PlyType index : indexTypes) {
        const PlySpec spec =
            gridSpec(format, coordinate,
                     index == PlyType::kUint8 ? PlyType::kInt32 : PlyType::kUint8, index);
        Result<Model> model = readPlyText(encodePly(spec));
        ASSERT_TRUE(model.ok()) << model.error().message << " format " << plyFormatName(format)
                                << " type " << plyTypeName(coordinate);
        ASSERT_EQ(model->vertexCount(), 16u);
        ASSERT_EQ(model->triangleCount(), 18u);  // 9 quads, fan-triangulated
        for (std::size_t v = 0; v < 16; ++v) {
          ASSERT_EQ(model->positions[v],
                    (Vec3f{float(v % 4), float(v / 4), float((v % 4 + v / 4) % 3)}));
        }
        // Quad (a, b, c, d) becomes (a, b, c) and (a, c, d): winding kept.
        EXPECT_EQ(std::vector<std::uint32_t>(model->indices.begin(), model->indices.begin() + 6),
                  (std::vector<std::uint32_t>{0, 1, 5, 0, 5, 4}));
      }
    }
  }
}

TEST(PlyRead, AnyPropertyOrderExtraPropertiesAndElementsAreSkippedWithAWarning) {
  for (PlyFormat format : {PlyFormat::kAscii, PlyFormat::kBinaryBigEndian}) {
    // Hand-encoded: shuffled vertex properties (one a list), an unknown element before the faces,
    // and unknown face properties around the index list.
    std::string text;
    {
      text = fmt::format("ply\nformat {} 1.0\nelement vertex 3\n", plyFormatName(format));
      text +=
          "property float confidence\nproperty double z\nproperty list uchar uchar tags\nproperty "
          "float y\nproperty short x\n";
      text += "element edge 1\nproperty int vertex1\nproperty int vertex2\n";
      text +=
          "element face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\nproperty "
          "float quality\n";
      text += "end_header\n";
      const double vertices[3][3] = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
      for (const auto& v : vertices) {
        encodeValue(text, format, PlyType::kFloat32, 0.5);
        encodeValue(text, format, PlyType::kFloat64, v[2]);
        encodeValue(text, format, PlyType::kUint8, 2);
        encodeValue(text, format, PlyType::kUint8, 9);
        encodeValue(text, format, PlyType::kUint8, 9);
        encodeValue(text, format, PlyType::kFloat32, v[1]);
        encodeValue(text, format, PlyType::kInt16, v[0]);
        if (format == PlyFormat::kAscii) text += "\n";
      }
      encodeValue(text, format, PlyType::kInt32, 0);
      encodeValue(text, format, PlyType::kInt32, 1);
      if (format == PlyFormat::kAscii) text += "\n";
      encodeValue(text, format, PlyType::kUint8, 7);
      encodeValue(text, format, PlyType::kUint8, 3);
      for (double i : {2.0, 1.0, 0.0}) encodeValue(text, format, PlyType::kInt32, i);
      encodeValue(text, format, PlyType::kFloat32, 0.25);
      if (format == PlyFormat::kAscii) text += "\n";
    }
    std::vector<std::string> warnings;
    PlyReadOptions options;
    options.warnings = &warnings;
    Result<Model> model = readPlyFromMemory(test::bytesOf(text), "test.ply", options);
    ASSERT_TRUE(model.ok()) << model.error().message;
    ASSERT_EQ(model->vertexCount(), 3u);
    EXPECT_EQ(model->positions[1], (Vec3f{4, 5, 6}));
    EXPECT_EQ(model->indices, (std::vector<std::uint32_t>{2, 1, 0}));
    // The skipped element is named, not dropped in silence.
    EXPECT_EQ(warnings, (std::vector<std::string>{"test.ply: element not read: 'edge' (1)"}));
  }
}

// With readExtras, the vertex's other scalar properties come packed in their own types (lists
// and the properties lodforge reads itself left out).
TEST(PlyRead, OtherVertexPropertiesComeAsExtraFields) {
  const std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property uchar label\nproperty float y\nproperty list uchar int ring\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "property short segment_index\nproperty double psz\nend_header\n";
  std::string body;
  const auto be = [&body](auto v) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    std::reverse(b, b + sizeof v);
    body.append(b, sizeof v);
  };
  for (int i = 0; i < 2; ++i) {
    be(1.0f * float(i));
    be(static_cast<std::uint8_t>(200 + i));
    be(2.0f);
    be(static_cast<std::uint8_t>(1));
    be(std::int32_t{7});
    be(3.0f);
    be(0.0f), be(0.0f), be(1.0f);
    be(static_cast<std::int16_t>(-300 - i));
    be(0.125 * i);
  }
  PlyReadOptions options;
  options.readExtras = true;
  const std::string file = ply + body;  // the reader reads it in place
  Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(file), "x.ply", options);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  const PointExtras& extras = reader->header().extras;
  ASSERT_EQ(extras.fields.size(), 3u);
  EXPECT_EQ(extras.stride, 11u);
  EXPECT_EQ(extras.fields[0].name, "label");
  EXPECT_EQ(extras.fields[0].type, ExtraType::kUint8);
  EXPECT_EQ(extras.fields[1].name, "segment_index");
  EXPECT_EQ(extras.fields[1].offset, 1u);
  EXPECT_EQ(extras.fields[2].type, ExtraType::kFloat64);
  PlyBatch batch;
  ASSERT_TRUE(*reader->next(batch));
  ASSERT_EQ(batch.extras.size(), 22u);
  for (std::size_t i = 0; i < 2; ++i) {
    const std::byte* e = batch.extras.data() + 11 * i;
    EXPECT_EQ(extraRaw(e, extras.fields[0]), 200.0 + double(i));
    EXPECT_EQ(extraRaw(e, extras.fields[1]), -300.0 - double(i));
    EXPECT_EQ(extraRaw(e, extras.fields[2]), 0.125 * double(i));
  }
  // An ascii value that does not fit its property's type is bad input, with its vertex.
  options.readExtras = true;
  const std::string wideFile =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar label\nend_header\n0 0 0 7\n1 1 1 300\n";
  Result<PlyReader> wide = PlyReader::fromMemory(test::bytesOf(wideFile), "w.ply", options);
  ASSERT_TRUE(wide.ok()) << wide.error().message;
  Result<bool> bad = wide->next(batch);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("vertex 1: 300 does not fit property 'label' (uint8)"),
            std::string::npos)
      << bad.error().message;
  // Without the option (meshes), nothing is packed.
  Result<PlyReader> plain = PlyReader::fromMemory(test::bytesOf(file), "x.ply");
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->header().extras.fields.empty());
}

TEST(PlyRead, ColoursFromEveryChannelType) {
  struct Case {
    PlyType type;
    double value;
    std::uint8_t expected;
  };
  for (const Case& c : {Case{PlyType::kUint8, 200, 200}, Case{PlyType::kUint16, 65535, 255},
                        Case{PlyType::kUint16, 32896, 128}, Case{PlyType::kFloat32, 0.5, 128},
                        Case{PlyType::kFloat64, 1.0, 255}}) {
    PlySpec spec;
    spec.vertexProps = {{"x"}, {"y"}, {"z"}, {"red", c.type}, {"green", c.type}, {"blue", c.type}};
    spec.vertices = {{0, 0, 0, c.value, c.value, 0}};
    Result<Model> model = readPlyText(encodePly(spec));
    ASSERT_TRUE(model.ok()) << model.error().message;
    ASSERT_TRUE(model->hasColors());
    EXPECT_EQ(model->colors[0], (Rgba8{c.expected, c.expected, 0, 255})) << plyTypeName(c.type);
  }
}

TEST(PlyRead, ObjectIdsSplitFacesIntoSelfContainedObjects) {
  PlySpec spec =
      gridSpec(PlyFormat::kBinaryLittleEndian, PlyType::kFloat32, PlyType::kUint8, PlyType::kInt32);
  spec.faceProps.push_back({"object_id", PlyType::kUint32});
  // Quads alternate between objects 7 and 3: vertices on shared edges appear in both.
  for (std::size_t f = 0; f < spec.faces.size(); ++f) spec.faces[f].push_back({f % 2 ? 3.0 : 7.0});
  Result<Model> model = readPlyText(encodePly(spec));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->objectName(0), "object 3");
  EXPECT_EQ(model->objectName(1), "object 7");
  EXPECT_EQ(model->objects[0].triangleCount, 8u);
  EXPECT_EQ(model->objects[1].triangleCount, 10u);
  EXPECT_TRUE(isConsistent(*model));
  // Every object's triangles keep their original corner positions.
  for (std::size_t o = 0; o < 2; ++o) {
    const auto positions = model->objectPositions(o);
    for (std::uint32_t i : model->objectIndices(o)) ASSERT_LT(i, positions.size());
  }
  // Checkerboard: object 3 has 4 quads touching 12 grid points, object 7 has 5 touching 16.
  EXPECT_EQ(model->objects[0].vertexCount, 12u);
  EXPECT_EQ(model->objects[1].vertexCount, 16u);
}

TEST(PlyRead, StreamingBatchesAddUpToTheWholeFile) {
  Random random(4);
  PlySpec spec;
  spec.vertexProps = {{"x"}, {"y"}, {"z"}, {"nx"}, {"ny"}, {"nz"}};
  for (int v = 0; v < 1000; ++v) {
    spec.vertices.push_back(
        {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1), 0, 0, 1});
  }
  spec.faceProps = {{"vertex_indices", PlyType::kUint32, true}};
  for (int f = 0; f < 777; ++f) {
    spec.faces.push_back(
        {{double(random.below(1000)), double(random.below(1000)), double(random.below(1000))}});
  }
  const std::string text = encodePly(spec);
  PlyReadOptions options;
  options.batchSize = 64;
  Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(text), "stream.ply", options);
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->header().hasNormals);
  std::uint64_t vertices = 0, faces = 0, batches = 0;
  PlyBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    ASSERT_TRUE(more.ok()) << more.error().message;
    if (!*more) break;
    ++batches;
    if (batch.kind == PlyBatch::Kind::kVertices) {
      ASSERT_EQ(batch.first, vertices);
      ASSERT_LE(batch.count, 64u);
      for (std::size_t i = 0; i < batch.positions.size(); ++i) {
        ASSERT_EQ(toFloat(batch.positions[i]),
                  toFloat(Vec3d{spec.vertices[vertices + i][0], spec.vertices[vertices + i][1],
                                spec.vertices[vertices + i][2]}));
      }
      vertices += batch.count;
    } else {
      ASSERT_EQ(batch.first, faces);
      for (std::size_t i = 0; i < batch.count; ++i) {
        ASSERT_EQ(batch.triangles[3 * i], spec.faces[faces + i][0][0]);
      }
      faces += batch.count;
    }
  }
  EXPECT_EQ(vertices, 1000u);
  EXPECT_EQ(faces, 777u);
  EXPECT_EQ(batches, 16u + 13u);
}

// What a slice delivers: its batches' positions or first corners, and the indices they start at.
struct SliceRead {
  std::vector<Vec3d> positions;
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint64_t> firsts;
};
Result<SliceRead> readSlice(const std::string& text, PlySlice vertices, PlySlice faces,
                            bool readVertices) {
  PlyReadOptions options;
  options.batchSize = 50;
  options.readVertices = readVertices;
  options.readFaces = !readVertices;
  options.vertexSlice = vertices;
  options.faceSlice = faces;
  Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(text), "slice.ply", options);
  if (!reader) return reader.status();
  SliceRead read;
  PlyBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) return read;
    read.firsts.push_back(batch.first);
    read.positions.insert(read.positions.end(), batch.positions.begin(), batch.positions.end());
    read.triangles.insert(read.triangles.end(), batch.triangles.begin(), batch.triangles.end());
  }
}

// A distributed job's ranks read slices of one binary PLY: together they deliver exactly what
// one whole read does, each from its own first index; what cannot be found by seeking (faces of
// another size, ascii) is refused as unsupported, never read wrong.
TEST(PlyRead, SlicesOfVerticesAndFacesAddUpToTheWholeFile) {
  Random random(9);
  PlySpec spec;
  spec.vertexProps = {{"x"}, {"y"}, {"z"}, {"nx"}, {"ny"}, {"nz"}};
  for (int v = 0; v < 1000; ++v)
    spec.vertices.push_back(
        {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1), 0, 0, 1});
  spec.faceProps = {{"vertex_indices", PlyType::kInt32, true}, {"quality", PlyType::kFloat32}};
  for (int f = 0; f < 777; ++f)
    spec.faces.push_back(
        {{double(random.below(1000)), double(random.below(1000)), double(random.below(1000))},
         {0.5}});
  const std::string text = encodePly(spec);
  Result<SliceRead> whole = readSlice(text, {}, {}, true);
  Result<SliceRead> wholeFaces = readSlice(text, {}, {}, false);
  ASSERT_TRUE(whole.ok() && wholeFaces.ok());
  ASSERT_EQ(whole->positions.size(), 1000u);
  ASSERT_EQ(wholeFaces->triangles.size(), 3 * 777u);
  for (std::uint64_t parts : {2u, 3u, 7u}) {
    SliceRead joined, joinedFaces;
    for (std::uint64_t r = 0; r < parts; ++r) {
      const PlySlice vertices{1000 * r / parts, 1000 * (r + 1) / parts - 1000 * r / parts};
      const PlySlice faces{777 * r / parts, 777 * (r + 1) / parts - 777 * r / parts};
      Result<SliceRead> v = readSlice(text, vertices, {}, true);
      Result<SliceRead> f = readSlice(text, {}, faces, false);
      ASSERT_TRUE(v.ok()) << v.status().message();
      ASSERT_TRUE(f.ok()) << f.status().message();
      EXPECT_EQ(v->firsts.front(), vertices.first);
      EXPECT_EQ(f->firsts.front(), faces.first);
      joined.positions.insert(joined.positions.end(), v->positions.begin(), v->positions.end());
      joinedFaces.triangles.insert(joinedFaces.triangles.end(), f->triangles.begin(),
                                   f->triangles.end());
    }
    EXPECT_EQ(joined.positions, whole->positions) << parts << " slices";
    EXPECT_EQ(joinedFaces.triangles, wholeFaces->triangles) << parts << " slices";
  }
  Result<SliceRead> past = readSlice(text, {}, {800, 100}, false);
  ASSERT_TRUE(past.ok());
  EXPECT_TRUE(past->triangles.empty()) << "a slice past the last face is empty";

  // A quad among the triangles: a slice that holds it is refused, one before it is not.
  spec.faces[500][0].push_back(3);
  const std::string mixed = encodePly(spec);
  Result<SliceRead> before = readSlice(mixed, {}, {0, 500}, false);
  EXPECT_TRUE(before.ok());
  Result<SliceRead> over = readSlice(mixed, {}, {400, 200}, false);
  ASSERT_FALSE(over.ok());
  EXPECT_EQ(over.status().kind(), ErrorKind::kUnsupported);
  EXPECT_NE(over.status().message().find("face 500"), std::string::npos) << over.status().message();
  spec.format = PlyFormat::kAscii;
  Result<SliceRead> ascii = readSlice(encodePly(spec), {10, 10}, {}, true);
  ASSERT_FALSE(ascii.ok());
  EXPECT_EQ(ascii.status().kind(), ErrorKind::kUnsupported);
}

TEST(PlyRoundTrip, WriterOutputReadsBackExactly) {
  Random random(12);
  Model model;
  ModelBuilder builder(model);
  for (int o = 0; o < 3; ++o) {
    builder.beginObject(fmt::format("part {}", o));
    for (int v = 0; v < 50; ++v) {
      builder.addVertex({float(random.uniform(-10, 10)), float(random.uniform(-10, 10)),
                         float(random.uniform(-10, 10))});
      model.normals.push_back(
          normalizeOr(Vec3f{float(random.uniform(-1, 1)), 1, 0}, Vec3f{0, 0, 1}));
      model.colors.push_back(
          {std::uint8_t(random.below(256)), std::uint8_t(random.below(256)), 7, 255});
    }
    for (int t = 0; t < 40; ++t) {
      builder.addTriangle(std::uint32_t(random.below(50)), std::uint32_t(random.below(50)),
                          std::uint32_t(random.below(50)));
    }
  }
  builder.endObject();
  test::TempDir dir;
  const std::string path = dir.file("round.ply");
  ASSERT_TRUE(writePly(model, path).ok());
  Result<Model> back = readPly(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->objectCount(), 3u);
  // Objects come back in id order with their own vertices; unused vertices are not kept.
  for (std::size_t o = 0; o < 3; ++o) {
    const auto original = model.objectIndices(o);
    const auto read = back->objectIndices(o);
    ASSERT_EQ(original.size(), read.size());
    for (std::size_t i = 0; i < read.size(); ++i) {
      const std::uint64_t a = model.objects[o].vertexOffset + original[i];
      const std::uint64_t b = back->objects[o].vertexOffset + read[i];
      ASSERT_EQ(model.positions[a], back->positions[b]);
      ASSERT_EQ(model.normals[a], back->normals[b]);
      ASSERT_EQ(model.colors[a], back->colors[b]);
    }
  }
}

TEST(PlyRoundTrip, GeoScaleCoordinatesKeepMillimetres) {
  Model model;
  model.origin = {637512.0, 5106512.0, 150.0};
  ModelBuilder builder(model);
  builder.beginObject("terrain");
  for (Vec3f p : {Vec3f{0.001f, 0, 0}, Vec3f{1000.25f, 0.5f, 1}, Vec3f{0, 800.125f, -3}})
    builder.addVertex(p);
  builder.addTriangle(0, 1, 2);
  builder.endObject();
  test::TempDir dir;
  ASSERT_TRUE(writePly(model, dir.file("utm.ply")).ok());
  Result<PlyReader> reader = PlyReader::open(dir.file("utm.ply"));
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->header().doublePositions);
  Result<Model> back = readPly(dir.file("utm.ply"));
  ASSERT_TRUE(back.ok());
  for (std::size_t v = 0; v < 3; ++v) {
    const Vec3d a = model.origin + toDouble(model.positions[v]);
    const Vec3d b = back->origin + toDouble(back->positions[v]);
    EXPECT_NEAR(a.x, b.x, 1e-3);
    EXPECT_NEAR(a.y, b.y, 1e-3);
    EXPECT_NEAR(a.z, b.z, 1e-3);
  }
}

TEST(PlyRealFiles, HorseRoundTripsAndDamagedPondIsRefused) {
  Result<Model> horse = readPly(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(horse.ok()) << horse.error().message;
  EXPECT_EQ(horse->vertexCount(), 48'485u);
  EXPECT_EQ(horse->triangleCount(), 96'966u);
  EXPECT_TRUE(horse->hasNormals());
  std::vector<std::uint32_t> labels(horse->triangleCount());
  EXPECT_EQ(connectedComponents(std::uint32_t(horse->vertexCount()), horse->indices, labels), 1u);

  // pond.0.ply is damaged: it declares 70,051 points of 31 bytes but holds 2,171,512 bytes of
  // data (room for 70,048), and from point 692 on the records are garbage (coordinates of
  // 1e15, NaN normals). Strict reading refuses the size; salvaging stops at the first NaN.
  Result<Model> strict = readPly(test::dataPath("points/pond.0.ply"));
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(strict.error().message.find("room for 70048 at most): the file is truncated"),
            std::string::npos)
      << strict.error().message;
  PlyReadOptions salvage;
  salvage.salvageTruncated = true;
  Result<Model> damaged = readPly(test::dataPath("points/pond.0.ply"), salvage);
  ASSERT_FALSE(damaged.ok());
  EXPECT_NE(damaged.error().message.find("byte 21728: vertex 692: normal is not finite"),
            std::string::npos)
      << damaged.error().message;

  test::TempDir dir;
  for (const Model* model : {&horse.value()}) {
    ASSERT_TRUE(writePly(*model, dir.file("copy.ply")).ok());
    Result<Model> back = readPly(dir.file("copy.ply"));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->positions, model->positions);
    EXPECT_EQ(back->normals, model->normals);
    EXPECT_EQ(back->colors, model->colors);
    EXPECT_EQ(back->indices, model->indices);
  }
}

TEST(PlySalvage, TruncatedFacesKeepTheCompleteOnes) {
  PlySpec spec =
      gridSpec(PlyFormat::kBinaryLittleEndian, PlyType::kFloat32, PlyType::kUint8, PlyType::kInt32);
  const std::string whole = encodePly(spec);
  const std::string cut = whole.substr(0, whole.size() - 10);  // inside the last quad
  PlyReadOptions options;
  EXPECT_FALSE(readPlyFromMemory(test::bytesOf(cut), "cut.ply", options).ok());
  options.salvageTruncated = true;
  Result<Model> model = readPlyFromMemory(test::bytesOf(cut), "cut.ply", options);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 16u);
  EXPECT_EQ(model->triangleCount(), 16u);  // 8 complete quads
}

// A vertex pass told to stop after the vertices does not read the faces at all (a face list has
// no fixed size to seek over): it ends cleanly even where the faces are cut short, which a pass
// that skips them reads into and reports.
TEST(PlyRead, AVertexPassThatStopsAfterTheVerticesNeverReadsTheFaces) {
  PlySpec spec =
      gridSpec(PlyFormat::kBinaryLittleEndian, PlyType::kFloat32, PlyType::kUint8, PlyType::kInt32);
  const std::string whole = encodePly(spec);
  const std::string cut = whole.substr(0, whole.size() - 10);  // inside the last quad
  const auto vertexPass = [&](bool stop) -> Result<std::uint64_t> {
    PlyReadOptions options;
    options.readFaces = false;
    options.stopAfterDelivered = stop;
    Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(cut), "cut.ply", options);
    if (!reader) return reader.status();
    PlyBatch batch;
    std::uint64_t vertices = 0;
    while (true) {
      Result<bool> more = reader->next(batch);
      if (!more) return more.status();
      if (!*more) return vertices;
      EXPECT_EQ(batch.kind, PlyBatch::Kind::kVertices);
      vertices += batch.count;
    }
  };
  EXPECT_FALSE(vertexPass(false).ok());  // skipping the faces runs into the cut
  Result<std::uint64_t> stopped = vertexPass(true);
  ASSERT_TRUE(stopped.ok()) << stopped.error().message;
  EXPECT_EQ(*stopped, 16u);
}

// --- triangle strips ------------------------------------------------------------------------

// gridSpec's 4x4 quads as two triangle strips: quad rows 0 and 1 in one strip with a restart
// (-1) between them, rows 2 and 3 in the other, joined by repeating the last index of row 2 and
// the first of row 3 (four degenerate triangles).
PlySpec stripSpec(PlyFormat format, PlyType countType, PlyType indexType) {
  PlySpec spec = gridSpec(format, PlyType::kFloat32, countType, indexType, 4);
  constexpr int kSide = 5;
  const double restart = indexType == PlyType::kUint32 ? 4294967295.0 : -1.0;  // -1 as a uint
  const auto row = [](int j) {
    std::vector<double> indices;
    for (int i = 0; i < kSide; ++i)
      indices.insert(indices.end(), {double((j + 1) * kSide + i), double(j * kSide + i)});
    return indices;
  };
  std::vector<double> first = row(0), second = row(2);
  const std::vector<double> row1 = row(1), row3 = row(3);
  first.push_back(restart);
  first.insert(first.end(), row1.begin(), row1.end());
  second.insert(second.end(), {second.back(), row3.front()});
  second.insert(second.end(), row3.begin(), row3.end());
  spec.faceElement = "tristrips";
  spec.faces = {{first}, {second}};
  return spec;
}

// Triangles with their winding, each turned to start at its smallest index.
std::multiset<std::array<std::uint32_t, 3>> orientedTriangles(
    const std::vector<std::uint32_t>& indices) {
  std::multiset<std::array<std::uint32_t, 3>> out;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<std::uint32_t, 3> corners = {indices[t], indices[t + 1], indices[t + 2]};
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    out.insert(corners);
  }
  return out;
}

TEST(PlyStrips, ReadAsTheTrianglesOfTheSameMeshAsFacesFacingTheSameWay) {
  Result<Model> faces = readPlyText(encodePly(
      gridSpec(PlyFormat::kAscii, PlyType::kFloat32, PlyType::kUint8, PlyType::kInt32, 4)));
  ASSERT_TRUE(faces.ok()) << faces.error().message;
  ASSERT_EQ(faces->triangleCount(), 32u);
  const std::pair<PlyType, PlyType> listTypes[] = {{PlyType::kUint8, PlyType::kInt32},
                                                   {PlyType::kInt32, PlyType::kInt32},
                                                   {PlyType::kUint8, PlyType::kUint32},
                                                   {PlyType::kInt32, PlyType::kUint32}};
  for (PlyFormat format :
       {PlyFormat::kAscii, PlyFormat::kBinaryLittleEndian, PlyFormat::kBinaryBigEndian}) {
    for (const auto& [countType, indexType] : listTypes) {
      const std::string what = fmt::format("{}, list {} {}", plyFormatName(format),
                                           plyTypeName(countType), plyTypeName(indexType));
      Result<Model> strips = readPlyText(encodePly(stripSpec(format, countType, indexType)));
      ASSERT_TRUE(strips.ok()) << strips.error().message << " (" << what << ")";
      EXPECT_EQ(strips->objectCount(), 1u) << what;
      EXPECT_EQ(strips->positions, faces->positions) << what;
      // Restarted and joined: 2 x 16 triangles, the join's 4 degenerate ones dropped.
      ASSERT_EQ(strips->triangleCount(), 32u) << what;
      EXPECT_EQ(orientedTriangles(strips->indices), orientedTriangles(faces->indices)) << what;
      // A height field over x and y, seen from above: every triangle faces up.
      const auto& p = strips->positions;
      const auto& i = strips->indices;
      for (std::size_t t = 0; t < i.size(); t += 3)
        ASSERT_GT(cross(p[i[t + 1]] - p[i[t]], p[i[t + 2]] - p[i[t]]).z, 0.0f) << what;
    }
  }
}

TEST(PlyStrips, HeaderCountsTheirTrianglesAndBatchesStreamThem) {
  const std::string text =
      encodePly(stripSpec(PlyFormat::kBinaryBigEndian, PlyType::kUint8, PlyType::kInt32));
  Result<Model> whole = readPlyText(text);
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  // Every reader's header counts them, also one for vertices only (a tileset's first pass): a
  // strip file is a mesh, not a point cloud.
  PlyReadOptions verticesOnly;
  verticesOnly.readFaces = false;
  Result<PlyReader> vertices = PlyReader::fromMemory(test::bytesOf(text), "s.ply", verticesOnly);
  ASSERT_TRUE(vertices.ok()) << vertices.error().message;
  EXPECT_EQ(vertices->header().faceCount, 32u);
  EXPECT_EQ(vertices->header().stripCount, 2u);
  PlyBatch batch;
  std::uint64_t vertexCount = 0;
  while (true) {
    Result<bool> more = vertices->next(batch);
    ASSERT_TRUE(more.ok()) << more.error().message;
    if (!*more) break;
    ASSERT_EQ(batch.kind, PlyBatch::Kind::kVertices);
    vertexCount += batch.count;
  }
  EXPECT_EQ(vertexCount, 25u);

  // Batches of 5 triangles: strips go on from one batch to the next.
  PlyReadOptions options;
  options.batchSize = 5;
  Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(text), "s.ply", options);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  std::vector<std::uint32_t> triangles;
  std::uint64_t faceBatches = 0;
  while (true) {
    Result<bool> more = reader->next(batch);
    ASSERT_TRUE(more.ok()) << more.error().message;
    if (!*more) break;
    if (batch.kind != PlyBatch::Kind::kFaces) continue;
    ++faceBatches;
    ASSERT_EQ(batch.first, triangles.size() / 3);
    ASSERT_EQ(batch.count * 3, batch.triangles.size());
    ASSERT_LE(batch.count, 5u);
    triangles.insert(triangles.end(), batch.triangles.begin(), batch.triangles.end());
  }
  EXPECT_EQ(triangles, whole->indices);
  EXPECT_EQ(faceBatches, 7u);  // 32 triangles
}

TEST(PlyStrips, ACutStripIsRefusedOrSalvagedUpToItsLastWholeTriangle) {
  for (PlyFormat format : {PlyFormat::kBinaryLittleEndian, PlyFormat::kAscii}) {
    const std::string whole = encodePly(stripSpec(format, PlyType::kUint8, PlyType::kInt32));
    // The second strip loses its last 7 indices (in binary the cut splits the first of them):
    // 9 of its 16 triangles are whole.
    const std::string cut = format == PlyFormat::kAscii
                                ? whole.substr(0, whole.rfind("16 22 17 23 18 24 19 \n"))
                                : whole.substr(0, whole.size() - 4 * 7 + 2);
    Result<Model> strict = readPlyText(cut, "cut.ply");
    ASSERT_FALSE(strict.ok());
    EXPECT_EQ(strict.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(strict.error().message.find("tristrips 1"), std::string::npos)
        << strict.error().message;
    std::vector<std::string> warnings;
    PlyReadOptions options;
    options.salvageTruncated = true;
    options.warnings = &warnings;
    Result<Model> salvaged = readPlyFromMemory(test::bytesOf(cut), "cut.ply", options);
    ASSERT_TRUE(salvaged.ok()) << salvaged.error().message;
    ASSERT_EQ(salvaged->triangleCount(), 25u) << plyFormatName(format);
    Result<Model> full = readPlyText(whole);
    ASSERT_TRUE(full.ok());
    EXPECT_TRUE(
        std::equal(salvaged->indices.begin(), salvaged->indices.end(), full->indices.begin()));
    EXPECT_EQ(warnings.size(), 1u);
  }
}

TEST(PlyStrips, ReadBesideFacesAndOtherPropertiesButNotBesideObjectIds) {
  // Faces, then strips whose index list sits between two other properties.
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n{}"
      "element tristrips 2\nproperty uchar flags\nproperty list int int vertex_indices\n"
      "property float quality\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
  const std::string text =
      fmt::format(fmt::runtime(header), "") + "3 0 1 2\n7 4 1 3 0 2 0.5\n1 0 0.25\n";
  Result<PlyReader> reader = PlyReader::fromMemory(test::bytesOf(text), "both.ply");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_EQ(reader->header().faceCount, 3u);  // 1 face and 2 strip triangles
  Result<Model> model = readPlyText(text);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 0, 0, 3, 2}));

  // Strips carry no object id: beside faces that do, their triangles would have no object.
  const std::string ids = fmt::format(fmt::runtime(header), "property int object_id\n") +
                          "3 0 1 2 7\n7 4 1 3 0 2 0.5\n1 0 0.25\n";
  model = readPlyText(ids);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().kind, ErrorKind::kUnsupported);
  EXPECT_NE(model.error().message.find("object ids and 'tristrips'"), std::string::npos)
      << model.error().message;
}

// --- bad input ------------------------------------------------------------------------------

struct BadCase {
  const char* name;
  std::string text;
  std::string expected;  // part of the message
};

std::string binaryHeader(std::uint64_t vertices, std::uint64_t faces) {
  return fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float "
      "y\nproperty float z\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      vertices, faces);
}

std::string floats(std::initializer_list<float> values) {
  std::string out;
  for (float v : values) out.append(reinterpret_cast<const char*>(&v), 4);
  return out;
}

std::string face(std::initializer_list<std::int32_t> indices) {
  std::string out(1, char(indices.size()));
  for (std::int32_t i : indices) out.append(reinterpret_cast<const char*>(&i), 4);
  return out;
}

// Three vertices and one strip, binary little-endian or ascii, with the strip's list types.
std::string stripHeader(PlyFormat format, std::string_view listTypes = "int int") {
  return fmt::format(
      "ply\nformat {} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
      "z\nelement tristrips 1\nproperty list {} vertex_indices\nend_header\n",
      plyFormatName(format), listTypes);
}

// A binary strip: an int length, int indices.
std::string strip(std::initializer_list<std::int32_t> indices) {
  const auto length = static_cast<std::int32_t>(indices.size());
  std::string out(reinterpret_cast<const char*>(&length), 4);
  for (std::int32_t i : indices) out.append(reinterpret_cast<const char*>(&i), 4);
  return out;
}

TEST(PlyBadInput, EveryMalformationIsABadInputErrorWithAPosition) {
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
      "z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string nan = std::string(1, '\0') + floats({std::numeric_limits<float>::quiet_NaN()});
  const std::string binaryStrip =
      stripHeader(PlyFormat::kBinaryLittleEndian) + floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const std::string asciiStrip = stripHeader(PlyFormat::kAscii) + "0 0 0\n1 0 0\n0 1 0\n";
  const BadCase cases[] = {
      {"wrong magic", "plx\nformat ascii 1.0\n", "byte 0: not a PLY file"},
      {"empty", "", "not a PLY file"},
      {"unknown format", "ply\nformat binary_middle_endian 1.0\nend_header\n",
       ":2: unknown format"},
      {"bad version", "ply\nformat ascii 2.0\nend_header\n", "unsupported version"},
      {"no end_header", "ply\nformat ascii 1.0\nelement vertex 1\n", "no 'end_header'"},
      {"property before element", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
       "property before any element"},
      {"unknown type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
       "unknown type"},
      {"bad count", "ply\nformat ascii 1.0\nelement vertex many\nend_header\n",
       "not a whole number"},
      {"no xyz", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
       "lacks x, y or z"},
      {"no vertex element",
       "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int "
       "vertex_indices\nend_header\n",
       "no 'vertex' element"},
      {"huge count", binaryHeader(1'000'000'000'000ull, 0),
       "header declares 1000000000000 'vertex' elements"},
      {"truncated vertices", binaryHeader(3, 0) + floats({0, 0, 0, 1, 0}),
       "only 20 bytes follow the header"},
      {"truncated face list",
       binaryHeader(3, 2) + floats({0, 0, 0, 1, 0, 0, 0, 1, 0}) + face({0, 1, 2}) +
           std::string(3, '\1'),
       "face 1: list 'vertex_indices' claims 1 items"},
      {"truncated face index",
       binaryHeader(3, 2) + floats({0, 0, 0, 1, 0, 0, 0, 1, 0}) + face({0, 1, 2}) + "\2" +
           std::string(6, '\0'),
       "face 1: list 'vertex_indices' claims 2 items"},
      {"index out of range",
       binaryHeader(3, 1) + floats({0, 0, 0, 1, 0, 0, 0, 1, 0}) + face({0, 1, 3}),
       "face 0: vertex index 3 out of range (the file has 3 vertices)"},
      {"negative index",
       binaryHeader(3, 1) + floats({0, 0, 0, 1, 0, 0, 0, 1, 0}) + face({0, -1, 2}),
       "vertex index -1 out of range"},
      {"binary nan", binaryHeader(1, 0) + floats({0, std::numeric_limits<float>::quiet_NaN(), 0}),
       "vertex 0: coordinate is not a finite number"},
      {"binary infinity",
       binaryHeader(1, 0) + floats({std::numeric_limits<float>::infinity(), 0, 0}),
       "not a finite number"},
      {"ascii nan", ascii + "0 0 0\nnan 1 0\n0 1 0\n3 0 1 2\n",
       ":11: vertex 1: coordinate is not a finite number"},
      {"ascii word", ascii + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",
       ":11: vertex 1: expected a number for 'y', found 'zero'"},
      {"ascii short", ascii + "0 0 0\n1 0 0\n", "file ends before the element is complete"},
      {"ascii extra", ascii + "0 0 0 9\n1 0 0\n0 1 0\n3 0 1 2\n", "unexpected '9'"},
      {"ascii fraction index", ascii + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "expected an integer"},
      {"ascii huge list", ascii + "0 0 0\n1 0 0\n0 1 0\n255 0 1 2\n", "claims 255 items"},
      // The index's own byte (after the 36 of the vertices, 4 of the length, 3 indices).
      {"strip index out of range", binaryStrip + strip({0, 1, 2, 3}),
       fmt::format("byte {}: tristrips 0: vertex index 3 out of range (the file has 3 vertices)",
                   binaryStrip.size() + 4 + 12)},
      {"negative strip index", binaryStrip + strip({0, 1, -1, 2, -2}),
       "tristrips 0: vertex index -2 out of range"},
      {"cut strip", binaryStrip + strip({0, 1, 2, 1}).substr(0, 14),
       "tristrips 0: list 'vertex_indices' claims 4 items"},
      // The index's own line: the strip goes on over a second line.
      {"ascii strip index out of range", asciiStrip + "5 0 1 2\n-1 3\n",
       ":14: tristrips 0: vertex index 3 out of range"},
      {"ascii fraction strip index", asciiStrip + "3 0 1 1.5\n", "expected an integer"},
      {"strip without indices",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty "
       "float z\nelement tristrips 0\nproperty int vertex_indices\nend_header\n",
       "tristrips element lacks the list 'vertex_indices'"},
      {"float strip indices",
       stripHeader(PlyFormat::kAscii, "uchar float") + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "tristrips vertex indices must have an integer type"},
  };
  for (const BadCase& c : cases) {
    Result<Model> model = readPlyText(c.text, "bad.ply");
    ASSERT_FALSE(model.ok()) << c.name;
    EXPECT_EQ(model.error().kind, ErrorKind::kBadInput) << c.name;
    EXPECT_NE(model.error().message.find(c.expected), std::string::npos)
        << c.name << ": " << model.error().message;
    EXPECT_EQ(model.error().message.rfind("bad.ply", 0), 0u)
        << c.name << ": " << model.error().message;
  }
}

TEST(PlyBadInput, ByteOffsetsPointAtTheProblem) {
  const std::string header = binaryHeader(2, 0);
  const std::string text =
      header + floats({0, 0, 0, 1, std::numeric_limits<float>::quiet_NaN(), 0});
  Result<Model> model = readPlyText(text, "nan.ply");
  ASSERT_FALSE(model.ok());
  // The second vertex starts 12 bytes after the header.
  EXPECT_NE(model.error().message.find(fmt::format("byte {}", header.size() + 12)),
            std::string::npos)
      << model.error().message;
}

TEST(PlyWriter, RefusesCountsThatDoNotMatchTheDeclaration) {
  test::TempDir dir;
  {
    PlyLayout layout;
    layout.vertexCount = 3;
    layout.faceCount = 1;
    Result<PlyWriter> writer = PlyWriter::create(dir.file("short.ply"), layout);
    ASSERT_TRUE(writer.ok());
    const std::vector<Vec3f> two = {{0, 0, 0}, {1, 0, 0}};
    ASSERT_TRUE(writer->writeVertices(two, {}, {}).ok());
    const Status finished = writer->finish();
    ASSERT_FALSE(finished.ok());
    EXPECT_NE(finished.message().find("declared 3 vertices and 1 faces but wrote 2 and 0"),
              std::string::npos);
  }
  EXPECT_TRUE(test::listFolder(dir.path()).empty());  // nothing half-written is left
}

TEST(PlyWriter, InterleavedVerticesAndFacesLandInTheirSections) {
  test::TempDir dir;
  PlyLayout layout;
  layout.vertexCount = 6;
  layout.faceCount = 2;
  layout.objectIds = true;
  Result<PlyWriter> writer = PlyWriter::create(dir.file("two.ply"), layout);
  ASSERT_TRUE(writer.ok());
  for (std::uint32_t o = 0; o < 2; ++o) {
    const std::vector<Vec3f> tri = {{float(o), 0, 0}, {float(o) + 1, 0, 0}, {float(o), 1, 0}};
    const std::vector<std::uint32_t> indices = {3 * o, 3 * o + 1, 3 * o + 2};
    const std::vector<std::uint32_t> ids = {o};
    ASSERT_TRUE(writer->writeVertices(tri, {}, {}).ok());
    ASSERT_TRUE(writer->writeTriangles(indices, ids).ok());
  }
  ASSERT_TRUE(writer->finish().ok());
  Result<Model> back = readPly(dir.file("two.ply"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->objectCount(), 2u);
  EXPECT_EQ(back->objectPositions(1)[1], (Vec3f{2, 0, 0}));
}

}  // namespace
}  // namespace lodforge
