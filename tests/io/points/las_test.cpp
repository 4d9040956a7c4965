#include "lodforge/io/points/las_reader.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "lodforge/io/points/las_writer.h"
#include "lodforge/io/points/point_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

using test::bytesOf;

struct LasPoint {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t r = 0, g = 0, b = 0;
};

struct Record {
  std::string user = "LASF_Projection";
  std::uint16_t id = 0;
  std::string data;
};

template <class T>
void put(std::string& s, std::size_t at, T value) {
  if (s.size() < at + sizeof value) s.resize(at + sizeof value, '\0');
  std::memcpy(s.data() + at, &value, sizeof value);
}

// A LAS file built field by field (the layout of LAS 1.4 R15, Tables 3, 4 and 7–17).
std::string makeLas(int minor, int format, const std::vector<LasPoint>& points,
                    const std::vector<Record>& vlrs = {}, const std::vector<Record>& evlrs = {},
                    Vec3d scale = {0.01, 0.01, 0.01}, Vec3d offset = {1000, 2000, 0},
                    std::uint16_t extraBytes = 0) {
  const std::size_t headerSize = minor >= 4 ? 375 : minor == 3 ? 235 : 227;
  std::string s(headerSize, '\0');
  std::memcpy(s.data(), "LASF", 4);
  s[24] = 1;
  s[25] = static_cast<char>(minor);
  std::memcpy(s.data() + 58, "lodforge test", 13);
  put<std::uint16_t>(s, 94, static_cast<std::uint16_t>(headerSize));
  std::size_t vlrBytes = 0;
  for (const Record& v : vlrs) vlrBytes += 54 + v.data.size();
  put<std::uint32_t>(s, 96, static_cast<std::uint32_t>(headerSize + vlrBytes));
  put<std::uint32_t>(s, 100, static_cast<std::uint32_t>(vlrs.size()));
  s[104] = static_cast<char>(format);
  const auto length = static_cast<std::uint16_t>(lasRecordSize(format) + extraBytes);
  put<std::uint16_t>(s, 105, length);
  put<std::uint32_t>(s, 107, minor >= 4 ? 0u : static_cast<std::uint32_t>(points.size()));
  for (int k = 0; k < 3; ++k) {
    put<double>(s, 131 + 8 * static_cast<std::size_t>(k), scale[k]);
    put<double>(s, 155 + 8 * static_cast<std::size_t>(k), offset[k]);
    put<double>(s, 179 + 16 * static_cast<std::size_t>(k), 1e9);   // max
    put<double>(s, 187 + 16 * static_cast<std::size_t>(k), -1e9);  // min
  }
  for (const Record& v : vlrs) {
    std::string head(54, '\0');
    std::memcpy(head.data() + 2, v.user.data(), std::min<std::size_t>(16, v.user.size()));
    put<std::uint16_t>(head, 18, v.id);
    put<std::uint16_t>(head, 20, static_cast<std::uint16_t>(v.data.size()));
    s += head + v.data;
  }
  const std::size_t colorAt = format == 2 ? 20 : format == 3 || format == 5 ? 28 : 30;
  const bool colors =
      format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
  for (const LasPoint& p : points) {
    std::string r(length, '\0');
    put(r, 0, p.x);
    put(r, 4, p.y);
    put(r, 8, p.z);
    if (colors) {
      put(r, colorAt, p.r);
      put(r, colorAt + 2, p.g);
      put(r, colorAt + 4, p.b);
    }
    s += r;
  }
  if (minor >= 4) {
    put<std::uint64_t>(s, 235, evlrs.empty() ? 0 : s.size());
    put<std::uint32_t>(s, 243, static_cast<std::uint32_t>(evlrs.size()));
    put<std::uint64_t>(s, 247, points.size());
    for (const Record& v : evlrs) {
      std::string head(60, '\0');
      std::memcpy(head.data() + 2, v.user.data(), std::min<std::size_t>(16, v.user.size()));
      put<std::uint16_t>(head, 18, v.id);
      put<std::uint64_t>(head, 20, v.data.size());
      s += head + v.data;
    }
  }
  return s;
}

