// Damaged, odd and ambiguous real inputs (issue 35): each is refused naming the file and where,
// or read with a warning that says what was lost — never exit 0 with a silently wrong answer.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <regex>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_lodforge.h"
#include "test_support.h"

namespace lodforge {
namespace {

using test::lodforge;
using test::Outcome;

// `text` with its first `from` replaced by `to` (which must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::uint64_t triangles(const std::string& path, const test::TempDir& dir) {
  const Outcome o = lodforge("info --json " + path, dir);
  EXPECT_EQ(o.code, 0) << o.err;
  return o.code == 0 ? nlohmann::json::parse(o.out)["triangles"].get<std::uint64_t>() : 0;
}

// An IFC (an ISO 10303-21 file) cut short is refused naming the byte it ends at; --salvage
// reads what it holds and says it was cut. convert writes nothing from the half.
TEST(DamagedInput, AnIfcCutShortIsRefusedOrSalvagedWithAWarning) {
  test::TempDir dir;
  const std::string house = test::readFile(test::testDataPath("ifc/house.ifc"));
  const std::string half = house.substr(0, house.size() / 2);
  test::writeFile(dir.file("half.ifc"), half);
  Outcome o = lodforge("info " + dir.file("half.ifc"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find(fmt::format("half.ifc: byte {}: the file ends here", half.size())),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("END-ISO-10303-21;"), std::string::npos) << o.err;
  o = lodforge("convert " + dir.file("half.ifc") + " -o " + dir.file("half.glb"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("half.glb")));
  // Most of it, with --salvage: read, with the cut said.
  const std::string most = house.substr(0, house.size() * 9 / 10);
  test::writeFile(dir.file("most.ifc"), most);
  o = lodforge("info --salvage " + dir.file("most.ifc"), dir);
  if (o.code == 0) {
    EXPECT_NE(o.err.find(fmt::format("most.ifc: cut short at byte {}", most.size())),
              std::string::npos)
        << o.err;
  } else {
    EXPECT_EQ(o.code, 2) << o.err;  // or what assimp says of what is left, naming the file
    EXPECT_NE(o.err.find("most.ifc"), std::string::npos) << o.err;
  }
  // The whole file reads without a word; trailing white space and a comment are no cut.
  test::writeFile(dir.file("whole.ifc"), house + "\n/* exported */\n\n");
  o = lodforge("info " + dir.file("whole.ifc"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("warning"), std::string::npos) << o.err;
}

// A STEP file cut short: the same rule as IFC.
TEST(DamagedInput, AStepFileCutShortIsRefused) {
  test::TempDir dir;
  const std::string motor = test::readFile(test::dataPath("cad/as1_motor.step"));
  test::writeFile(dir.file("cut.step"), motor.substr(0, motor.size() / 2));
  const Outcome o = lodforge("info " + dir.file("cut.step"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("cut.step: byte "), std::string::npos) << o.err;
  EXPECT_NE(o.err.find(", inside entity #"), std::string::npos) << o.err;
}

// One flipped byte or one deleted line in a STEP file: OCCT drops what it cannot read; the
// warning counts the entities and names the first, -v lists each with OCCT's reason.
TEST(DamagedInput, AStepFileMissingEntitiesSaysWhatWasLost) {
  test::TempDir dir;
  const std::string motor = test::readFile(test::dataPath("cad/as1_motor.step"));
  test::writeFile(dir.file("flipped.step"), replaced(motor, "= FACE_BOUND(", "= FACE_BOZND("));
  Outcome o = lodforge("info " + dir.file("flipped.step"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("flipped.step: damaged: OCCT could not read or transfer"), std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("(#"), std::string::npos) << o.err;
  o = lodforge("-v info " + dir.file("flipped.step"), dir);
  EXPECT_NE(o.err.find("flipped.step: OCCT could not read #"), std::string::npos) << o.err;
  // A line deleted: the entities that refer to it are lost too.
  const std::size_t face = motor.find("= ADVANCED_FACE(");
  const std::size_t start = motor.rfind('\n', face) + 1, end = motor.find('\n', face) + 1;
  test::writeFile(dir.file("deleted.step"), motor.substr(0, start) + motor.substr(end));
  o = lodforge("info " + dir.file("deleted.step"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("deleted.step: damaged: OCCT could not read or transfer"), std::string::npos)
      << o.err;
  // The whole file: no such warning.
  o = lodforge("info " + test::dataPath("cad/as1_motor.step"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("damaged"), std::string::npos) << o.err;
}

// Part names in a legacy code page (CP1251, as OCCT's bug31670 sample): noticed, guessed from
// their bytes, and --code-page still decides.
TEST(DamagedInput, PartNamesInALegacyCodePageAreNoticedAndGuessed) {
  test::TempDir dir;
  std::string motor = test::readFile(test::dataPath("cad/as1_motor.step"));
  // "Деталь" (part) in CP1251 for each part, named "Product 1.1.N.1" in the file.
  const std::string detal = "\xC4\xE5\xF2\xE0\xEB\xFC";
  motor =
      std::regex_replace(motor, std::regex("'Product 1\\.1\\.([0-9]+)\\.1'"), "'" + detal + "$1'");
  test::writeFile(dir.file("cp1251.step"), motor);
  Outcome o = lodforge("info --json " + dir.file("cp1251.step"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("are not UTF-8 (e.g. '\\xC4\\xE5\\xF2\\xE0\\xEB\\xFC"), std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("read as CP1251"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--code-page"), std::string::npos) << o.err;
  const std::string json = o.out;
  EXPECT_NE(json.find("Деталь1"), std::string::npos);
  // Given, it is used without a guess or a warning; the same names.
  o = lodforge("info --json --code-page CP1251 " + dir.file("cp1251.step"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("UTF-8"), std::string::npos) << o.err;
  EXPECT_NE(o.out.find("Деталь1"), std::string::npos);
  // Bytes that make no code page clear: the warning asks for one.
  std::string mixed = test::readFile(test::dataPath("cad/as1_motor.step"));
  mixed = replaced(mixed, "'Product 1.1.1'", "'\x81\x41\x83\x7F\x90'");
  test::writeFile(dir.file("unclear.step"), mixed);
  o = lodforge("info " + dir.file("unclear.step"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("show garbled: give the file's code page with --code-page"),
            std::string::npos)
      << o.err;
}

// A CRS that cannot be the data's — a file whose WKT says geocentric while its coordinates are
// Lambert feet — would put the tiles thousands of km underground: refused, naming where the CRS
// came from (the file, not an option the user never gave) and the fix.
TEST(DamagedInput, ACoordinateSystemThatPutsTheDataUndergroundIsRefused) {
  test::TempDir dir;
  const std::string las = test::readFile(test::dataPath("points/autzen_trim.las"));
  const std::size_t wkt = las.find("PROJCS[");
  ASSERT_NE(wkt, std::string::npos);
  const std::size_t end = las.find('\0', wkt);
  const std::string geocentric =
      "GEOCCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],"
      "PRIMEM[\"Greenwich\",0],UNIT[\"metre\",1]]";
  ASSERT_LT(geocentric.size(), end - wkt);
  std::string wrong = las;
  wrong.replace(wkt, end - wkt, geocentric + std::string(end - wkt - geocentric.size(), '\0'));
  test::writeFile(dir.file("geocentric.las"), wrong);
  Outcome o = lodforge("tiles " + dir.file("geocentric.las") + " -o " + dir.file("t"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("the coordinate system in " + dir.file("geocentric.las") + " (WGS 84)"),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("km under the Earth's surface"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--crs EPSG:N, or place it with --origin"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("t")));
  // The same through --surface (the mesh pipeline places it).
  o = lodforge("tiles " + dir.file("geocentric.las") + " --surface --voxel 12 -o " + dir.file("s"),
               dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("the coordinate system in "), std::string::npos) << o.err;
  // A CRS given on the command line is named as the option.
  o = lodforge(
      "tiles " + test::dataPath("points/simple.las") + " --crs EPSG:4326 -o " + dir.file("u"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("--crs (WGS 84)"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("the coordinate system in"), std::string::npos) << o.err;
  // A CRS whose area of use (Switzerland) the points land far outside of.
  o = lodforge(
      "tiles " + test::dataPath("points/simple.las") + " --crs EPSG:2056 -o " + dir.file("v"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("--crs (CH1903+ / LV95) puts the input point"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("far outside the area it is for (5.96 to 10.49 east"), std::string::npos)
      << o.err;
}

// --voxel means the cloud's units in both commands (Autzen is in feet): the same voxel makes
// about the same surface, and the default is the same voxel.
TEST(OddInput, TheVoxelIsInTheCloudsUnitsForReconstructAndTiles) {
  test::TempDir dir;
  const std::string autzen = test::dataPath("points/autzen_trim.las");
  const auto reconstructed = [&](const std::string& voxel, double& used) {
    // Undecimated, as tiles --surface leaves its pieces.
    const Outcome o =
        lodforge("reconstruct " + autzen + voxel + " --decimate 0 -o " + dir.file("r.ply"), dir);
    EXPECT_EQ(o.code, 0) << o.err;
    std::smatch m;
    EXPECT_TRUE(std::regex_search(o.out, m, std::regex("voxel ([0-9.]+)"))) << o.out;
    used = m.empty() ? 0 : std::stod(m[1]);
    return triangles(dir.file("r.ply"), dir);
  };
  const auto tiled = [&](const std::string& voxel, double& used) -> std::uint64_t {
    const Outcome o =
        lodforge("tiles " + autzen + " --surface" + voxel + " -o " + dir.file("t"), dir);
    EXPECT_EQ(o.code, 0) << o.err;
    std::smatch m;
    EXPECT_TRUE(std::regex_search(
        o.out, m, std::regex("reconstructed ([0-9,]+) triangles .*\\(voxel ([0-9.]+)")))
        << o.out;
    if (m.empty()) return 0;
    used = std::stod(m[2]);
    return std::stoull(std::regex_replace(m[1].str(), std::regex(","), ""));
  };
  double a = 0, b = 0;
  const std::uint64_t r = reconstructed(" --voxel 10", a), t = tiled(" --voxel 10", b);
  EXPECT_EQ(a, 10);
  EXPECT_EQ(b, 10);
  // Not the same to the triangle: tiles --surface reconstructs in the local frame on Earth,
  // turned from the CRS's grid (52,836 and 52,516 triangles).
  EXPECT_GT(t, r * 97 / 100) << "reconstruct " << r << ", tiles --surface " << t;
  EXPECT_LT(t, r * 103 / 100) << "reconstruct " << r << ", tiles --surface " << t;
  reconstructed("", a);
  tiled("", b);
  EXPECT_NEAR(a, b, 0.01 * a) << "default voxel: reconstruct " << a << ", tiles " << b;
}

// A voxel larger than the cloud is refused with the cloud's size and a voxel that works.
TEST(OddInput, AVoxelLargerThanTheCloudIsRefused) {
  test::TempDir dir;
  const Outcome o = lodforge(
      "reconstruct " + test::dataPath("points/kitten.xyz") + " --voxel 1e9 -o " + dir.file("k.ply"),
      dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("--voxel 1e+09 is more than a quarter of the cloud, which is "),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("or less, or leave it out"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("k.ply")));
}

// An OFF without colours has none (assimp's grey default material is not the file's).
TEST(OddInput, AnOffWithoutColoursSaysNone) {
  test::TempDir dir;
  test::writeFile(dir.file("cube.off"),
                  "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                  "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  Outcome o = lodforge("info --json " + dir.file("cube.off"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(nlohmann::json::parse(o.out)["colors"], false) << o.out;
  o = lodforge("info " + dir.file("cube.off"), dir);
  EXPECT_EQ(o.out.find("colors"), std::string::npos) << o.out;
}

// A PLY element none of our readers reads (edges here) is named in a warning on every path that
// streams a PLY: a mesh into tiles, a point cloud into tiles, a cloud package or a surface,
// objects into a package.
TEST(OddInput, AnUnreadPlyElementIsNamedByEveryStreamingReader) {
  test::TempDir dir;
  const std::string vertices =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string edges = "element edge 2\nproperty int vertex1\nproperty int vertex2\n";
  const std::string points = "0 0 0\n1 0 0\n1 1 0\n0 1 1\n";
  test::writeFile(dir.file("mesh.ply"),
                  "ply\nformat ascii 1.0\n" + vertices + edges +
                      "element face 2\nproperty list uchar int vertex_indices\n"
                      "property int object_id\nend_header\n" +
                      points + "0 1\n1 2\n3 0 1 2 0\n3 0 2 3 1\n");
  test::writeFile(dir.file("cloud.ply"), "ply\nformat ascii 1.0\n" + vertices + edges +
                                             "end_header\n" + points + "0 1\n1 2\n");
  // A generated cloud with two edges after its vertices, for the commands that need a surface's
  // worth of points.
  ASSERT_EQ(lodforge("-q generate points --points 3K -o " + dir.file("g.ply"), dir).code, 0);
  std::string generated = test::readFile(dir.file("g.ply"));
  const std::size_t header = generated.find("end_header\n");
  ASSERT_NE(header, std::string::npos);
  generated.insert(header, edges);
  generated += std::string(16, '\0');  // two edges of two ints
  test::writeFile(dir.file("edges.ply"), generated);
  for (const std::string& command :
       {"tiles " + dir.file("mesh.ply") + " -o " + dir.file("mesh-tiles"),
        "tiles " + dir.file("cloud.ply") + " -o " + dir.file("cloud-tiles"),
        "build " + dir.file("mesh.ply") + " -o " + dir.file("mesh.lfp"),
        "points " + dir.file("edges.ply") + " -o " + dir.file("edges.lfc"),
        "reconstruct " + dir.file("edges.ply") + " -o " + dir.file("surface.ply"),
        "tiles --surface " + dir.file("edges.ply") + " -o " + dir.file("surface-tiles")}) {
    const Outcome o = lodforge(command, dir);
    ASSERT_EQ(o.code, 0) << command << "\n" << o.err;
    // Once: a package's ungrouped PLY is read again whole, which must not warn twice.
    const std::string warning = "element not read: 'edge' (2)";
    const std::size_t first = o.err.find(warning);
    EXPECT_NE(first, std::string::npos) << command << "\n" << o.err;
    EXPECT_EQ(o.err.find(warning, first + 1), std::string::npos) << command << "\n" << o.err;
  }
}

// A point cloud cut short and read with --salvage says so in every command that reads clouds.
TEST(DamagedInput, ASalvagedCloudCutShortIsNamedByEveryCloudCommand) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 3K -o " + dir.file("c.ply"), dir).code, 0);
  const std::string whole = test::readFile(dir.file("c.ply"));
  test::writeFile(dir.file("cut.ply"), whole.substr(0, whole.size() * 3 / 4));
  for (const std::string& command :
       {"points --salvage " + dir.file("cut.ply") + " -o " + dir.file("c.lfc"),
        "reconstruct --salvage " + dir.file("cut.ply") + " -o " + dir.file("surface.ply"),
        "tiles --surface --salvage " + dir.file("cut.ply") + " -o " + dir.file("s"),
        "tiles --salvage " + dir.file("cut.ply") + " -o " + dir.file("t")}) {
    const Outcome o = lodforge(command, dir);
    ASSERT_EQ(o.code, 0) << command << "\n" << o.err;
    EXPECT_NE(o.err.find("warning: " + dir.file("cut.ply")), std::string::npos) << command << "\n"
                                                                                << o.err;
    EXPECT_NE(o.err.find("file ends inside"), std::string::npos) << command << "\n" << o.err;
  }
}

// Empty files: convert refuses a model without triangles as tiles and build do; info refuses a
// zero-byte file and a text cloud without points.
TEST(OddInput, EmptyFilesAreRefusedByEveryCommand) {
  test::TempDir dir;
  test::writeFile(dir.file("empty.obj"), "");
  test::writeFile(dir.file("comments.obj"), "# nothing here\n");
  test::writeFile(dir.file("empty.xyz"), "");
  test::writeFile(dir.file("comments.xyz"), "# x y z\n");
  for (const std::string& args :
       {"convert " + dir.file("empty.obj") + " -o " + dir.file("e.ply"),
        "convert " + dir.file("comments.obj") + " -o " + dir.file("c.ply"),
        "tiles " + dir.file("empty.obj") + " -o " + dir.file("t"),
        "build " + dir.file("empty.obj") + " -o " + dir.file("b.lfp"),
        "info " + dir.file("empty.obj"), "info " + dir.file("comments.obj"),
        "info " + dir.file("empty.xyz"), "info " + dir.file("comments.xyz")}) {
    const Outcome o = lodforge(args, dir);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.err;
    EXPECT_NE(o.err.find(dir.path()), std::string::npos) << args << "\n" << o.err;
  }
  for (const char* name : {"e.ply", "c.ply", "t", "b.lfp"})
    EXPECT_FALSE(std::filesystem::exists(dir.file(name))) << name;
}

// compare of a mesh and a point cloud says the cloud has no triangles, before any table.
TEST(OddInput, CompareNamesTheSideThatIsNoSurface) {
  test::TempDir dir;
  const Outcome o = lodforge(
      "compare " + test::dataPath("meshes/horse.ply") + " " + test::dataPath("points/kitten.xyz"),
      dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("kitten.xyz: a point cloud: it has no triangles to measure"),
            std::string::npos)
      << o.err;
  EXPECT_EQ(o.err.find("PNG"), std::string::npos) << o.err;
  EXPECT_TRUE(o.out.empty()) << o.out;
}

// build of a STEP file counts the read and the tessellation in its time and rate.
TEST(OddInput, BuildTimesTheWholeRunOfACadFile) {
  test::TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  const Outcome o =
      lodforge("build " + test::dataPath("cad/as1_motor.step") + " -o " + dir.file("m.lfp"), dir);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(o.code, 0) << o.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.out, m, std::regex(" in ([0-9.]+) s \\("))) << o.out;
  // The process's own start and exit are outside its clock, not the read.
  EXPECT_GE(std::stod(m[1]) + 0.15, 0.5 * wall) << o.out << " in " << wall << " s";
}

// One rule for every command: a --memory-limit too small is a limit (exit 1) naming the least
// that works; a count of threads is whole.
TEST(OddInput, AMemoryLimitTooSmallIsExitCode1InEveryCommand) {
  test::TempDir dir;
  const std::string kitten = test::dataPath("points/kitten.xyz");
  for (const std::string& args :
       {"--memory-limit 1M reconstruct " + kitten + " -o " + dir.file("k.ply"),
        "--memory-limit 1M tiles " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("t"),
        "--memory-limit 1M points " + kitten + " -o " + dir.file("k.lfc"),
        "--memory-limit 1M build " + test::dataPath("meshes/horse.ply") + " -o " +
            dir.file("h.lfp"),
        "--memory-limit 1M convert " + test::dataPath("points/autzen_trim.laz") + " -o " +
            dir.file("a.las")}) {
    const Outcome o = lodforge(args, dir);
    EXPECT_EQ(o.code, 1) << args << "\n" << o.err;
    EXPECT_NE(o.err.find("at least"), std::string::npos) << args << "\n" << o.err;
  }
  const Outcome o = lodforge("--threads 1.5 info " + kitten, dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("--threads"), std::string::npos) << o.err;
}

// The next run at an output removes what a run killed there (SIGKILL) left, and nothing else.
TEST(OddInput, ARunRemovesTheLeftoversOfADeadRunAtItsOutput) {
  test::TempDir dir;
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // a PID no process has now
  const std::string leftover = dir.file(fmt::format("horse.glb.tmp-{}-0", child));
  const std::string work = dir.file(fmt::format("k.lfc.work.tmp-{}-1", child));
  test::writeFile(leftover, "half a GLB");
  std::filesystem::create_directories(work);
  test::writeFile(dir.file("notes.glb.tmp-1-0"), "not this output's");
  Outcome o = lodforge(
      "convert " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("horse.glb"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_FALSE(std::filesystem::exists(leftover));
  EXPECT_TRUE(std::filesystem::exists(work)) << "another output's";
  EXPECT_TRUE(std::filesystem::exists(dir.file("notes.glb.tmp-1-0")));
  o = lodforge("points " + test::dataPath("points/kitten.xyz") + " -o " + dir.file("k.lfc"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_FALSE(std::filesystem::exists(work));
}

// info lists classification codes by number (2, 3, 4, 11, 14, 31), not as text (11, 14, 2 …).
TEST(OddInput, InfoListsClassesInNumberOrder) {
  test::TempDir dir;
  std::string las = test::readFile(test::dataPath("points/simple.las"));
  std::uint32_t first = 0;
  std::uint16_t length = 0;
  std::memcpy(&first, las.data() + 96, 4);
  std::memcpy(&length, las.data() + 105, 2);
  const unsigned char classes[] = {2, 11, 3, 31, 14, 4};
  for (std::size_t i = 0, at = first + 15; at < las.size(); ++i, at += length)
    las[at] = static_cast<char>(classes[i % 6]);
  test::writeFile(dir.file("classes.las"), las);
  const Outcome o = lodforge("info " + dir.file("classes.las"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  std::size_t previous = 0;
  for (const int c : {2, 3, 4, 11, 14, 31}) {
    const std::size_t at = o.out.find(fmt::format("class {:<9}", c));
    ASSERT_NE(at, std::string::npos) << c << "\n" << o.out;
    EXPECT_GT(at, previous) << "class " << c << " out of order:\n" << o.out;
    previous = at;
  }
}

}  // namespace
}  // namespace lodforge