std::vector<LasPoint> somePoints(std::size_t n, std::uint16_t colorScale) {
  std::vector<LasPoint> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = static_cast<std::int32_t>(i);
    points[i] = {v * 100 - 5000,
                 -v * 7,
                 v * 3 + 1,
                 static_cast<std::uint16_t>((i % 256) * colorScale),
                 static_cast<std::uint16_t>(((i * 7) % 256) * colorScale),
                 static_cast<std::uint16_t>(255 * colorScale)};
  }
  return points;
}

std::vector<Vec3d> readAll(LasReader& reader, std::vector<Rgba8>* colors = nullptr) {
  std::vector<Vec3d> positions;
  PointBatch batch;
  while (true) {
    Result<bool> more = reader.next(batch);
    EXPECT_TRUE(more.ok()) << (more.ok() ? "" : more.error().message);
    if (!more.ok() || !*more) break;
    positions.insert(positions.end(), batch.positions.begin(), batch.positions.end());
    if (colors) colors->insert(colors->end(), batch.colors.begin(), batch.colors.end());
  }
  return positions;
}

TEST(LasReader, ReadsEveryVersionAndPointFormatWithScaleAndOffset) {
  // Formats 0–10 (6–10 only in 1.4), records of each format's size, read in small batches so
  // several batch boundaries are crossed.
  for (int format = 0; format <= 10; ++format) {
    for (int minor : {0, 2, 3, 4}) {
      if (format >= 6 && minor < 4) continue;
      if ((format == 4 || format == 5) && minor < 3) continue;
      SCOPED_TRACE(::testing::Message() << "LAS 1." << minor << " format " << format);
      const std::vector<LasPoint> points = somePoints(300, 257);
      const std::string file = makeLas(minor, format, points);
      Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las", 64);
      ASSERT_TRUE(reader.ok()) << reader.error().message;
      EXPECT_EQ(reader->header().pointFormat, format);
      EXPECT_EQ(reader->header().pointCount, points.size());
      std::vector<Rgba8> colors;
      const std::vector<Vec3d> read = readAll(*reader, &colors);
      ASSERT_EQ(read.size(), points.size());
      for (std::size_t i = 0; i < points.size(); ++i) {
        EXPECT_DOUBLE_EQ(read[i].x, points[i].x * 0.01 + 1000);
        EXPECT_DOUBLE_EQ(read[i].y, points[i].y * 0.01 + 2000);
        EXPECT_DOUBLE_EQ(read[i].z, points[i].z * 0.01);
      }
      const bool hasColors = reader->header().hasColors;
      EXPECT_EQ(hasColors, format == 2 || format == 3 || format == 5 || format == 7 ||
                               format == 8 || format == 10);
      if (hasColors) {
        ASSERT_EQ(colors.size(), points.size());
        EXPECT_FALSE(reader->header().eightBitColors);
        for (std::size_t i = 0; i < points.size(); ++i)
          EXPECT_EQ(colors[i].r, points[i].r >> 8) << i;
      }
    }
  }
}

TEST(LasReader, TellsEightBitColoursFromSixteen) {
  const std::string file = makeLas(2, 3, somePoints(100, 1));
  Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las");
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->header().eightBitColors);
  std::vector<Rgba8> colors;
  readAll(*reader, &colors);
  ASSERT_EQ(colors.size(), 100u);
  EXPECT_EQ(colors[77].r, 77);
  EXPECT_EQ(colors[77].g, (77 * 7) % 256);
}

TEST(LasReader, KeepsGeoScaleCoordinatesExact) {
  // Millimetres at a UTM easting of 600 km: exact in double, as written.
  std::vector<LasPoint> points{{123456789, 987654321, -12345}};
  const std::string file = makeLas(2, 0, points, {}, {}, {0.001, 0.001, 0.001}, {500000, 4e6, 0});
  Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las");
  ASSERT_TRUE(reader.ok());
  const std::vector<Vec3d> read = readAll(*reader);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_DOUBLE_EQ(read[0].x, 123456789 * 0.001 + 500000);
  EXPECT_NEAR(read[0].x, 623456.789, 1e-9);
  EXPECT_NEAR(read[0].y, 4987654.321, 1e-8);
}

TEST(LasReader, ReadsTheCoordinateSystemFromWktGeoKeysAndExtendedRecords) {
  const std::string wkt = "PROJCS[\"WGS 84 / UTM zone 33N\"]";
  {
    const std::string file =
        makeLas(2, 0, somePoints(3, 1), {{"LASF_Projection", 2112, wkt + '\0'}});
    Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las");
    ASSERT_TRUE(reader.ok()) << reader.error().message;
    EXPECT_EQ(reader->header().crs, wkt);
  }
  {
    // GeoKeyDirectory: version 1.1.0, 2 keys: GTModelType = 1, ProjectedCSType = 32633.
    std::string keys;
    for (std::uint16_t v : {1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 32633}) {
      keys.append(reinterpret_cast<const char*>(&v), 2);
    }
    const std::string file = makeLas(2, 1, somePoints(3, 1), {{"LASF_Projection", 34735, keys}});
    Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las");
    ASSERT_TRUE(reader.ok()) << reader.error().message;
    EXPECT_EQ(reader->header().crs, "EPSG:32633");
  }
  {
    // LAS 1.4 keeps its WKT in an extended record after the points.
    const std::string file = makeLas(4, 6, somePoints(5, 1), {}, {{"LASF_Projection", 2112, wkt}});
    Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "t.las");
    ASSERT_TRUE(reader.ok()) << reader.error().message;
    EXPECT_EQ(reader->header().crs, wkt);
    EXPECT_EQ(readAll(*reader).size(), 5u);
  }
}

TEST(LasReader, ReadsTheRealAutzenAndLibLasSamples) {
  // The header's bounds must hold every point, and the first point is as PDAL reads it.
  Result<LasReader> autzen = LasReader::open(test::dataPath("points/autzen_trim.las"));
  ASSERT_TRUE(autzen.ok()) << autzen.error().message;
  const LasHeader& h = autzen->header();
  EXPECT_EQ(h.versionMinor, 2);
  EXPECT_EQ(h.pointFormat, 3);
  EXPECT_EQ(h.pointCount, 110'000u);
  EXPECT_NE(h.crs.find("Lambert_Conformal_Conic"), std::string::npos);
  EXPECT_TRUE(h.eightBitColors);
  std::vector<Rgba8> colors;
  const std::vector<Vec3d> points = readAll(*autzen, &colors);
  ASSERT_EQ(points.size(), 110'000u);
  Aabbd bounds;
  for (const Vec3d& p : points) bounds.add(p);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(bounds.min[k], h.bounds.min[k], 1e-6);
    EXPECT_NEAR(bounds.max[k], h.bounds.max[k], 1e-6);
  }
  EXPECT_EQ(colors[0].r, 84);  // 8-bit colours taken as they are
  Result<LasReader> sample = LasReader::open(test::dataPath("points/sample_c.las"));
  ASSERT_TRUE(sample.ok());
  EXPECT_FALSE(sample->header().eightBitColors);
  std::vector<Rgba8> sampleColors;
  EXPECT_EQ(readAll(*sample, &sampleColors).size(), 14'408u);
  EXPECT_EQ(sampleColors[0].r, 48896 >> 8);
}

void expectBad(const std::string& file, const std::string& fragment) {
  Result<LasReader> reader = LasReader::fromMemory(bytesOf(file), "bad.las");
  Status status = reader.status();
  if (reader.ok()) {
    PointBatch batch;
    while (status.ok()) {
      Result<bool> more = reader->next(batch);
      status = more.status();
      if (more.ok() && !*more) break;
    }
  }
  ASSERT_FALSE(status.ok()) << "accepted a file that should fail with: " << fragment;
  EXPECT_EQ(status.kind(), ErrorKind::kBadInput);
  EXPECT_NE(status.message().find("bad.las: byte "), std::string::npos) << status.message();
  EXPECT_NE(status.message().find(fragment), std::string::npos) << status.message();
}

TEST(LasReader, RefusesBadFilesWithTheirPosition) {
  const std::string good = makeLas(2, 3, somePoints(10, 1));
  expectBad(good.substr(0, 100), "too few for a LAS header");
  std::string wrong = good;
  wrong[0] = 'X';
  expectBad(wrong, "LASF");
  wrong = good;
  put<std::uint16_t>(wrong, 94, 200);
  expectBad(wrong, "header size 200");
  wrong = good;
  put<std::uint32_t>(wrong, 107, 1000);
  expectBad(wrong, "run past the end of the file");
  expectBad(good.substr(0, good.size() - 5), "run past the end of the file");
  wrong = good;
  wrong[104] = 11;
  expectBad(wrong, "point format 11");
  wrong = good;
  put<std::uint16_t>(wrong, 105, 20);
  expectBad(wrong, "shorter than format 3's 34");
  wrong = good;
  put<double>(wrong, 139, std::nan(""));
  expectBad(wrong, "scale factor");
  wrong = good;
  wrong[25] = 9;
  expectBad(wrong, "version 1.9");
  // A VLR longer than the space before the points.
  std::string vlr = makeLas(2, 0, somePoints(4, 1), {{"LASF_Projection", 2112, "WKT"}});
  put<std::uint16_t>(vlr, 227 + 20, 500);
  expectBad(vlr, "runs past the point data");
  vlr = makeLas(2, 0, somePoints(4, 1), {{"LASF_Projection", 2112, "WKT"}});
  put<std::uint32_t>(vlr, 100, 3);
  expectBad(vlr, "variable length record 2 of 3");
  // Extended records that point beyond the file.
  std::string evlr = makeLas(4, 6, somePoints(4, 1), {}, {{"LASF_Projection", 2112, "WKT"}});
  put<std::uint64_t>(evlr, 235, evlr.size() + 10);
  expectBad(evlr, "extended records");
}

// The LASzip record of the real LAZ files, as their LAS twins and the issue describe them.
TEST(LasReader, ReadsTheLaszipRecordOfRealLazAndCopc) {
  struct Case {
    std::string file;
    LazCompressor compressor;
    int pointFormat;
    std::uint16_t itemVersion;
    std::vector<std::string> items;
    bool chunked, copc;
  };
  for (const Case& c : {
           Case{"autzen_trim.laz",
                LazCompressor::kPointwiseChunked,
                3,
                2,
                {"POINT10", "GPSTIME11", "RGB12"},
                true,
                false},
           Case{"simple-v1.laz",
                LazCompressor::kPointwise,
                3,
                1,
                {"POINT10", "GPSTIME11", "RGB12"},
                false,
                false},
           Case{"1.2-with-color.copc.laz",
                LazCompressor::kLayeredChunked,
                7,
                3,
                {"POINT14", "RGB14"},
                true,
                true},
       }) {
    Result<LasHeader> h = LasReader::readHeader(test::dataPath("points/" + c.file));
    ASSERT_TRUE(h.ok()) << c.file << ": " << h.error().message;
    EXPECT_TRUE(h->compressed) << c.file;
    EXPECT_EQ(h->copc, c.copc) << c.file;
    EXPECT_EQ(h->pointFormat, c.pointFormat) << c.file;
    ASSERT_TRUE(h->laz.has_value()) << c.file;
    EXPECT_EQ(h->laz->compressor, c.compressor) << c.file;
    EXPECT_EQ(h->laz->coder, 0) << c.file;
    EXPECT_EQ(h->laz->recordBytes(), h->recordLength) << c.file;
    ASSERT_EQ(h->laz->items.size(), c.items.size()) << c.file;
    for (std::size_t i = 0; i < c.items.size(); ++i) {
      EXPECT_EQ(lazItemName(h->laz->items[i].type), c.items[i]) << c.file;
      EXPECT_EQ(h->laz->items[i].version, c.itemVersion) << c.file;
    }
    if (c.chunked) {
      EXPECT_GT(h->laz->chunkSize, 0u) << c.file;
    }
  }
  // The same header as the LAS of the same points: counts, scale and bounds.
  Result<LasHeader> laz = LasReader::readHeader(test::dataPath("points/autzen_trim.laz"));
  Result<LasHeader> las = LasReader::readHeader(test::dataPath("points/autzen_trim.las"));
  ASSERT_TRUE(laz.ok() && las.ok());
  EXPECT_FALSE(las->compressed);
  EXPECT_FALSE(las->laz.has_value());
  EXPECT_EQ(laz->pointCount, las->pointCount);
  EXPECT_EQ(laz->scale, las->scale);
  EXPECT_EQ(laz->bounds.min, las->bounds.min);
  EXPECT_EQ(laz->crs, las->crs);
}

TEST(LasReader, RefusesADamagedLaszipRecordWithItsPosition) {
  // A compressed format byte and a LASzip record of POINT10 v2 (20 bytes, format 0).
  std::string record(34 + 6, '\0');
  put<std::uint16_t>(record, 0, 2);       // point-wise chunked
  put<std::uint32_t>(record, 12, 50000);  // chunk size
  put<std::int64_t>(record, 16, -1);
  put<std::int64_t>(record, 24, -1);
  put<std::uint16_t>(record, 32, 1);
  put<std::uint16_t>(record, 34, 6);   // POINT10
  put<std::uint16_t>(record, 36, 20);  // bytes
  put<std::uint16_t>(record, 38, 2);
  const auto laz = [&](const std::string& data) {
    std::string file = makeLas(2, 0, {}, {{"laszip encoded", kLazRecordId, data}});
    file[104] = static_cast<char>(0x80);
    return file;
  };
  const auto header = [](const std::string& bytes) {
    // readHeader wants a file: through a temporary one.
    test::TempDir dir;
    test::writeFile(dir.file("x.laz"), bytes);
    return LasReader::readHeader(dir.file("x.laz"));
  };
  Result<LasHeader> good = header(laz(record));
  ASSERT_TRUE(good.ok()) << good.error().message;
  EXPECT_EQ(good->laz->items.size(), 1u);
  std::string wrong = record;
  put<std::uint16_t>(wrong, 32, 3);  // three items in room for one
  Result<LasHeader> bad = header(laz(wrong));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("byte 313: LASzip record: 3 items need 52 bytes"),
            std::string::npos)
      << bad.error().message;
  wrong = record;
  put<std::uint16_t>(wrong, 36, 24);  // items cover more than the record
  bad = header(laz(wrong));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("LASzip items cover 24 bytes of a 20-byte point record"),
            std::string::npos)
      << bad.error().message;
  wrong = record;
  put<std::uint16_t>(wrong, 2, 7);  // an unknown coder
  bad = header(laz(wrong));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("unknown coder 7"), std::string::npos) << bad.error().message;
  // Compressed points without the record at all.
  std::string bare = makeLas(2, 0, {});
  bare[104] = static_cast<char>(0x80);
  bad = header(bare);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("no LASzip record"), std::string::npos) << bad.error().message;
}

// One descriptor of the Extra Bytes record, field by field (LAS 1.4 R15, Table 24).
std::string descriptor(std::uint8_t type, std::uint8_t options, const std::string& name,
                       std::array<double, 3> scale = {1, 1, 1},
                       std::array<double, 3> offset = {0, 0, 0}, std::int64_t noData = 0) {
  std::string d(192, '\0');
  d[2] = static_cast<char>(type);
  d[3] = static_cast<char>(options);
  std::memcpy(d.data() + 4, name.data(), std::min<std::size_t>(32, name.size()));
  put(d, 40, noData);
  for (std::size_t k = 0; k < 3; ++k) {
    put(d, 112 + 8 * k, scale[k]);
    put(d, 136 + 8 * k, offset[k]);
  }
  std::memcpy(d.data() + 160, "described", 9);
  return d;
}

TEST(LasExtraBytes, DescriptorsGiveTypesOffsetsScalesAndNoData) {
  // Undocumented 3 bytes, a scaled uint16 with no-data, a 3-element float array (LAS 1.3's
  // type 29) and a double: 3 + 2 + 12 + 8 = 25 bytes of the 27 the records have.
  const std::string record = descriptor(0, 3, "pad") +
                             descriptor(3, 1 | 8 | 16, "height", {0.01, 1, 1}, {5, 0, 0}, 65535) +
                             descriptor(29, 0, "xyz") + descriptor(10, 0, "range");
  Result<PointExtras> extras = parseLasExtraBytes(bytesOf(record), 27, "f.las", 1000);
  ASSERT_TRUE(extras.ok()) << extras.error().message;
  EXPECT_EQ(extras->stride, 27u);
  ASSERT_EQ(extras->fields.size(), 5u);
  const ExtraField& height = extras->fields[0];
  EXPECT_EQ(height.name, "height");
  EXPECT_EQ(height.description, "described");
  EXPECT_EQ(height.type, ExtraType::kUint16);
  EXPECT_EQ(height.offset, 3u);
  EXPECT_EQ(height.scale, 0.01);
  EXPECT_EQ(height.add, 5);
  EXPECT_EQ(height.noData, 65535.0);
  EXPECT_EQ(extras->fields[1].name, "xyz[0]");
  EXPECT_EQ(extras->fields[3].name, "xyz[2]");
  EXPECT_EQ(extras->fields[3].offset, 13u);
  EXPECT_EQ(extras->fields[3].type, ExtraType::kFloat32);
  EXPECT_EQ(extras->fields[4].offset, 17u);
  EXPECT_EQ(extras->fields[4].type, ExtraType::kFloat64);
  EXPECT_FALSE(extras->fields[4].noData.has_value());
  std::vector<std::byte> point(27);
  const std::uint16_t raw = 1234;
  std::memcpy(point.data() + 3, &raw, 2);
  EXPECT_DOUBLE_EQ(extraValue(point.data(), height), 17.34);
  // Bad records name the file, the byte and the field.
  Result<PointExtras> tooLong = parseLasExtraBytes(bytesOf(record), 20, "f.las", 1000);
  ASSERT_FALSE(tooLong.ok());
  EXPECT_NE(tooLong.error().message.find("f.las"), std::string::npos);
  EXPECT_NE(tooLong.error().message.find("\"range\" end at byte 25"), std::string::npos);
  EXPECT_FALSE(parseLasExtraBytes(bytesOf(record.substr(0, 300)), 27, "f.las", 0).ok());
  Result<PointExtras> badType = parseLasExtraBytes(bytesOf(descriptor(31, 0, "x")), 8, "f.las", 0);
  ASSERT_FALSE(badType.ok());
  EXPECT_NE(badType.error().message.find("data type 31"), std::string::npos);
  EXPECT_FALSE(
      parseLasExtraBytes(bytesOf(descriptor(9, 8, "zero", {0, 1, 1})), 4, "f.las", 0).ok());
  // Arrays take each element's scale and offset; a no-data value the type cannot hold (300 for
  // a uint8) is dropped; a float's is the float it would be stored as; names are made printable.
  const std::string pair = descriptor(13, 8 | 16, "rg", {0.5, 0.25, 1}, {1, 2, 0}) +
                           descriptor(1, 1, "byte", {1, 1, 1}, {0, 0, 0}, 300) +
                           descriptor(9, 0, "f\x01\xff");
  std::string floatNoData = descriptor(9, 1, "level");
  put(floatNoData, 40, -9999.9);
  Result<PointExtras> more = parseLasExtraBytes(bytesOf(pair + floatNoData), 13, "f.las", 0);
  ASSERT_TRUE(more.ok()) << more.error().message;
  ASSERT_EQ(more->fields.size(), 5u);
  EXPECT_EQ(more->fields[1].name, "rg[1]");
  EXPECT_EQ(more->fields[1].scale, 0.25);
  EXPECT_EQ(more->fields[1].add, 2);
  EXPECT_EQ(more->fields[1].offset, 2u);
  EXPECT_FALSE(more->fields[2].noData.has_value());
  EXPECT_EQ(more->fields[3].name, "f??");
  ASSERT_TRUE(more->fields[4].noData.has_value());
  EXPECT_EQ(*more->fields[4].noData, static_cast<double>(-9999.9f));
}

// A damaged Extra Bytes record costs the extra bytes, not the file: the points are read, and
// the header says why the extra bytes are not. An EVLR describes them as well as a VLR.
TEST(LasExtraBytes, ADamagedRecordIsReadPastAndAnExtendedOneIsRead) {
  test::TempDir dir;
  const std::vector<LasPoint> points = somePoints(10, 1);
  const std::string bad = makeLas(2, 1, points, {{"LASF_Spec", 4, std::string(100, '\x01')}});
  test::writeFile(dir.file("bad.las"), bad);
  Result<LasReader> reader = LasReader::open(dir.file("bad.las"));
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  EXPECT_TRUE(reader->header().extras.fields.empty());
  EXPECT_NE(reader->header().extrasIgnored.find("not a whole number of 192-byte descriptors"),
            std::string::npos)
      << reader->header().extrasIgnored;
  EXPECT_EQ(readAll(*reader).size(), 10u);
  Result<PointReader> common = PointReader::open(dir.file("bad.las"));
  ASSERT_TRUE(common.ok());
  ASSERT_EQ(common->info().warnings.size(), 1u);
  // LAS 1.4 with 2 extra bytes a record, described by an extended record.
  const std::string evlr = makeLas(4, 6, points, {}, {{"LASF_Spec", 4, descriptor(3, 0, "tag")}},
                                   {0.01, 0.01, 0.01}, {1000, 2000, 0}, 2);
  test::writeFile(dir.file("evlr.las"), evlr);
  Result<PointReader> extended = PointReader::open(dir.file("evlr.las"));
  ASSERT_TRUE(extended.ok()) << extended.error().message;
  ASSERT_EQ(extended->info().extras.fields.size(), 1u);
  EXPECT_EQ(extended->info().extras.fields[0].name, "tag");
  EXPECT_EQ(extended->info().extras.stride, 2u);
  PointBatch batch;
  ASSERT_TRUE(*extended->next(batch));
  EXPECT_EQ(batch.extras.size(), 20u);
  // Without extras asked for, none come.
  Result<PointReader> without = PointReader::open(dir.file("evlr.las"), {.readExtras = false});
  ASSERT_TRUE(without.ok());
  EXPECT_TRUE(without->info().extras.fields.empty());
  ASSERT_TRUE(*without->next(batch));
  EXPECT_TRUE(batch.extras.empty());
}

// PDAL writes an Extra Bytes record per dimension: every record's descriptors, in file order,
// make up the layout (Deviation at byte 0, confidence at byte 2), not the last record alone.
TEST(LasExtraBytes, EveryRecordsDescriptorsInOrderMakeTheLayout) {
  test::TempDir dir;
  const std::vector<LasPoint> points = somePoints(70, 1);
  std::string las = makeLas(4, 6, points,
                            {{"LASF_Spec", 4, descriptor(3, 0, "Deviation")},
                             {"LASF_Projection", 2112, "LOCAL_CS[\"x\"]"},
                             {"LASF_Spec", 4, descriptor(1, 0, "confidence")}},
                            {}, {0.01, 0.01, 0.01}, {1000, 2000, 0}, 3);
  const std::size_t first = las.size() - points.size() * 33, stride = 33;  // format 6: 30 + 3
  for (std::size_t i = 0; i < points.size(); ++i) {
    put<std::uint16_t>(las, first + i * stride + 30, static_cast<std::uint16_t>(100 * i));
    put<std::uint8_t>(las, first + i * stride + 32, static_cast<std::uint8_t>(1 + i % 65));
  }
  test::writeFile(dir.file("pdal.las"), las);
  Result<PointReader> reader = PointReader::open(dir.file("pdal.las"));
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  const PointExtras& extras = reader->info().extras;
  ASSERT_EQ(extras.fields.size(), 2u);
  EXPECT_EQ(extras.stride, 3u);
  EXPECT_EQ(extras.fields[0].name, "Deviation");
  EXPECT_EQ(extras.fields[0].offset, 0u);
  EXPECT_EQ(extras.fields[1].name, "confidence");
  EXPECT_EQ(extras.fields[1].offset, 2u);
  EXPECT_EQ(extras.fields[1].type, ExtraType::kUint8);
  PointBatch batch;
  std::vector<std::byte> all;
  while (*reader->next(batch)) all.insert(all.end(), batch.extras.begin(), batch.extras.end());
  ASSERT_EQ(all.size(), points.size() * 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(extraValue(all.data() + 3 * i, extras.fields[0]), 100.0 * i);
    EXPECT_EQ(extraValue(all.data() + 3 * i, extras.fields[1]), 1.0 + i % 65);
  }
  // Two records that together describe more bytes than the points have: the second is named.
  const std::string deviation = descriptor(3, 0, "Deviation"), range = descriptor(5, 0, "range");
  const LasExtraRecord records[] = {{bytesOf(deviation), 400}, {bytesOf(range), 700}};
  Result<PointExtras> bad = parseLasExtraBytes(records, 3, "f.las");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("byte 700"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("\"range\" end at byte 6"), std::string::npos);
}

// What the writer describes, the reader reads back: the fields and each point's bytes.
TEST(LasExtraBytes, WrittenAndReadBackWithEveryPoint) {
  test::TempDir dir;
  PointExtras layout;
  layout.fields = {{"label", "", ExtraType::kUint8, 0, 1, 0, std::nullopt},
                   {"depth", "metres", ExtraType::kInt32, 1, 0.001, -10, -1}};
  layout.stride = 5;
  Result<LasWriter> writer =
      LasWriter::create(dir.file("x.las"), {0.01, 0.01, 0.01}, {0, 0, 0}, "test", layout);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  std::vector<LasPoint3> points(300);
  std::vector<std::byte> extras(300 * 5);
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i].position = {double(i), 2, 3};
    const auto label = static_cast<std::uint8_t>(i % 11);
    const auto depth = static_cast<std::int32_t>(i * 1000 - 7);
    std::memcpy(extras.data() + 5 * i, &label, 1);
    std::memcpy(extras.data() + 5 * i + 1, &depth, 4);
  }
  ASSERT_TRUE(writer->write(points, extras).ok());
  EXPECT_FALSE(writer->write(points, {}).ok());  // extra bytes missing: refused
  ASSERT_TRUE(writer->finish().ok());
  Result<PointReader> reader = PointReader::open(dir.file("x.las"));
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  const PointExtras& read = reader->info().extras;
  ASSERT_EQ(read.fields.size(), 2u);
  EXPECT_EQ(read.stride, 5u);
  EXPECT_EQ(read.fields[1].name, "depth");
  EXPECT_EQ(read.fields[1].description, "metres");
  EXPECT_EQ(read.fields[1].scale, 0.001);
  EXPECT_EQ(read.fields[1].add, -10);
  EXPECT_EQ(read.fields[1].noData, -1.0);
  EXPECT_NE(reader->info().attributes & kAttrExtras, 0u);
  PointBatch batch;
  std::vector<std::byte> all;
  while (*reader->next(batch)) all.insert(all.end(), batch.extras.begin(), batch.extras.end());
  EXPECT_TRUE(all == extras);
  EXPECT_DOUBLE_EQ(extraValue(all.data() + 5 * 3, read.fields[1]), 2.993 - 10);
}

TEST(PointReader, ReadsLasThroughTheCommonReader) {
  Result<PointReader> reader = PointReader::open(test::dataPath("points/sample_c.las"));
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->info().format, "LAS 1.2, point format 3");
  EXPECT_EQ(reader->info().count, 14'408u);
  EXPECT_TRUE(reader->info().hasColors);
  EXPECT_TRUE(reader->info().crs.empty());
  std::uint64_t count = 0;
  PointBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    ASSERT_TRUE(more.ok());
    if (!*more) break;
    count += batch.size();
  }
  EXPECT_EQ(count, 14'408u);
  EXPECT_FALSE(PointReader::open("cloud.e57").ok());
}

}  // namespace
}  // namespace lodforge
