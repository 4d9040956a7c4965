// The `lodforge` command as users run it: real binary, real files, exit codes and messages.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <assimp/material.h>
#include <assimp/scene.h>
#include <httplib.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/render/image.h"
#include "run_lodforge.h"
#include "test_support.h"

extern char** environ;

namespace lodforge {
namespace {

using test::glSubprocess;
using test::lodforge;
using test::Outcome;

// `lodforge build` of a model in ../shared/data/meshes into `package`; the exit code.
int buildPackage(const std::string& model, const std::string& package, const test::TempDir& dir) {
  return lodforge("build " + test::dataPath("meshes/" + model) + " -o " + package, dir).code;
}

nlohmann::json info(const std::string& path, const test::TempDir& dir) {
  const Outcome o = lodforge("info --json " + path, dir);
  EXPECT_EQ(o.code, 0) << o.err;
  return nlohmann::json::parse(o.out);
}

// Starts `lodforge ARGS` without a shell (so signals reach it), stderr to `errPath` if given.
pid_t spawnLodforge(std::vector<std::string> args, const std::string& errPath = "",
                    const std::string& outPath = "") {
  const std::string binary = LODFORGE_BINARY;
  args.insert(args.begin(), binary);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (!errPath.empty())
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
  if (!outPath.empty())
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
  pid_t pid = 0;
  const int started = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  EXPECT_EQ(started, 0);
  return pid;
}

struct Finished {
  int code = -1;           // exit code, -1 if killed
  std::uint64_t peak = 0;  // peak RSS in bytes
};

Finished waitFor(pid_t pid) {
  int status = 0;
  struct rusage usage {};
  EXPECT_EQ(::wait4(pid, &status, 0, &usage), pid);
  Finished f;
  f.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  f.peak = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;
  return f;
}

TEST(Cli, VersionHelpAndUsageErrors) {
  test::TempDir dir;
  Outcome o = lodforge("--version", dir);
  EXPECT_EQ(o.code, 0);
  EXPECT_EQ(o.out, "lodforge " LODFORGE_VERSION "\n");
  o = lodforge("--help", dir);
  EXPECT_EQ(o.code, 0);
  EXPECT_NE(o.out.find("generate"), std::string::npos);
  o = lodforge("generate cad --help", dir);
  EXPECT_EQ(o.code, 0);
  EXPECT_NE(o.out.find("--objects"), std::string::npos);
  EXPECT_EQ(lodforge("", dir).code, 2);
  EXPECT_EQ(lodforge("frobnicate", dir).code, 2);
  o = lodforge("generate cad --objects 10X", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("expected a count such as"), std::string::npos) << o.err;
  o = lodforge("--memory-limit lots info x.ply", dir);
  EXPECT_EQ(o.code, 2);
  o = lodforge("info " + dir.file("model.abc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("unknown format"), std::string::npos) << o.err;
  o = lodforge("info " + dir.file("missing.ply"), dir);
  EXPECT_EQ(o.code, 1);  // the system failed, not the input
  EXPECT_NE(o.err.find("missing.ply: cannot stat: No such file"), std::string::npos) << o.err;
}

TEST(Cli, MemoryLimitIsHonouredOrRefusedWithTheLeastThatWorks) {
  test::TempDir dir;
  const std::string cloud = test::dataPath("points/simple.las");
  const std::string mesh = test::dataPath("meshes/horse.ply");
  struct Case {
    std::string args;
    int code;
    std::string says;
  };
  for (const Case& c : {
           Case{"--memory-limit 1K tiles " + cloud + " -o " + dir.file("t"), 1, "at least"},
           Case{"--memory-limit 1K tiles " + mesh + " -o " + dir.file("t"), 1,
                "--memory-limit 1.00 KiB is too small for tiles: at least 48.0 MiB"},
           Case{"--memory-limit 1K points " + cloud + " -o " + dir.file("c.lfc"), 1, "at least"},
           Case{"--memory-limit 1K build " + mesh + " -o " + dir.file("h.lfp"), 1, "at least"},
           Case{"--memory-limit 0 build " + mesh + " -o " + dir.file("h.lfp"), 2, "means nothing"},
           Case{"--memory-limit 1G info " + mesh, 2, "info does not take --memory-limit"},
           Case{"--memory-limit 1G convert " + test::dataPath("meshes/as1_motor.glb") + " -o " +
                    dir.file("m.ply"),
                2, "PLY input only"},
       }) {
    const Outcome o = lodforge(c.args, dir);
    EXPECT_EQ(o.code, c.code) << c.args << "\n" << o.err;
    EXPECT_NE(o.err.find(c.says), std::string::npos) << c.args << "\n" << o.err;
    EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{}) << c.args;
  }
}

TEST(Cli, ThreadsOptionSaysWhatItTakes) {
  test::TempDir dir;
  const std::string mesh = test::dataPath("meshes/horse.ply");
  Outcome o = lodforge("--threads -1 info " + mesh, dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("expected 0 (all cores) or a number of threads"), std::string::npos)
      << o.err;
  EXPECT_LT(o.err.size(), 200u) << "no range of 300 digits: " << o.err;
  o = lodforge("--threads 100000 info " + mesh, dir);
  EXPECT_EQ(o.code, 2) << o.err;
  o = lodforge("--threads 1000 info " + mesh, dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("--threads 1000: this process may run on"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("TBB"), std::string::npos) << o.err;
  o = lodforge("--help", dir);
  EXPECT_NE(o.out.find("0 or left out for all cores"), std::string::npos) << o.out;
}

TEST(Cli, UnknownFormatsSayWhatEachCommandReadsAndHowToBringThemIn) {
  test::TempDir dir;
  for (const char* name : {"part.wrl", "part.vtk", "house.ifc", "scan.e57", "cloud.pcd", "a.xyz3"})
    test::writeFile(dir.file(name), "not read\n");
  struct Case {
    std::string args;
    std::vector<std::string> says;
  };
  for (const Case& c : {
           // Advice only with tools that read the format (Debian's assimp reads neither).
           Case{"info " + dir.file("part.wrl"),
                {"a VRML scene", "MeshLab or Blender", ".las .laz", ".lfp .lfc packages"}},
           Case{
               "tiles " + dir.file("part.vtk") + " -o " + dir.file("t"),
               {"a VTK mesh", "ParaView", ".glb meshes", ".step", ".fbx", ".las", ".lfp packages"}},
           // A format assimp reads, but not a file of it: assimp's reason, naming the file.
           Case{"build " + dir.file("house.ifc") + " -o " + dir.file("h.lfp"),
                {dir.file("house.ifc") + ": assimp: "}},
           Case{"points " + dir.file("scan.e57") + " -o " + dir.file("s.lfc"),
                {"an E57 scan", ".las .laz .ply .xyz .txt .csv .pts point clouds"}},
           Case{"tiles " + dir.file("cloud.pcd") + " -o " + dir.file("t"), {"a PCL point cloud"}},
           Case{"convert " + dir.file("a.xyz3") + " -o " + dir.file("a.ply"),
                {"unknown format (this command reads .ply .obj"}},
       }) {
    const Outcome o = lodforge(c.args, dir);
    EXPECT_EQ(o.code, 2) << c.args << "\n" << o.err;
    for (const std::string& s : c.says)
      EXPECT_NE(o.err.find(s), std::string::npos) << c.args << ": " << s << "\n" << o.err;
    EXPECT_EQ(o.err.find("assimp export"), std::string::npos) << c.args << "\n" << o.err;
  }
  EXPECT_EQ(test::listFolder(dir.path()).size(), 6u) << "nothing written";
}

// A directory given where a file is read: every command says so (exit 2), leaves nothing, and
// never aborts, whatever the directory's name claims it is.
TEST(Cli, EveryCommandRefusesADirectoryAsInput) {
  test::TempDir dir;
  for (const char* name : {"adir.ply", "adir.glb", "adir.las", "adir.lfp", "adir.lfc", "adir"})
    std::filesystem::create_directories(dir.file(name));
  const std::vector<std::string> before = test::listFolder(dir.path());
  const auto in = [&](const char* name) { return dir.file(name); };
  for (const std::string& args : {
           "info " + in("adir.ply"),
           "info " + in("adir"),
           "info " + in("adir.lfp"),
           "info " + in("adir.lfc"),
           "info " + in("adir.las"),
           "tiles " + in("adir.ply") + " -o " + dir.file("out"),
           "tiles " + in("adir") + " -o " + dir.file("out"),
           "tiles " + in("adir.las") + " -o " + dir.file("out"),
           "tiles " + in("adir.lfp") + " -o " + dir.file("out"),
           "build " + in("adir.glb") + " -o " + dir.file("m.lfp"),
           "convert " + in("adir.ply") + " -o " + dir.file("m.obj"),
           "extract " + in("adir.lfp") + " --ratio 0.5 -o " + dir.file("m.ply"),
           "points " + in("adir.las") + " -o " + dir.file("c.lfc"),
           "bench " + in("adir.lfp") + " --frames 2",
           "bench " + in("adir.lfc") + " --frames 2",
       }) {
    const Outcome o = lodforge(args, dir);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.err;
    EXPECT_NE(o.err.find("is a directory"), std::string::npos) << args << "\n" << o.err;
    EXPECT_EQ(o.err.find("terminate"), std::string::npos) << args << "\n" << o.err;
    EXPECT_EQ(test::listFolder(dir.path()), before) << args << ": nothing left";
  }
}

// A PLY cut short names the option that reads what is there, and every command that reads
// meshes from PLY takes it (tiles too).
TEST(Cli, ATruncatedPlySaysSalvageAndEveryMeshCommandTakesIt) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate scan --triangles 4K -o " + dir.file("scan.ply"), dir).code, 0);
  const std::string bytes = test::readFile(dir.file("scan.ply"));
  test::writeFile(dir.file("cut.ply"), bytes.substr(0, bytes.size() * 3 / 4));
  for (const std::string& command :
       {std::string("info"), std::string("build"), std::string("convert"), std::string("tiles")}) {
    const std::string out = command == "build"     ? " -o " + dir.file("c.lfp")
                            : command == "convert" ? " -o " + dir.file("c.glb")
                            : command == "tiles"   ? " -o " + dir.file("t")
                                                   : "";
    Outcome o = lodforge(command + " " + dir.file("cut.ply") + out, dir);
    EXPECT_EQ(o.code, 2) << command << "\n" << o.err;
    EXPECT_NE(o.err.find("--salvage"), std::string::npos) << command << "\n" << o.err;
    o = lodforge(command + " " + dir.file("cut.ply") + out + " --salvage", dir);
    EXPECT_EQ(o.code, 0) << command << " --salvage\n" << o.err;
    EXPECT_NE((o.err + o.out).find("cut.ply"), std::string::npos)
        << command << ": a warning names the cut\n"
        << o.err;
  }
  nlohmann::json tileset = nlohmann::json::parse(test::readFile(dir.file("t/tileset.json")));
  EXPECT_TRUE(tileset["root"].contains("children")) << "a mesh tileset of what was there";
}

TEST(Cli, MeshCommandsRefusePointCloudsAndModelsWithoutTriangles) {
  test::TempDir dir;
  const std::string cloud = test::dataPath("points/simple.las");
  test::writeFile(dir.file("vertices.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
  struct Case {
    std::string args, says;
  };
  for (const Case& c : {
           Case{"build " + cloud + " -o " + dir.file("c.lfp"), "a point cloud; build takes meshes"},
           Case{"convert " + cloud + " -o " + dir.file("c.ply"), "a point cloud; convert takes"},
           Case{"build " + dir.file("vertices.ply") + " -o " + dir.file("v.lfp"), "no triangles"},
       }) {
    const Outcome o = lodforge(c.args, dir);
    EXPECT_EQ(o.code, 2) << c.args << "\n" << o.err;
    EXPECT_NE(o.err.find(c.says), std::string::npos) << c.args << "\n" << o.err;
    EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"vertices.ply"}) << c.args;
  }
}

TEST(Cli, InfoReportsEveryRealModel) {
  test::TempDir dir;
  struct Case {
    const char* file;
    std::uint64_t vertices, triangles, objects;
  };
  for (const Case& c : {Case{"meshes/stanford-bunny.obj", 34'834, 69'451, 1},
                        Case{"meshes/horse.ply", 48'485, 96'966, 1},
                        Case{"meshes/2CylinderEngine.glb", 84'657, 121'496, 67},
                        Case{"meshes/as1_motor.glb", 21'980, 27'506, 35},
                        Case{"meshes/Motor-c.glb", 22'374, 30'682, 17}}) {
    const nlohmann::json j = info(test::dataPath(c.file), dir);
    EXPECT_EQ(j["vertices"], c.vertices) << c.file;
    EXPECT_EQ(j["triangles"], c.triangles) << c.file;
    EXPECT_EQ(j["objects"], c.objects) << c.file;
    EXPECT_GT(j["memoryBytes"].get<std::uint64_t>(), c.triangles * 12) << c.file;
    EXPECT_LT(j["bounds"]["min"][0].get<double>(), j["bounds"]["max"][0].get<double>());
  }
  const Outcome text = lodforge("info " + test::dataPath("meshes/horse.ply"), dir);
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("triangles  96,966"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("PLY binary_little_endian"), std::string::npos);
}

TEST(Cli, ConvertBetweenEveryFormat) {
  test::TempDir dir;
  const std::string bunny = test::dataPath("meshes/stanford-bunny.obj");
  for (const char* ext : {"ply", "glb", "obj", "stl"}) {
    const std::string out = dir.file(std::string("bunny.") + ext);
    const Outcome o = lodforge("convert " + bunny + " -o " + out, dir);
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_NE(o.out.find("69,451 triangles"), std::string::npos) << o.out;
    EXPECT_EQ(info(out, dir)["triangles"], 69'451u) << ext;
  }
  // Welding a soup restores shared vertices.
  Outcome o = lodforge(
      "convert " + dir.file("bunny.stl") + " -o " + dir.file("welded.ply") + " --weld", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("welded.ply"), dir)["vertices"], 34'834u);
  o = lodforge("convert " + bunny + " -o " + dir.file("bunny.gltf"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("convert does not write this format (it writes .ply .glb .obj .stl models, "
                       "and .las from .las or .laz point clouds)"),
            std::string::npos)
      << o.err;
  // LAZ is not written, and the message says what is (it used to leave .las out).
  o = lodforge("convert " + test::dataPath("points/simple.las") + " -o " + dir.file("x.laz"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("convert does not write LAZ (compressed LAS)"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.laz")));
}

TEST(Cli, GenerateWritesWhatInfoReads) {
  test::TempDir dir;
  Outcome o = lodforge("generate cad --objects 400 --seed 3 -o " + dir.file("cad.glb"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("400 objects"), std::string::npos) << o.out;
  EXPECT_EQ(info(dir.file("cad.glb"), dir)["objects"], 400u);
  o = lodforge("generate cad --objects 400 --seed 3 -o " + dir.file("cad.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("cad.ply"), dir)["objects"], 400u);
  o = lodforge("generate cad --objects 40 --seed 3 -o " + dir.file("cad.step"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("40 parts as B-rep"), std::string::npos) << o.out;
  EXPECT_EQ(info(dir.file("cad.step"), dir)["objects"], 40u);
  o = lodforge("generate scan --triangles 10K -o " + dir.file("scan.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("scan.ply"), dir)["triangles"], 10'000u);
  o = lodforge("-q generate points --points 2.5K -o " + dir.file("points.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.out, "");  // quiet
  EXPECT_EQ(info(dir.file("points.ply"), dir)["vertices"], 2'500u);
  o = lodforge("generate scan --triangles 100 -o " + dir.file("scan.obj"), dir);
  EXPECT_EQ(o.code, 2);
}

// Every file of the malformed corpus: exit code 2, a message naming the file and the position,
// and nothing written by a conversion that fails.
TEST(Cli, MalformedCorpusGetsExitCode2AndAPositionedMessage) {
  test::TempDir dir;
  std::ifstream expected(test::testDataPath("malformed/expected.tsv"));
  ASSERT_TRUE(expected) << "missing tests/data/malformed/expected.tsv";
  std::string line;
  int cases = 0;
  while (std::getline(expected, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::string file = line.substr(0, line.find('\t'));
    const std::string fragment = line.substr(line.find('\t') + 1);
    const std::string path = test::testDataPath("malformed/" + file);
    for (const std::string& command :
         {"info " + path, "convert " + path + " -o " + dir.file("out.glb")}) {
      const Outcome o = lodforge(command, dir);
      EXPECT_EQ(o.code, 2) << command << "\n" << o.err;
      EXPECT_EQ(o.err.rfind("lodforge: " + path, 0), 0u) << o.err;
      EXPECT_NE(o.err.find(fragment), std::string::npos) << file << ": " << o.err;
      EXPECT_EQ(o.err.find('\n'), o.err.size() - 1) << "one line: " << o.err;
    }
    EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{}) << file;
    ++cases;
  }
  EXPECT_GE(cases, 25);
}

TEST(Cli, DamagedRealFileIsRefused) {
  test::TempDir dir;
  const Outcome o = lodforge("info " + test::dataPath("points/pond.0.ply"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("the file is truncated"), std::string::npos) << o.err;
}

TEST(Cli, MemoryLimitRefusesBeforeLoading) {
  test::TempDir dir;
  const Outcome o = lodforge("--memory-limit 1M convert " + test::dataPath("meshes/horse.ply") +
                                 " -o " + dir.file("h.glb"),
                             dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.err.find("--memory-limit is 1.00 MiB"), std::string::npos) << o.err;
  EXPECT_TRUE(test::listFolder(dir.path()).empty());
}

TEST(Cli, CtrlCCancelsAndLeavesNothingBehind) {
  test::TempDir dir;
  const std::string output = dir.file("big.ply");
  const std::string binary = LODFORGE_BINARY;
  std::vector<std::string> args = {binary, "generate", "scan", "--triangles", "50M", "-o", output};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string err = dir.file(".stderr");
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Wait until the temporary output exists, i.e. the generator is writing.
  bool writing = false;
  for (int i = 0; i < 600 && !writing; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    for (const std::string& name : test::listFolder(dir.path()))
      writing = writing || name.starts_with("big.ply.tmp");
  }
  ASSERT_TRUE(writing);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_NE(test::readFile(err).find("lodforge: cancelled"), std::string::npos)
      << test::readFile(err);
  std::remove(err.c_str());
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{});
}

TEST(CliPackage, BuildInfoAndExtract) {
  test::TempDir dir;
  const std::string package = dir.file("bunny.lfp");
  Outcome o =
      lodforge("build " + test::dataPath("meshes/stanford-bunny.obj") + " -o " + package, dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("69,451 triangles"), std::string::npos) << o.out;
  const nlohmann::json j = info(package, dir);
  EXPECT_EQ(j["format"], "lodforge package");
  EXPECT_EQ(j["objects"], 1u);
  EXPECT_EQ(j["vertices"], 34'834u);
  EXPECT_EQ(j["triangles"], 69'451u);
  EXPECT_LT(j["minTriangles"].get<std::uint64_t>(), 1000u);
  EXPECT_GT(j["lodBytes"].get<std::uint64_t>(), 0u);
  const Outcome text = lodforge("info " + package, dir);
  EXPECT_NE(text.out.find("LOD data   ECol + Map + error"), std::string::npos) << text.out;

  o = lodforge("extract " + package + " --ratio 0.1 -o " + dir.file("tenth.glb"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const auto tenth = info(dir.file("tenth.glb"), dir);
  EXPECT_NEAR(tenth["vertices"].get<double>(), 3483, 1);
  o = lodforge("extract " + package + " --error 0.001 -o " + dir.file("err.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_LT(info(dir.file("err.ply"), dir)["triangles"].get<std::uint64_t>(), 69'451u);
  EXPECT_EQ(
      lodforge("extract " + package + " --ratio 0.5 --error 1 -o " + dir.file("x.glb"), dir).code,
      2);
  EXPECT_EQ(lodforge("extract " + package + " --ratio 2 -o " + dir.file("x.glb"), dir).code, 2);
  EXPECT_EQ(
      lodforge("build " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("horse.glb"), dir)
          .code,
      2);
}

// A textured OBJ through build, info, extract and render: the package carries the coordinates
// and the four JPEGs, every level comes out textured (GLB with them embedded, OBJ with them
// beside), and the frames are drawn from it.
TEST(CliPackage, ATexturedModelKeepsItsTexturesThroughBuildExtractAndRender) {
  test::TempDir dir;
  const std::string package = dir.file("spider.lfp");
  Outcome o =
      lodforge("build " + test::dataPath("textured/spider/spider.obj") + " -o " + package, dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("warning"), std::string::npos) << o.err;
  const nlohmann::json j = info(package, dir);
  ASSERT_TRUE(j.contains("textures")) << j.dump();
  EXPECT_EQ(j["textures"]["images"].size(), 4u);
  EXPECT_EQ(j["textures"]["images"][0]["format"], "JPEG");
  for (const char* ratio : {"1", "0.3", "0"}) {
    const std::string glb = dir.file(std::string("lod") + ratio + ".glb");
    o = lodforge("extract " + package + " --ratio " + ratio + " -o " + glb, dir);
    ASSERT_EQ(o.code, 0) << o.err;
    const nlohmann::json level = info(glb, dir);
    ASSERT_TRUE(level.contains("textures")) << ratio << ": " << level.dump();
    EXPECT_EQ(level["textures"]["images"].size(), 4u) << ratio;
    EXPECT_TRUE(level["uvs"].get<bool>()) << ratio;
  }
  o = lodforge("extract " + package + " --ratio 0.5 -o " + dir.file("half/spider.obj"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("half/spider.mtl")));
  EXPECT_EQ(info(dir.file("half/spider.obj"), dir)["textures"]["images"].size(), 4u);
  // A textured PLY of several objects (object_id per face) is read whole, textures and all.
  o = lodforge("extract " + package + " --ratio 0.5 -o " + dir.file("ply/spider.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("build " + dir.file("ply/spider.ply") + " -o " + dir.file("again.lfp"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("again.lfp"), dir)["textures"]["images"].size(), 4u);
  o = lodforge(
      "render " + package + " --frames 1 --size 160x120 --budget 50% -o " + dir.file("frames"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("frames/frame_0000.png")));
}

nlohmann::json glbJson(const std::string& path);

// 2CylinderEngine repeats 29 shapes in 67 objects: `build` places the repeats and `extract` writes
// 29 meshes; with --no-instances every object is built and written on its own. The package does
// not depend on the thread count.
TEST(CliPackage, RepeatedShapesAreBuiltOnceUnlessAskedNotTo) {
  test::TempDir dir;
  const std::string input = test::dataPath("meshes/2CylinderEngine.glb");
  Outcome o = lodforge("build " + input + " -o " + dir.file("a.lfp"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("67 objects (38 placed again from an earlier one's shape)"),
            std::string::npos)
      << o.out;
  ASSERT_EQ(lodforge("-q --threads 1 build " + input + " -o " + dir.file("one.lfp"), dir).code, 0);
  EXPECT_TRUE(test::readFile(dir.file("a.lfp")) == test::readFile(dir.file("one.lfp")))
      << "the package depends on the thread count";
  o = lodforge("build " + input + " --no-instances -o " + dir.file("own.lfp"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.out.find("placed again"), std::string::npos) << o.out;
  // Built on their own, most placements simplify differently and no longer match.
  std::size_t meshes[2] = {};
  for (int i = 0; i < 2; ++i) {
    const std::string package = dir.file(i == 0 ? "a.lfp" : "own.lfp"), glb = package + ".glb";
    ASSERT_EQ(lodforge("-q extract " + package + " --ratio 0.5 -o " + glb, dir).code, 0);
    meshes[i] = glbJson(glb)["meshes"].size();
  }
  EXPECT_EQ(meshes[0], 29u);
  EXPECT_GT(meshes[1], 2 * 29u);
}

TEST(CliPackage, DamagedPackagesAreRefusedWithExitCode2) {
  test::TempDir dir;
  const std::string package = dir.file("m.lfp");
  ASSERT_EQ(
      lodforge("-q build " + test::dataPath("meshes/Motor-c.glb") + " -o " + package, dir).code, 0);
  const std::string bytes = test::readFile(package);
  test::writeFile(dir.file("cut.lfp"), bytes.substr(0, bytes.size() - 100));
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 1;
  test::writeFile(dir.file("flipped.lfp"), flipped);
  test::writeFile(dir.file("text.lfp"), "not a package at all, just some text that is long enough");
  for (const char* name : {"cut.lfp", "flipped.lfp", "text.lfp"}) {
    for (const std::string& command :
         {"info " + dir.file(name), "extract " + dir.file(name) + " -o " + dir.file("out.glb")}) {
      const Outcome o = lodforge(command, dir);
      EXPECT_EQ(o.code, 2) << name << ": " << o.err;
      EXPECT_EQ(o.err.rfind("lodforge: " + dir.file(name) + ": byte ", 0), 0u) << o.err;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.glb")));
}

// The memory limit is real: a model several times larger than the limit builds under it.
TEST(CliPackage, BuildStaysUnderItsMemoryLimit) {
#ifdef LODFORGE_SANITIZED
  GTEST_SKIP() << "peak RSS means nothing under ASan (shadow memory, quarantine); the release "
                  "build checks it";
#endif
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate cad --objects 20K --seed 3 -o " + dir.file("big.ply"), dir).code,
            0);
  const auto inputBytes = std::filesystem::file_size(dir.file("big.ply"));
  constexpr std::uint64_t kLimit = 96ull << 20;
  ASSERT_GT(inputBytes, 2 * kLimit);  // the input is larger than the limit
  const Finished run = waitFor(spawnLodforge(
      {"-q", "--memory-limit", "96M", "build", dir.file("big.ply"), "-o", dir.file("big.lfp")}));
  ASSERT_EQ(run.code, 0);
  EXPECT_LT(run.peak, kLimit) << "peak RSS " << run.peak / (1 << 20) << " MiB";
  EXPECT_EQ(info(dir.file("big.lfp"), dir)["objects"], 20'000u);
}

TEST(CliPoints, BuildsAPackageFromLasAndInfoReportsBoth) {
  test::TempDir dir;
  const std::string las = test::dataPath("points/autzen_trim.las");
  const nlohmann::json header = info(las, dir);
  EXPECT_EQ(header["format"], "LAS");
  EXPECT_EQ(header["version"], "1.2");
  EXPECT_EQ(header["pointFormat"], 3);
  EXPECT_EQ(header["points"], 110'000);
  EXPECT_EQ(header["colorBits"], 8);
  EXPECT_NE(header["crs"].get<std::string>().find("Lambert_Conformal_Conic"), std::string::npos);
  EXPECT_DOUBLE_EQ(header["bounds"]["min"][0].get<double>(), 636001.76);
  const Outcome o =
      lodforge("-v points " + las + " -o " + dir.file("autzen.lfc") + " --block-size 20K", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("110,000 points"), std::string::npos) << o.out;
  EXPECT_NE(o.err.find("normals estimated"), std::string::npos) << o.err;
  const nlohmann::json cloud = info(dir.file("autzen.lfc"), dir);
  EXPECT_EQ(cloud["points"], 110'000);
  EXPECT_GE(cloud["blocks"].get<int>(), 110'000 / 20'000);
  EXPECT_LE(cloud["blockPoints"][1].get<int>(), 20'000);
  EXPECT_EQ(cloud["crs"], header["crs"]);
  EXPECT_EQ(cloud["partI"].get<std::uint64_t>() + cloud["partII"].get<std::uint64_t>() +
                cloud["partIII"].get<std::uint64_t>(),
            2 * 110'000 - cloud["blocks"].get<std::uint64_t>());
  // Text and PLY points too.
  EXPECT_EQ(
      lodforge("points " + test::dataPath("points/kitten.xyz") + " -o " + dir.file("k.lfc"), dir)
          .code,
      0);
  EXPECT_EQ(info(dir.file("k.lfc"), dir)["points"], 5'210);
  ASSERT_EQ(lodforge("-q generate points --points 20K -o " + dir.file("p.ply"), dir).code, 0);
  EXPECT_EQ(lodforge("points " + dir.file("p.ply") + " -o " + dir.file("p.lfc"), dir).code, 0);
  EXPECT_EQ(info(dir.file("p.lfc"), dir)["points"], 20'000);
}

// Our point tiles read back as point sets: info on every tile of a point tileset counts each
// input point once (every point is in exactly one tile), and no triangles.
TEST(CliTiles, InfoReadsEveryPointTileAndTheirPointsAddUpToTheCloud) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 20K -o " + dir.file("p.ply"), dir).code, 0);
  const Outcome tiles = lodforge(
      "-q tiles " + dir.file("p.ply") + " --block-size 2K --tile-points 2K -o " + dir.file("t"),
      dir);
  ASSERT_EQ(tiles.code, 0) << tiles.err;
  std::uint64_t points = 0, files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.file("t/tiles"))) {
    const nlohmann::json j = info(entry.path().string(), dir);
    EXPECT_EQ(j["triangles"], 0) << entry.path();
    EXPECT_GT(j["vertices"].get<std::uint64_t>(), 0u) << entry.path();
    points += j["vertices"].get<std::uint64_t>();
    ++files;
  }
  EXPECT_GT(files, 4u);
  EXPECT_EQ(points, 20'000u);
}

// Described extra bytes: generated, listed by info with their ranges, carried by tiles.
TEST(CliPoints, ExtraBytesAreListedAndCarried) {
  test::TempDir dir;
  Outcome o = lodforge("-q generate points --points 5K --extra-bytes -o " + dir.file("e.las"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("info " + dir.file("e.las") + " --json", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json extras = nlohmann::json::parse(o.out)["attributes"]["extras"];
  ASSERT_EQ(extras.size(), 4u);
  EXPECT_EQ(extras[0]["name"], "height_above_ground");
  EXPECT_EQ(extras[0]["type"], "uint16");
  EXPECT_EQ(extras[0]["scale"], 0.01);
  EXPECT_LE(extras[0]["max"].get<double>(), 25.0);
  EXPECT_EQ(extras[2]["name"], "range");
  EXPECT_GT(extras[2]["min"].get<double>(), 900.0);
  o = lodforge("info " + dir.file("e.las"), dir);
  EXPECT_NE(o.out.find("echo_width            25 to "), std::string::npos) << o.out;
  o = lodforge("tiles " + dir.file("e.las") + " -o " + dir.file("t") + " --block-size 2K", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(test::readFile(dir.file("t/tiles/b.glb")).find("_ECHO_WIDTH"), std::string::npos);
  o = lodforge("tiles " + dir.file("e.las") + " -o " + dir.file("n") + " --attributes none", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(test::readFile(dir.file("n/tiles/b.glb")).find("_ECHO_WIDTH"), std::string::npos);
  // A PLY's other vertex properties likewise.
  test::writeFile(dir.file("l.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  "property float z\nproperty uchar label\nproperty int segment_index\n"
                  "end_header\n0 0 0 1 10\n1 0 0 2 11\n0 1 0 3 -12\n");
  o = lodforge("info " + dir.file("l.ply") + " --json", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json plyExtras = nlohmann::json::parse(o.out)["attributes"]["extras"];
  ASSERT_EQ(plyExtras.size(), 2u);
  EXPECT_EQ(plyExtras[1]["name"], "segment_index");
  EXPECT_EQ(plyExtras[1]["type"], "int32");
  EXPECT_EQ(plyExtras[1]["min"], -12);
  EXPECT_EQ(plyExtras[1]["max"], 11);
  o = lodforge("generate points --points 5K --extra-bytes -o " + dir.file("e.ply"), dir);
  EXPECT_NE(o.code, 0);
  EXPECT_NE(o.err.find("--extra-bytes needs a .las output"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("e.ply")));
}

// `generate points --from`: a mesh's surface sampled, then a reconstruction of it measured with
// compare, whose JSON says where the largest distance is; misuse is refused with nothing written.
TEST(CliPoints, SamplesAMeshAndCompareSaysWhereTheLargestDistanceIs) {
  test::TempDir dir;
  const std::string horse = test::dataPath("meshes/horse.ply");
  Outcome o = lodforge(
      "-q generate points --from " + horse + " --points 30K --noise 0.0005 -o " + dir.file("h.ply"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("h.ply"), dir)["vertices"], 30'000u);
  o = lodforge("-q reconstruct " + dir.file("h.ply") + " -o " + dir.file("r.ply"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("-q compare " + dir.file("r.ply") + " " + horse + " --json " + dir.file("c.json"),
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json c = nlohmann::json::parse(test::readFile(dir.file("c.json")));
  EXPECT_EQ(c["hausdorff"], std::max(c["max_ab"].get<double>(), c["max_ba"].get<double>()));
  ASSERT_EQ(c["farthest_on_a"].size(), 3u);
  ASSERT_EQ(c["farthest_on_b"].size(), 3u);
  // Each farthest point lies within its mesh's bounds (the horse's: about 0.085 x 0.184 x 0.153
  // round the origin), and is a sample, not the unset (0, 0, 0).
  double away = 0;
  for (int k = 0; k < 3; ++k) {
    const double b = c["farthest_on_b"][k].get<double>(), a = c["farthest_on_a"][k].get<double>();
    EXPECT_LT(std::abs(b), 0.1);
    EXPECT_LT(std::abs(a), 0.1);
    away += std::abs(a) + std::abs(b);
  }
  EXPECT_GT(away, 1e-3);
  o = lodforge("generate points --points 5K --noise 0.01 -o " + dir.file("n.ply"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("--noise goes with --from"), std::string::npos) << o.err;
  o = lodforge("generate points --from " + horse + " --points 5K -o " + dir.file("h.las"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir.file("h.las")));
  o = lodforge("generate points --from " + dir.file("missing.ply") + " -o " + dir.file("m.ply"),
               dir);
  EXPECT_EQ(o.code, 1) << o.err;  // as every command for a file that is not there
  EXPECT_NE(o.err.find("missing.ply"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.ply")));
}

// `reconstruct`: a surface from generated points, its figures on the way; bad input is exit 2
// with what would work, and nothing written.
TEST(CliReconstruct, MakesASurfaceAndRefusesWhatCannotBeOne) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 30K -o " + dir.file("p.ply"), dir).code, 0);
  Outcome o = lodforge("reconstruct " + dir.file("p.ply") + " -o " + dir.file("s.ply") +
                           " --chunk-size 16 --min-triangles 50",
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("triangles"), std::string::npos) << o.out;
  o = lodforge("info " + dir.file("s.ply") + " --json", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json mesh = nlohmann::json::parse(o.out);
  EXPECT_GT(mesh["triangles"].get<std::uint64_t>(), 30'000u);
  EXPECT_TRUE(mesh["normals"].get<bool>());
  EXPECT_TRUE(mesh["colors"].get<bool>());
  // Bad input: too few points, all on a line, a coordinate that is not a number, a voxel too
  // small for the cloud, a chunk too big for the memory limit.
  test::writeFile(dir.file("few.xyz"), "0 0 0\n1 0 0\n0 1 0\n");
  std::string line;
  for (int i = 0; i < 50; ++i) line += fmt::format("{} 2 3\n", i);
  test::writeFile(dir.file("line.xyz"), line);
  test::writeFile(dir.file("nan.xyz"), "0 0 0\n1 0 nan\n0 1 0\n1 1 1\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"few.xyz", "too few for a surface"},
      {"line.xyz", "on a line"},
      {"nan.xyz", "nan.xyz"},
      {"p.ply --voxel 0.000001", "--voxel"},
  };
  for (const auto& [args, says] : cases) {
    o = lodforge("reconstruct " + dir.file(args) + " -o " + dir.file("bad.ply"), dir);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.err;
    EXPECT_NE(o.err.find(says), std::string::npos) << args << "\n" << o.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("bad.ply"))) << args;
  }
  o = lodforge("--memory-limit 64M reconstruct " + dir.file("p.ply") + " -o " +
                   dir.file("bad.ply") + " --chunk-size 512",
               dir);
  EXPECT_EQ(o.code, 1) << "a limit, as in every command";
  EXPECT_NE(o.err.find("--chunk-size"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("give at least --memory-limit"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.ply")));
  // tiles --surface: the reconstruction's chunks tiled as the leaves, its work folder gone
  // afterwards.
  o = lodforge(
      "tiles " + dir.file("p.ply") + " --surface -o " + dir.file("t") + " --chunk-size 150", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("reconstructed"), std::string::npos) << o.out;
  EXPECT_TRUE(std::filesystem::exists(dir.file("t/tileset.json")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("t.work")));
  // Options that do not go together, or do not go without --surface.
  const std::vector<std::pair<std::string, std::string>> usage = {
      {"tiles " + dir.file("s.ply") + " --surface -o " + dir.file("u"),
       "--surface is for point clouds"},
      {"tiles " + dir.file("p.ply") + " --surface --levels 2 -o " + dir.file("u"),
       "--levels does not go with --surface"},
      {"tiles " + dir.file("p.ply") + " --voxel 2 -o " + dir.file("u"), "go with --surface"},
      {"reconstruct " + dir.file("p.ply") + " -o " + dir.file("x.ply") + " --orient sideways",
       "not auto, propagate, up or a viewpoint"},
  };
  for (const auto& [args, says] : usage) {
    o = lodforge(args, dir);
    EXPECT_EQ(o.code, 2) << args;
    EXPECT_NE(o.err.find(says), std::string::npos) << args << "\n" << o.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("u"))) << args;
  }
}

TEST(CliPoints, BadInputIsExitCode2AndLeavesNothing) {
  test::TempDir dir;
  // A LAZ cut inside its last chunk: the chunk table went with the cut.
  const std::string laz = test::readFile(test::dataPath("points/autzen_trim.laz"));
  test::writeFile(dir.file("cut.laz"), laz.substr(0, laz.size() * 9 / 10));
  Outcome o = lodforge("points " + dir.file("cut.laz") + " -o " + dir.file("a.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("cut.laz: byte 2144: the chunk table is said to be at byte 603333"),
            std::string::npos)
      << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.lfc")));
  // Bytes of a chunk overwritten: the chunk is named.
  std::string damaged = laz;
  for (std::size_t i = 300'000; i < 300'100; ++i) damaged[i] = static_cast<char>(i * 31);
  test::writeFile(dir.file("damaged.laz"), damaged);
  o = lodforge("tiles " + dir.file("damaged.laz") + " -o " + dir.file("t"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("damaged.laz: byte "), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("LAZ chunk 2 of 3"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("t")));
  // info reads the header, then every point for the fields' ranges (--header-only: not).
  o = lodforge("info " + test::dataPath("points/autzen_trim.laz") + " --json", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json attributes = nlohmann::json::parse(o.out)["attributes"];
  EXPECT_EQ(attributes["intensity"]["max"], 254);
  EXPECT_EQ(attributes["number_of_returns"]["max"], 4);
  EXPECT_EQ(attributes["classification"]["2"]["name"], "Ground");
  EXPECT_EQ(attributes["classification"]["2"]["points"].get<std::uint64_t>() +
                attributes["classification"]["1"]["points"].get<std::uint64_t>(),
            110'000u);
  o = lodforge("info " + dir.file("damaged.laz") + " --header-only", dir);
  EXPECT_EQ(o.code, 0) << o.err;
  o = lodforge("info " + dir.file("damaged.laz"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("LAZ chunk 2 of 3"), std::string::npos) << o.err;
  o = lodforge("info " + test::dataPath("points/autzen_trim.laz"), dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("compressed point-wise chunked (50,000 points per chunk)"),
            std::string::npos)
      << o.out;
  o = lodforge("info " + test::dataPath("points/1.2-with-color.copc.laz") + " --json", dir);
  EXPECT_EQ(o.code, 0) << o.err;
  const nlohmann::json copc = nlohmann::json::parse(o.out);
  EXPECT_EQ(copc["format"], "COPC");
  EXPECT_EQ(copc["points"], 1'065);
  EXPECT_EQ(copc["laz"]["items"][0]["type"], "POINT14");
  // A LAS cut short: its point count runs past the end.
  std::string las = test::readFile(test::dataPath("points/sample_c.las"));
  test::writeFile(dir.file("cut.las"), las.substr(0, 5'000));
  o = lodforge("points " + dir.file("cut.las") + " -o " + dir.file("b.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("cut.las: byte 107"), std::string::npos) << o.err;
  // A real PLY point set, cut short, and (read with --salvage) with a NaN normal.
  o = lodforge("points " + test::dataPath("points/pond.0.ply") + " -o " + dir.file("c.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("pond.0.ply: byte 276"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("truncated"), std::string::npos) << o.err;
  o = lodforge(
      "points --salvage " + test::dataPath("points/pond.0.ply") + " -o " + dir.file("c.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("vertex 692: normal is not finite"), std::string::npos) << o.err;
  test::writeFile(dir.file("bad.xyz"), "1 2 3\n4 5 x\n");
  o = lodforge("points " + dir.file("bad.xyz") + " -o " + dir.file("d.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("bad.xyz:2:"), std::string::npos) << o.err;
  EXPECT_EQ(lodforge("points " + dir.file("bad.xyz") + " -o " + dir.file("d.ply"), dir).code, 2);
  test::writeFile(dir.file("bad.lfc"), "LFCLOUD");
  o = lodforge("info " + dir.file("bad.lfc"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("bad.lfc"), std::string::npos) << o.err;
  // Nothing half written.
  for (const auto& name : test::listFolder(dir.path())) {
    EXPECT_TRUE(name == "cut.las" || name == "bad.xyz" || name == "bad.lfc" || name == "cut.laz" ||
                name == "damaged.laz")
        << name;
  }
}

// LAZ in: convert writes the LAS it was made from, byte for byte, and the tiles of a LAZ are
// the tiles of its LAS.
TEST(CliLaz, ConvertsToTheLasItCameFromAndTilesLikeIt) {
  test::TempDir dir;
  for (const auto& [laz, las] : {std::pair{"autzen_trim.laz", "autzen_trim.las"},
                                 std::pair{"simple-v1.laz", "simple.las"}}) {
    const Outcome o = lodforge(
        "convert " + test::dataPath(std::string("points/") + laz) + " -o " + dir.file("out.las"),
        dir);
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_NE(o.out.find("1 compression records dropped"), std::string::npos) << o.out;
    EXPECT_TRUE(test::readFile(dir.file("out.las")) ==
                test::readFile(test::dataPath(std::string("points/") + las)))
        << laz;
  }
  // COPC: LAS 1.4 format 7 out, its COPC records dropped, the CRS kept.
  Outcome o = lodforge(
      "convert " + test::dataPath("points/1.2-with-color.copc.laz") + " -o " + dir.file("copc.las"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("1,065 points, 1 records kept, 3 compression records dropped"),
            std::string::npos)
      << o.out;
  o = lodforge("info " + dir.file("copc.las") + " --json", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json copc = nlohmann::json::parse(o.out);
  EXPECT_EQ(copc["format"], "LAS");
  EXPECT_EQ(copc["pointFormat"], 7);
  EXPECT_NE(copc["crs"].get<std::string>().find("NAD83"), std::string::npos);
  // The tiles of the LAZ are the tiles of the LAS, file for file.
  for (const char* input : {"autzen_trim.laz", "autzen_trim.las"}) {
    o = lodforge("-q tiles " + test::dataPath(std::string("points/") + input) + " -o " +
                     dir.file(input) + " --block-size 20K --tile-points 10K",
                 dir);
    ASSERT_EQ(o.code, 0) << o.err;
  }
  std::size_t files = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(dir.file("autzen_trim.las"))) {
    if (!entry.is_regular_file()) continue;
    const std::string relative =
        std::filesystem::relative(entry.path(), dir.file("autzen_trim.las")).string();
    EXPECT_TRUE(test::readFile(entry.path().string()) ==
                test::readFile(dir.file("autzen_trim.laz") + "/" + relative))
        << relative;
    ++files;
  }
  EXPECT_GE(files, 10u);
  // convert writes .las from LAS input only.
  o = lodforge("convert " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("h.las"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("convert writes .las from .laz or .las input only"), std::string::npos)
      << o.err;
}

TEST(CliPoints, StaysUnderItsMemoryLimitOnAnInputLargerThanIt) {
#ifdef LODFORGE_SANITIZED
  GTEST_SKIP() << "peak RSS means nothing under ASan; the release build checks it";
#endif
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 3M -o " + dir.file("p.ply"), dir).code, 0);
  constexpr std::uint64_t kLimit = 64ull << 20;
  ASSERT_GT(std::filesystem::file_size(dir.file("p.ply")), kLimit);
  const Finished run = waitFor(spawnLodforge(
      {"-q", "--memory-limit", "64M", "points", dir.file("p.ply"), "-o", dir.file("p.lfc")}));
  ASSERT_EQ(run.code, 0);
  EXPECT_LT(run.peak, kLimit) << "peak RSS " << run.peak / (1 << 20) << " MiB";
  EXPECT_EQ(info(dir.file("p.lfc"), dir)["points"], 3'000'000);
}

TEST(CliPoints, BenchAndViewRunTheGazeDrivenRuntime) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("points " + test::dataPath("points/autzen_trim.las") + " -o " +
                         dir.file("a.lfc") + " --block-size 10K",
                     dir)
                .code,
            0);
  Outcome o = lodforge("bench " + dir.file("a.lfc") +
                           " --frames 8 --size 320x240 --fovea 50,400 --resident-blocks 3 --json " +
                           dir.file("b.json"),
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("frame time by splats drawn"), std::string::npos) << o.out;
  const auto j = nlohmann::json::parse(test::readFile(dir.file("b.json")));
  ASSERT_EQ(j["runs"].size(), 2u);
  std::uint64_t small = 0, large = 0;
  for (const auto& f : j["runs"][0]["frames"]) small += f["splats"].get<std::uint64_t>();
  for (const auto& f : j["runs"][1]["frames"]) large += f["splats"].get<std::uint64_t>();
  EXPECT_GT(large, small) << "a wider fovea draws more";
  // In a window (virtual display): the screenshot shows the cloud.
  o = lodforge("view " + dir.file("a.lfc") + " --size 320x240 --stop-after 6 --screenshot " +
                   dir.file("v.png"),
               dir, glSubprocess() + "xvfb-run -a -s '-screen 0 1280x1024x24' ");
  ASSERT_EQ(o.code, 0) << o.err;
  const auto shot = readPng(dir.file("v.png"));
  ASSERT_TRUE(shot.ok());
  EXPECT_GT(compareImages(*shot, Image(320, 240)).shareAbove, 0.02);
}

// `lodforge serve` on a free port (it prints which); stops it with Ctrl-C on destruction.
class Served {
 public:
  Served(const test::TempDir& dir, std::vector<std::string> args) : dir_(dir) {
    args.insert(args.begin(), {"serve", "--port", "0"});
    pid_ = spawnLodforge(args, dir.file(".serve-err"), dir.file(".serve-out"));
    for (int i = 0; i < 200 && port_ == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
      const std::string out = test::readFile(dir.file(".serve-out"));
      const std::size_t at = out.find("http://127.0.0.1:");
      if (at != std::string::npos) port_ = std::atoi(out.c_str() + at + 17);
    }
    EXPECT_GT(port_, 0) << test::readFile(dir.file(".serve-err"));
  }
  ~Served() {
    if (pid_ > 0 && !stopped_) stop();
  }
  // Ctrl-C: the exit code, and what it printed.
  Finished stop() {
    stopped_ = true;
    ::kill(pid_, SIGINT);
    return waitFor(pid_);
  }
  int port() const { return port_; }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_decompress(false);
    c.set_url_encode(false);  // paths go out exactly as written
    return c;
  }
  std::string log() const { return test::readFile(dir_.file(".serve-err")); }

 private:
  const test::TempDir& dir_;
  pid_t pid_ = -1;
  int port_ = 0;
  bool stopped_ = false;
};

TEST(CliServe, ServesATilesetWithTypesRangesAndCompression) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q tiles " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("t") +
                         " --chunk-size 0.05",
                     dir)
                .code,
            0);
  Served served(dir, {dir.file("t")});
  httplib::Client http = served.client();
  const std::string tileset = test::readFile(dir.file("t/tileset.json"));
  auto r = http.Get("/tiles/tileset.json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/json; charset=utf-8");
  EXPECT_EQ(r->body, tileset);
  EXPECT_FALSE(r->has_header("Access-Control-Allow-Origin"));  // opt-in only
  // Compressed JSON when the client takes gzip.
  r = http.Get("/tiles/tileset.json", {{"Accept-Encoding", "gzip"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->get_header_value("Content-Encoding"), "gzip");
  EXPECT_LT(r->body.size(), tileset.size() / 2);
  {
    // It is one gzip stream of the file (not compressed twice).
    httplib::Client plain("127.0.0.1", served.port());
    plain.set_decompress(true);
    auto decoded = plain.Get("/tiles/tileset.json", {{"Accept-Encoding", "gzip"}});
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->body, tileset);
  }
  // A tile: its type, a range of it, and HEAD.
  const auto tiles = test::listFolder(dir.file("t/tiles"));
  ASSERT_FALSE(tiles.empty());
  const std::string glb = test::readFile(dir.file("t/tiles/" + tiles[0]));
  r = http.Get("/tiles/tiles/" + tiles[0]);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->get_header_value("Content-Type"), "model/gltf-binary");
  EXPECT_EQ(r->body, glb);
  r = http.Get("/tiles/tiles/" + tiles[0], {{"Range", "bytes=12-111"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 206);
  EXPECT_EQ(r->body, glb.substr(12, 100));
  // Every kind of range (RFC 9110 §14): suffix, open, an end past the file (clamped), several,
  // and a start past the end (416 with the size). Each answer is complete, never short.
  const std::size_t size = glb.size();
  struct RangeCase {
    std::string range;
    int status;
    std::string contentRange, body;
  };
  for (const RangeCase& c : {
           RangeCase{"bytes=-100", 206, fmt::format("bytes {}-{}/{}", size - 100, size - 1, size),
                     glb.substr(size - 100)},
           RangeCase{fmt::format("bytes=-{}", size + 50), 206,
                     fmt::format("bytes 0-{}/{}", size - 1, size), glb},
           RangeCase{"bytes=20-", 206, fmt::format("bytes 20-{}/{}", size - 1, size),
                     glb.substr(20)},
           RangeCase{fmt::format("bytes={}-{}", size - 10, size + 100000), 206,
                     fmt::format("bytes {}-{}/{}", size - 10, size - 1, size),
                     glb.substr(size - 10)},
           RangeCase{fmt::format("bytes={}-", size + 100000), 416, fmt::format("bytes */{}", size),
                     ""},
           RangeCase{fmt::format("bytes={}-{}", size, size + 5), 416,
                     fmt::format("bytes */{}", size), ""},
           // A range that ends before it starts: cpp-httplib refuses it before any route.
           RangeCase{"bytes=10-5", 416, fmt::format("bytes */{}", size), ""},
       }) {
    r = http.Get("/tiles/tiles/" + tiles[0], {{"Range", c.range}});
    ASSERT_TRUE(r) << c.range << ": an answer, not a timeout";
    EXPECT_EQ(r->status, c.status) << c.range;
    EXPECT_EQ(r->get_header_value("Content-Range"), c.contentRange) << c.range;
    if (c.status == 206) {
      EXPECT_EQ(r->body, c.body) << c.range;
      EXPECT_EQ(r->get_header_value("Content-Length"), std::to_string(c.body.size())) << c.range;
    }
  }
  // Several ranges: the whole file (RFC 9110 lets a server ignore Range), never a broken
  // multipart answer.
  r = http.Get("/tiles/tiles/" + tiles[0],
               {{"Range", fmt::format("bytes=0-9,{}-{},{}-", size - 5, size + 99, size + 7)}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->body, glb);
  // Several where only one is inside the file: that one.
  r = http.Get("/tiles/tiles/" + tiles[0], {{"Range", fmt::format("bytes=0-9,{}-", size + 7)}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 206);
  EXPECT_EQ(r->body, glb.substr(0, 10));
  // A range of tileset.json is of the file itself, never of its gzip.
  r = http.Get("/tiles/tileset.json", {{"Range", "bytes=0-9"}, {"Accept-Encoding", "gzip"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 206);
  EXPECT_EQ(r->body, tileset.substr(0, 10));
  r = http.Head("/tiles/tiles/" + tiles[0]);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_TRUE(r->body.empty());
  EXPECT_EQ(r->get_header_value("Content-Length"), std::to_string(glb.size()));
  // Only GET and HEAD.
  r = http.Post("/tiles/tileset.json", "x", "text/plain");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 405);
  EXPECT_EQ(r->get_header_value("Allow"), "GET, HEAD");
  r = http.Delete("/tiles/tileset.json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 405);
  // The viewers, from this build's web/dist, whatever the working directory.
  r = http.Get("/");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 302);
  for (const char* page : {"/cesium/", "/three/"}) {
    r = http.Get(page);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200) << page;
    EXPECT_EQ(r->get_header_value("Content-Type"), "text/html; charset=utf-8");
  }
  // A viewer's scripts go out gzipped, compressed once (never per request: brotli at its top
  // quality took 10 s for CesiumJS on every page load), one gzip stream of the file.
  r = http.Get("/cesium/");
  ASSERT_TRUE(r);
  std::smatch script;
  const std::string page = r->body;
  const std::regex scriptSource(R"re(src="(/assets/[^"]+\.js)")re");
  ASSERT_TRUE(std::regex_search(page, script, scriptSource)) << page;
  httplib::Client scripts("127.0.0.1", served.port());
  scripts.set_decompress(false);
  const auto first = scripts.Get(script[1].str(), {{"Accept-Encoding", "gzip, deflate, br"}});
  const auto again = scripts.Get(script[1].str(), {{"Accept-Encoding", "gzip, deflate, br"}});
  ASSERT_TRUE(first && again);
  EXPECT_EQ(first->status, 200);
  EXPECT_EQ(first->get_header_value("Content-Encoding"), "gzip");
  EXPECT_EQ(first->get_header_value("Content-Type"), "application/javascript; charset=utf-8");
  EXPECT_EQ(again->body, first->body);
  scripts.set_decompress(true);
  const auto decoded = scripts.Get(script[1].str(), {{"Accept-Encoding", "gzip"}});
  const auto identity = scripts.Get(script[1].str());
  ASSERT_TRUE(decoded && identity);
  EXPECT_FALSE(identity->has_header("Content-Encoding"));
  EXPECT_EQ(decoded->body, identity->body);
  EXPECT_LT(first->body.size(), identity->body.size());
  // The first lines name the tileset's URL and the viewers.
  const std::string said = test::readFile(dir.file(".serve-out"));
  EXPECT_NE(said.find(fmt::format("as http://127.0.0.1:{}/tiles/tileset.json", served.port())),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("/cesium/"), std::string::npos) << said;
  // A request log line each, and a clean stop on Ctrl-C.
  const Finished end = served.stop();
  EXPECT_EQ(end.code, 0);
  EXPECT_NE(served.log().find("GET /tiles/tileset.json 200"), std::string::npos) << served.log();
}

TEST(CliServe, RefusesEveryWayOutOfTheDirectory) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("t/tiles"));
  test::writeFile(dir.file("t/tileset.json"), "{}");
  test::writeFile(dir.file("secret.txt"), "secret");
  std::filesystem::create_symlink(dir.file("secret.txt"), dir.file("t/link.txt"));
  std::filesystem::create_directory_symlink(dir.path(), dir.file("t/up"));
  std::filesystem::create_symlink("tileset.json", dir.file("t/inside.json"));
  Served served(dir, {dir.file("t"), "--cors"});
  httplib::Client http = served.client();
  const auto status = [&](const std::string& path) {
    auto r = http.Get(path);
    return r ? r->status : -1;
  };
  for (const std::string& path :
       {std::string("/tiles/../secret.txt"), std::string("/tiles/tiles/../../secret.txt"),
        std::string("/tiles/%2e%2e/secret.txt"), std::string("/tiles/%2E%2E%2Fsecret.txt"),
        std::string("/tiles/..%2fsecret.txt"), std::string("/tiles/.%2e/secret.txt"),
        std::string("/tiles/%2fetc%2fpasswd"), std::string("/tiles//etc/passwd"),
        std::string("/tiles/link.txt"), std::string("/tiles/up/secret.txt"),
        std::string("/tiles/..\\secret.txt")}) {
    const int s = status(path);
    EXPECT_TRUE(s == 403 || s == 404) << path << " -> " << s;
    auto r = http.Get(path);
    if (r) {
      EXPECT_EQ(r->body.find("secret"), std::string::npos) << path;
    }
  }
  // Double-encoded: one decoding leaves "%2e%2e", a name that does not exist.
  EXPECT_EQ(status("/tiles/%252e%252e/secret.txt"), 404);
  EXPECT_EQ(status("/tiles/missing.json"), 404);
  EXPECT_EQ(status("/tiles/tiles"), 404);  // no directory listings
  // A symlink that stays inside is fine, and --cors adds its header.
  auto r = http.Get("/tiles/inside.json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->body, "{}");
  EXPECT_EQ(r->get_header_value("Access-Control-Allow-Origin"), "*");
  EXPECT_EQ(served.stop().code, 0);
  // Not a directory, or a directory without a tileset: a usage error that says what to give.
  Outcome o = lodforge("serve " + dir.file("secret.txt"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("not a directory"), std::string::npos) << o.err;
  std::filesystem::create_directories(dir.file("empty"));
  o = lodforge("serve " + dir.file("empty"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("holds no tileset.json"), std::string::npos) << o.err;
}

TEST(CliTiles, WritesATilesetAndReplacesOnlyATileset) {
  test::TempDir dir;
  const std::string out = dir.file("horse-tiles");
  Outcome o = lodforge("tiles " + test::dataPath("meshes/horse.ply") + " -o " + out +
                           " --chunk-size 0.05 --reduction 0.25 --max-normal-deviation 20",
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("tiles ("), std::string::npos) << o.out;
  std::ifstream in(out + "/tileset.json");
  const nlohmann::json tileset = nlohmann::json::parse(in);
  EXPECT_EQ(tileset["asset"]["version"], "1.1");
  EXPECT_TRUE(tileset["root"].contains("children"));
  const std::size_t tiles = test::listFolder(out + "/tiles").size();
  EXPECT_GT(tiles, 9u);
  // Again over the previous tileset: replaced, nothing else left in the folder.
  o = lodforge("tiles " + test::dataPath("meshes/horse.ply") + " -o " + out + " --chunk-size 0.2",
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_LT(test::listFolder(out + "/tiles").size(), tiles);
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"horse-tiles"});
  // A folder that is not a tileset is not overwritten.
  std::filesystem::create_directories(dir.file("mine"));
  std::ofstream(dir.file("mine/notes.txt")) << "mine";
  o = lodforge("tiles " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("mine"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("not a tileset"), std::string::npos) << o.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("mine/notes.txt")));
}

// The depth of a tileset: levels of tiles above its deepest leaves.
int levelsAbove(const nlohmann::json& tile) {
  int deepest = -1;
  for (const auto& child : tile.value("children", nlohmann::json::array()))
    deepest = std::max(deepest, levelsAbove(child));
  return deepest + 1;
}

TEST(CliTiles, ASmallModelGetsLevelsAndLevelsAreHonouredOrRefused) {
  test::TempDir dir;
  const std::string part = test::dataPath("meshes/as1_motor.glb");  // 27,506 triangles
  Outcome o = lodforge("tiles " + part + " -o " + dir.file("a"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  nlohmann::json tileset = nlohmann::json::parse(test::readFile(dir.file("a/tileset.json")));
  EXPECT_GE(levelsAbove(tileset["root"]), 2) << "a hierarchy to refine through";
  // The root is coarse: a viewer from afar loads a fraction of the part.
  std::uintmax_t allTiles = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.file("a/tiles")))
    allTiles += entry.file_size();
  const std::string rootUri = tileset["root"]["content"]["uri"];
  EXPECT_LT(std::filesystem::file_size(dir.file("a/" + rootUri)) * 3, allTiles);
  for (int levels : {1, 3, 4}) {
    o = lodforge("tiles " + part + " -o " + dir.file("a") + " --levels " + std::to_string(levels),
                 dir);
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_NE(o.out.find(std::to_string(levels) + " levels above them"), std::string::npos)
        << o.out;
  }
  o = lodforge("tiles " + part + " -o " + dir.file("b") + " --levels 9", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("--levels 9: the model's 27506 triangles make at most"), std::string::npos)
      << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("b")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("b.work")));
}

// Implicit tiling where asked for, over an earlier explicit tileset of the same output (ours to
// replace); refused, before any work, where it cannot describe the tree.
TEST(CliTiles, ImplicitTilingIsWrittenOrRefusedBeforeAnyWork) {
  test::TempDir dir;
  const std::string horse = test::dataPath("meshes/horse.ply");
  Outcome o = lodforge("tiles " + horse + " -o " + dir.file("h") + " --chunk-size 0.05", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge(
      "tiles " + horse + " -o " + dir.file("h") + " --chunk-size 0.05 --implicit-tiling on", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("implicit tiling"), std::string::npos) << o.out;
  const nlohmann::json tileset = nlohmann::json::parse(test::readFile(dir.file("h/tileset.json")));
  EXPECT_EQ(tileset["root"]["implicitTiling"]["subdivisionScheme"], "OCTREE");
  EXPECT_TRUE(std::filesystem::exists(dir.file("h/subtrees/0/0/0/0.subtree")));
  // And back: the implicit output is ours to replace too.
  o = lodforge("tiles " + horse + " -o " + dir.file("h") + " --chunk-size 0.05", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("h/subtrees")));

  o = lodforge("tiles " + horse + " -o " + dir.file("l") + " --levels 1 --implicit-tiling on", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("--implicit-tiling on and --levels"), std::string::npos) << o.err;
  const std::string cloud = test::dataPath("points/autzen_trim.las");
  o = lodforge("tiles " + cloud + " -o " + dir.file("p") + " --implicit-tiling on", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("--implicit-tiling is for meshes"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("l")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("p")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("p.work")));
}

TEST(CliTiles, SaysWhenATilesetHasNoPlaceOnEarth) {
  test::TempDir dir;
  const std::string mesh = test::dataPath("meshes/horse.ply");
  Outcome o = lodforge("tiles " + mesh + " -o " + dir.file("a"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("no place on Earth"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("--origin"), std::string::npos) << o.err;
  o = lodforge("tiles " + mesh + " -o " + dir.file("a") + " --origin 7.1,50.7,60", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("no place on Earth"), std::string::npos) << o.err;
  o = lodforge("tiles " + test::dataPath("points/simple.las") + " -o " + dir.file("p"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.err.find("no place on Earth"), std::string::npos) << "a LAS without a CRS";
  o = lodforge("tiles " + test::dataPath("points/autzen_trim.las") + " -o " + dir.file("p"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err.find("no place on Earth"), std::string::npos) << "placed by its CRS";
}

TEST(CliTiles, BadInputAndArgumentsAreExitCode2AndLeaveNothing) {
  test::TempDir dir;
  std::ofstream(dir.file("cut.ply"))
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty float z\nend_header\n0 0 0\n";
  Outcome o = lodforge("tiles " + dir.file("cut.ply") + " -o " + dir.file("out"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("cut.ply"), std::string::npos) << o.err;
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"cut.ply"});
  o = lodforge(
      "tiles " + test::dataPath("meshes/horse.ply") + " -o " + dir.file("out") + " --reduction 1.5",
      dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"cut.ply"});
}

// CAD files go wherever meshes go: info shows the part tree, convert and tiles tessellate it,
// and a bad file or option is exit 2 leaving nothing.
TEST(CliCad, AStepAssemblyIsDescribedConvertedAndTiled) {
  test::TempDir dir;
  const std::string motor = test::dataPath("cad/as1_motor.step");
  const nlohmann::json j = info(motor, dir);
  EXPECT_EQ(j["format"], "CAD (STEP, IGES, BREP)");
  EXPECT_EQ(j["objects"], j["cad"]["instances"]);
  EXPECT_LT(j["cad"]["shapes"].get<int>(), j["cad"]["instances"].get<int>());
  EXPECT_GE(j["cad"]["depth"].get<int>(), 2);
  EXPECT_TRUE(j["colors"].get<bool>());
  std::uint64_t placed = 0;
  for (const nlohmann::json& part : j["cad"]["parts"]) placed += part["count"].get<std::uint64_t>();
  EXPECT_EQ(placed, j["objects"].get<std::uint64_t>());
  const Outcome text = lodforge("info " + motor, dir);
  EXPECT_NE(text.out.find("assembly depth"), std::string::npos) << text.out;

  // A finer deflection, given as a length, makes more triangles.
  Outcome o = lodforge("convert " + motor + " -o " + dir.file("coarse.glb"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("convert " + motor + " -o " + dir.file("fine.glb") + " --deflection 0.02m", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_GT(info(dir.file("fine.glb"), dir)["triangles"].get<std::uint64_t>(),
            info(dir.file("coarse.glb"), dir)["triangles"].get<std::uint64_t>());
  EXPECT_EQ(info(dir.file("coarse.glb"), dir)["objects"], j["objects"]);

  o = lodforge("tiles " + motor + " -o " + dir.file("tiles") + " --chunk-size 20", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("tiles/tileset.json")));

  for (const std::string& args :
       {"convert " + motor + " -o " + dir.file("x.glb") + " --deflection 2furlongs",
        "info " + motor + " --code-page KOI9"}) {
    o = lodforge(args, dir);
    EXPECT_EQ(o.code, 2) << args << "\n" << o.err;
  }
  test::writeFile(dir.file("cut.step"), test::readFile(motor).substr(0, 5000));
  o = lodforge("tiles " + dir.file("cut.step") + " -o " + dir.file("cut-tiles"), dir);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("cut.step"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("cut-tiles")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.glb")));
}

// A STEP file (written by OCCT) whose "ghost" product is invisible and whose "scaffold" sits on a
// hidden layer: info and convert leave both out and say so, --hidden keeps them.
TEST(CliCad, HiddenPartsAreLeftOutUnlessKept) {
  test::TempDir dir;
  const std::string step = test::testDataPath("cad/hidden-parts.step");
  nlohmann::json j = info(step, dir);
  EXPECT_EQ(j["objects"], 1u);
  EXPECT_EQ(j["cad"]["hidden"], 2u);
  const Outcome text = lodforge("info " + step, dir);
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("2 hidden, left out"), std::string::npos) << text.out;
  EXPECT_NE(text.err.find("warning: " + step + ": 2 part(s) the file hides left out"),
            std::string::npos)
      << text.err;
  Outcome o = lodforge("info --json --hidden " + step, dir);
  ASSERT_EQ(o.code, 0) << o.err;
  j = nlohmann::json::parse(o.out);
  EXPECT_EQ(j["objects"], 3u);
  EXPECT_EQ(j["cad"]["hidden"], 0u);
  o = lodforge("convert " + step + " --hidden -o " + dir.file("all.glb"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(info(dir.file("all.glb"), dir)["objects"], 3u);
}

// The JSON chunk of a GLB file.
nlohmann::json glbJson(const std::string& path) {
  const std::string bytes = test::readFile(path);
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);
  return nlohmann::json::parse(bytes.substr(20, length));
}

// Per depth of the tileset's tree: whether some tile there draws a BLEND material.
void blendedByDepth(const std::string& folder, const nlohmann::json& tile, std::size_t depth,
                    std::vector<bool>& blended) {
  if (blended.size() <= depth) blended.resize(depth + 1, false);
  if (tile.contains("content")) {
    const nlohmann::json glb = glbJson(folder + "/" + tile["content"]["uri"].get<std::string>());
    for (const nlohmann::json& m : glb.value("materials", nlohmann::json::array()))
      if (m.value("alphaMode", "OPAQUE") == "BLEND") blended[depth] = true;
  }
  for (const nlohmann::json& child : tile.value("children", nlohmann::json::array()))
    blendedByDepth(folder, child, depth + 1, blended);
}

// A Collada assembly written by assimp's exporter (as1_motor, its largest part's material made
// glass at opacity 0.12): described, tiled with its parts named, the glass blended at every
// depth of the tileset.
TEST(CliAssimp, AColladaAssemblyIsTiledWithItsPartsAndItsGlass) {
  test::TempDir dir;
  {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(test::dataPath("meshes/as1_motor.glb"), 0);
    ASSERT_NE(scene, nullptr) << importer.GetErrorString();
    unsigned largest = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
      if (scene->mMeshes[m]->mNumFaces > scene->mMeshes[largest]->mNumFaces) largest = m;
    const float opacity = 0.12f;
    scene->mMaterials[scene->mMeshes[largest]->mMaterialIndex]->AddProperty(&opacity, 1,
                                                                            AI_MATKEY_OPACITY);
    Assimp::Exporter exporter;
    ASSERT_EQ(exporter.Export(scene, "collada", dir.file("motor.dae")), AI_SUCCESS);
  }
  const nlohmann::json j = info(dir.file("motor.dae"), dir);
  EXPECT_EQ(j["format"], "interchange scene (assimp)");
  EXPECT_GT(j["objects"].get<int>(), 10);
  const Outcome o = lodforge("tiles " + dir.file("motor.dae") + " -o " + dir.file("t"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find(fmt::format("{} named parts", j["objects"].get<int>())), std::string::npos)
      << o.out;
  const nlohmann::json tileset = nlohmann::json::parse(test::readFile(dir.file("t/tileset.json")));
  std::vector<bool> blended;
  blendedByDepth(dir.file("t"), tileset["root"], 0, blended);
  ASSERT_GE(blended.size(), 2u);
  for (std::size_t depth = 0; depth < blended.size(); ++depth) {
    if (depth > 0 || tileset["root"].contains("content")) {
      EXPECT_TRUE(blended[depth]) << depth;
    }
  }

  // The glass pane of an IFC house stays BLEND in its tiles, and only the pane.
  const std::string house = test::testDataPath("ifc/house.ifc");
  ASSERT_EQ(lodforge("tiles " + house + " -o " + dir.file("house"), dir).code, 0);
  const nlohmann::json houseSet =
      nlohmann::json::parse(test::readFile(dir.file("house/tileset.json")));
  const nlohmann::json root =
      glbJson(dir.file("house/") + houseSet["root"]["content"]["uri"].get<std::string>());
  std::vector<std::string> modes;
  for (const nlohmann::json& m : root["materials"]) modes.push_back(m.value("alphaMode", "OPAQUE"));
  std::sort(modes.begin(), modes.end());
  EXPECT_EQ(modes, (std::vector<std::string>{"BLEND", "OPAQUE"}));
}

TEST(CliTiles, StaysUnderItsMemoryLimitOnAnInputLargerThanIt) {
#ifdef LODFORGE_SANITIZED
  GTEST_SKIP() << "peak RSS means nothing under ASan; the release build checks it";
#endif
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate scan --triangles 5M -o " + dir.file("scan.ply"), dir).code, 0);
  constexpr std::uint64_t kLimit = 96ull << 20;
  ASSERT_GT(std::filesystem::file_size(dir.file("scan.ply")), kLimit);
  const Finished run = waitFor(spawnLodforge(
      {"-q", "--memory-limit", "96M", "tiles", dir.file("scan.ply"), "-o", dir.file("tiles")}));
  ASSERT_EQ(run.code, 0);
  EXPECT_LT(run.peak, kLimit) << "peak RSS " << run.peak / (1 << 20) << " MiB";
  EXPECT_TRUE(std::filesystem::exists(dir.file("tiles/tileset.json")));
  // A limit too small for the program itself is refused up front.
  const Outcome small = lodforge(
      "--memory-limit 20M tiles " + dir.file("scan.ply") + " -o " + dir.file("small"), dir);
  EXPECT_EQ(small.code, 1);
  EXPECT_NE(small.err.find("too small"), std::string::npos) << small.err;
}

// An OBJ streams too (tiling/chunk_obj): a textured one larger than the limit, images included.
TEST(CliTiles, AStreamedObjStaysUnderItsMemoryLimit) {
#ifdef LODFORGE_SANITIZED
  GTEST_SKIP() << "peak RSS means nothing under ASan; the release build checks it";
#endif
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate scan --triangles 1M --texture 1K --atlases 2 -o " +
                         dir.file("scan.ply"),
                     dir)
                .code,
            0);
  ASSERT_EQ(
      lodforge("-q convert " + dir.file("scan.ply") + " -o " + dir.file("scan.obj"), dir).code, 0);
  constexpr std::uint64_t kLimit = 96ull << 20;
  ASSERT_GT(std::filesystem::file_size(dir.file("scan.obj")), kLimit);
  const Finished run = waitFor(spawnLodforge(
      {"-q", "--memory-limit", "96M", "tiles", dir.file("scan.obj"), "-o", dir.file("tiles")}));
  ASSERT_EQ(run.code, 0);
  EXPECT_LT(run.peak, kLimit) << "peak RSS " << run.peak / (1 << 20) << " MiB";
  const nlohmann::json root = info(dir.file("tiles/tiles/0-0-0-0.glb"), dir);
  EXPECT_TRUE(root.contains("textures")) << root.dump();
}

TEST(CliTiles, TexturedStaysUnderItsMemoryLimitWithImagesLargerThanIt) {
#ifdef LODFORGE_SANITIZED
  GTEST_SKIP() << "peak RSS means nothing under ASan; the release build checks it";
#endif
  // 16 atlases of 4K: 1 GiB of texels decoded, four times the limit.
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate scan --triangles 20K --texture 4K --atlases 16 -o " +
                         dir.file("scan.ply"),
                     dir)
                .code,
            0);
  constexpr std::uint64_t kLimit = 256ull << 20;
  const Finished run = waitFor(spawnLodforge(
      {"-q", "--memory-limit", "256M", "tiles", dir.file("scan.ply"), "-o", dir.file("tiles")}));
  ASSERT_EQ(run.code, 0);
  EXPECT_LT(run.peak, kLimit) << "peak RSS " << run.peak / (1 << 20) << " MiB";
  // Every tile drew from the atlases: each has a texture of its own.
  std::size_t tiles = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.file("tiles/tiles"))) {
    const nlohmann::json tile = info(entry.path().string(), dir);
    ASSERT_TRUE(tile.contains("textures")) << entry.path();
    EXPECT_GE(tile["textures"]["images"].size(), 1u);
    ++tiles;
  }
  EXPECT_GE(tiles, 10u);
}

// Runs lodforge with `args`, interrupted as Ctrl-C would at the durable step `at` ("node:6" is
// the sixth tile node's summary, "run:2" the second run of reconstructed chunks: the
// LODFORGE_INTERRUPT_AFTER hook of core/progress.h), and checks that it stopped with exit 1,
// naming --resume.
void interruptAfter(const test::TempDir& dir, const std::vector<std::string>& args,
                    const std::string& at) {
  ::setenv("LODFORGE_INTERRUPT_AFTER", at.c_str(), 1);
  const pid_t pid = spawnLodforge(args, dir.file(".stderr"));
  ::unsetenv("LODFORGE_INTERRUPT_AFTER");
  const Finished stopped = waitFor(pid);
  const std::string err = test::readFile(dir.file(".stderr"));
  std::remove(dir.file(".stderr").c_str());
  EXPECT_EQ(stopped.code, 1) << "the run was not interrupted after " << at << ": " << err;
  EXPECT_NE(err.find("--resume"), std::string::npos) << err;
}

// `tiles INPUT -o b ARGS…` stopped as by Ctrl-C after its sixth tile node (or, given `stopAt`,
// after that durable step), then run again with --resume: the earlier work is reused (the output
// says `resumed`) and the tileset is byte for byte the one an uninterrupted run (into a) writes.
void expectResumesToTheSameTileset(const test::TempDir& dir, const std::string& input,
                                   const std::vector<std::string>& more,
                                   const std::string& stopAt = "",
                                   const std::string& resumed = "chunks resumed") {
  std::vector<std::string> args = {"-q", "--threads", "1", "tiles", input, "-o", dir.file("b")};
  args.insert(args.end(), more.begin(), more.end());
  std::string whole = "-q --threads 1 tiles " + input + " -o " + dir.file("a");
  for (const std::string& a : more) whole += " " + a;
  ASSERT_EQ(lodforge(whole, dir).code, 0);
  interruptAfter(dir, args, stopAt.empty() ? "node:6" : stopAt);
  EXPECT_FALSE(std::filesystem::exists(dir.file("b")));
  if (stopAt.empty()) {
    EXPECT_GT(test::listFolder(dir.file("b.work/tileset/tiles")).size(), 0u);
  } else {
    // What a stopped run that had flushed its chunk buffers leaves: chunk files that later
    // chunks are appended to. The resumed run must not build on them.
    std::filesystem::create_directories(dir.file("b.work/chunks"));
    for (int x = 0; x < 8; ++x)
      for (int y = 0; y < 8; ++y)
        for (int z = 0; z < 4; ++z)
          test::writeFile(dir.file(fmt::format("b.work/chunks/{}_{}_{}.tri", x, y, z)), "stale");
  }

  std::vector<std::string> resume = args;
  resume.push_back("--resume");
  resume.erase(resume.begin());  // -v instead of -q, to see that the chunks were reused
  resume.insert(resume.begin(), "-v");
  std::string line;
  for (const std::string& a : resume) line += a + " ";
  const Outcome o = lodforge(line, dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE((o.out + o.err).find(resumed), std::string::npos) << o.out << o.err;
  // Byte for byte the tileset of an uninterrupted run, and nothing left over.
  const std::vector<std::string> files = test::listFolder(dir.file("a/tiles"));
  ASSERT_EQ(test::listFolder(dir.file("b/tiles")), files);
  for (const std::string& f : files)
    ASSERT_EQ(test::readFile(dir.file("a/tiles/" + f)), test::readFile(dir.file("b/tiles/" + f)))
        << f;
  EXPECT_EQ(test::readFile(dir.file("a/tileset.json")), test::readFile(dir.file("b/tileset.json")));
  // (The input's own entry: the file, or the folder it and its images are in.)
  const std::string name = std::filesystem::relative(input, dir.path()).begin()->string();
  EXPECT_EQ(test::listFolder(dir.path()), (std::vector<std::string>{"a", "b", name}));
}

TEST(CliTiles, AnInterruptedRunResumesToTheSameTileset) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate scan --triangles 200K -o " + dir.file("scan.ply"), dir).code, 0);
  expectResumesToTheSameTileset(dir, dir.file("scan.ply"), {});
}

// A small textured scan, in/scan.ply with its two atlases beside it.
void generateTexturedScan(const test::TempDir& dir) {
  std::filesystem::create_directories(dir.file("in"));
  ASSERT_EQ(lodforge("-q generate scan --triangles 60K --texture 512 --atlases 2 -o " +
                         dir.file("in/scan.ply"),
                     dir)
                .code,
            0);
}

// A textured input resumes too: its materials and images are in the chunk state (an embedded
// image's bytes in the work directory) and its texture pyramids are taken as they are.
TEST(CliTiles, AnInterruptedTexturedRunResumesToTheSameTileset) {
  test::TempDir dir;
  generateTexturedScan(dir);
  expectResumesToTheSameTileset(dir, dir.file("in/scan.ply"), {});
}

TEST(CliTiles, AnInterruptedRunOfEmbeddedTexturesResumesToTheSameTileset) {
  test::TempDir dir;
  generateTexturedScan(dir);
  ASSERT_EQ(
      lodforge("-q convert " + dir.file("in/scan.ply") + " -o " + dir.file("in/scan.glb"), dir)
          .code,
      0);
  for (const char* name : {"scan.ply", "scan_atlas_00.jpg", "scan_atlas_01.jpg"})
    std::filesystem::remove(dir.file(std::string("in/") + name));
  expectResumesToTheSameTileset(dir, dir.file("in/scan.glb"), {});
}

// An OBJ's material library is part of what its chunks were made from: edited between the
// interrupted run and --resume, the run chunks again (the edit is in the tiles).
TEST(CliTiles, AnEditedMaterialLibraryMeansChunkingAgainOnResume) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("in"));
  ASSERT_EQ(lodforge("-q generate scan --triangles 60K -o " + dir.file("in/scan.ply"), dir).code,
            0);
  ASSERT_EQ(
      lodforge("-q convert " + dir.file("in/scan.ply") + " -o " + dir.file("in/scan.obj"), dir)
          .code,
      0);
  const std::string obj = test::readFile(dir.file("in/scan.obj"));
  test::writeFile(dir.file("in/scan.obj"), "mtllib paint.mtl\nusemtl paint\n" + obj);
  test::writeFile(dir.file("in/paint.mtl"), "newmtl paint\nKd 1 0 0\n");
  interruptAfter(dir,
                 {"-q", "--threads", "1", "tiles", dir.file("in/scan.obj"), "-o", dir.file("b")},
                 "node:6");
  test::writeFile(dir.file("in/paint.mtl"), "newmtl paint\nKd 0 0 1\n# now blue\n");
  const Outcome o = lodforge(
      "-v --threads 1 tiles " + dir.file("in/scan.obj") + " -o " + dir.file("b") + " --resume",
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ((o.out + o.err).find("chunks resumed"), std::string::npos) << o.out << o.err;
  // The same tileset as a run that only ever saw the blue library.
  ASSERT_EQ(
      lodforge("-q --threads 1 tiles " + dir.file("in/scan.obj") + " -o " + dir.file("c"), dir)
          .code,
      0);
  const std::vector<std::string> files = test::listFolder(dir.file("c/tiles"));
  ASSERT_EQ(test::listFolder(dir.file("b/tiles")), files);
  for (const std::string& f : files)
    ASSERT_EQ(test::readFile(dir.file("c/tiles/" + f)), test::readFile(dir.file("b/tiles/" + f)))
        << f;
}

// tiles --surface resumes like any tileset: the reconstructed chunks are kept.
TEST(CliTiles, AnInterruptedSurfaceResumesToTheSameTileset) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 50K -o " + dir.file("p.ply"), dir).code, 0);
  expectResumesToTheSameTileset(dir, dir.file("p.ply"), {"--surface", "--voxel", "4"});
}

// Stopped during the reconstruction itself, tiles --surface --resume takes the runs of chunks
// it finished (and not the leaf chunk files the stopped run had begun: see the helper).
TEST(CliTiles, AReconstructionStoppedHalfwayResumesToTheSameTileset) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 100K -o " + dir.file("p.ply"), dir).code, 0);
  expectResumesToTheSameTileset(dir, dir.file("p.ply"),
                                {"--surface", "--voxel", "6", "--chunk-size", "72"}, "run:1",
                                " resumed)");
}

// An environment variable set for a test's runs of lodforge, unset after.
struct ScopedVariable {
  std::string name;
  ScopedVariable(std::string n, const std::string& value) : name(std::move(n)) {
    ::setenv(name.c_str(), value.c_str(), 1);
  }
  ~ScopedVariable() { ::unsetenv(name.c_str()); }
};

// A point tileset of p.las into `out`, stopped as by Ctrl-C at the durable step `stopAt`
// ("pointnode:3": the third node of the partition ranked; "tile:4": the fourth tile written;
// with ":kill", killed there), then, after `damage`, resumed: the tileset is byte for byte the
// uninterrupted one in `a`, nothing is left beside it, and what `-v` says of the resumed work is
// returned.
std::string resumePointTiles(const test::TempDir& dir, const std::string& out,
                             const std::string& stopAt, const std::function<void()>& damage) {
  std::vector<std::string> args = {"-q",          "--threads",       "1",
                                   "tiles",       dir.file("p.las"), "-o",
                                   dir.file(out), "--block-size",    "1000"};
  if (stopAt.ends_with(":kill")) {
    ::setenv("LODFORGE_INTERRUPT_AFTER", stopAt.c_str(), 1);
    const pid_t pid = spawnLodforge(args, dir.file(".stderr"));
    ::unsetenv("LODFORGE_INTERRUPT_AFTER");
    EXPECT_EQ(waitFor(pid).code, -1) << "the run was not killed at " << stopAt;
    std::remove(dir.file(".stderr").c_str());
  } else {
    interruptAfter(dir, args, stopAt);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file(out)));
  // What a run killed while writing a tile leaves: --resume must not ship it.
  test::writeFile(dir.file(out + ".work/points/tileset/tiles/planted.glb.tmp-4242-7"), "partial");
  damage();
  args.front() = "-v";
  args.push_back("--resume");
  std::string line;
  for (const std::string& a : args) line += a + " ";
  const Outcome o = lodforge(line, dir);
  EXPECT_EQ(o.code, 0) << o.err;
  const std::vector<std::string> files = test::listFolder(dir.file("a/tiles"));
  EXPECT_EQ(test::listFolder(dir.file(out + "/tiles")), files);
  for (const std::string& f : files)
    EXPECT_EQ(test::readFile(dir.file("a/tiles/" + f)),
              test::readFile(dir.file(out + "/tiles/" + f)))
        << f;
  EXPECT_EQ(test::readFile(dir.file("a/tileset.json")),
            test::readFile(dir.file(out + "/tileset.json")));
  EXPECT_FALSE(std::filesystem::exists(dir.file(out + ".work")));
  const std::size_t at = o.err.find("resumed: ");
  return at == std::string::npos ? "" : o.err.substr(at, o.err.find('\n', at) - at);
}

// A point tileset resumes from the split input, each node of the partition ranked and each tile
// written (16 nodes of ~3,750 points here, LODFORGE_PARTITION_BYTES); a changed input starts
// over.
TEST(CliTiles, AnInterruptedPointRunResumesToTheSameTileset) {
  test::TempDir dir;
  const ScopedVariable nodes("LODFORGE_PARTITION_BYTES", "500000");
  ASSERT_EQ(
      lodforge("-q generate points --points 60K --extra-bytes -o " + dir.file("p.las"), dir).code,
      0);
  ASSERT_EQ(lodforge("-q --threads 1 tiles " + dir.file("p.las") + " -o " + dir.file("a") +
                         " --block-size 1000",
                     dir)
                .code,
            0);
  const auto none = [] {};
  EXPECT_EQ(resumePointTiles(dir, "b", "pointnode:3", none),
            "resumed: the input as the interrupted run split it, 3 of the partition's 16 nodes "
            "as it ranked them, 0 tiles as it wrote them");
  // (A tile another thread was writing when the fourth was done may be done too.) By then the
  // blocks read by those tiles alone (about half here: `b` and `b0` hold most of the 60K points)
  // were given back as holes in the work file; the resumed tileset, byte for byte the
  // uninterrupted one, shows that no hole was read.
  const auto holes = [&] {
    const std::string path = dir.file("c.work/points/b.points");
    struct stat info {};
    ASSERT_EQ(::stat(path.c_str(), &info), 0);
    EXPECT_LT(info.st_blocks * 512, info.st_size / 2) << "the written blocks were not given back";
  };
  const std::string tiles = resumePointTiles(dir, "c", "tile:4", holes);
  std::smatch kept;
  ASSERT_TRUE(std::regex_match(tiles, kept,
                               std::regex("resumed: the input as the interrupted run split it, 16 "
                                          "of the partition's 16 nodes as it ranked them, "
                                          "([0-9]+) tiles as it wrote them")))
      << tiles;
  EXPECT_GE(std::stoi(kept[1]), 4);
  // Stopped in the middle of its second node: the blocks after the stop are not ranked, so
  // that node is split again.
  EXPECT_EQ(resumePointTiles(dir, "f", "pointblock:6", none),
            "resumed: the input as the interrupted run split it, 1 of the partition's 16 nodes "
            "as it ranked them, 0 tiles as it wrote them");
  // Killed with its third node staged but not yet in place: --resume puts it there, whatever
  // its place holds (here garbage, as a copy cut short may leave).
  const auto scribble = [&] {
    const nlohmann::json state =
        nlohmann::json::parse(test::readFile(dir.file("d.work/points/state.json")));
    const std::string path = dir.file("d.work/points/b.points");
    const std::uint64_t recordBytes =
        std::filesystem::file_size(path) / state["count"].get<std::uint64_t>();
    const nlohmann::json& third = state["nodes"][2];
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(third["first"].get<std::uint64_t>() * recordBytes));
    const std::string garbage(third["count"].get<std::uint64_t>() * recordBytes, '\x5a');
    file.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  };
  EXPECT_EQ(resumePointTiles(dir, "d", "pointstaged:3:kill", scribble),
            "resumed: the input as the interrupted run split it, 3 of the partition's 16 nodes "
            "as it ranked them, 0 tiles as it wrote them");
  EXPECT_EQ(resumePointTiles(dir, "e", "pointnode:3",
                             [&] {
                               const auto file = dir.file("p.las");
                               std::filesystem::last_write_time(
                                   file, std::filesystem::last_write_time(file) +
                                             std::chrono::seconds(10));
                             }),
            "");
  EXPECT_EQ(test::listFolder(dir.path()),
            (std::vector<std::string>{"a", "b", "c", "d", "e", "f", "p.las"}));
}

// reconstruct: Ctrl-C after some runs of chunks keeps OUTPUT.work and says so; --resume takes
// the finished runs and writes the bytes of an unbroken run, leaving nothing else behind.
TEST(CliReconstruct, AnInterruptedReconstructionResumesToTheSameMesh) {
  test::TempDir dir;
  ASSERT_EQ(lodforge("-q generate points --points 50K -o " + dir.file("p.ply"), dir).code, 0);
  const std::vector<std::string> args = {"-q",
                                         "--threads",
                                         "1",
                                         "--memory-limit",
                                         "64M",
                                         "reconstruct",
                                         dir.file("p.ply"),
                                         "-o",
                                         dir.file("b.ply"),
                                         "--voxel",
                                         "4"};
  std::string whole;
  for (const std::string& a : args) whole += (a == dir.file("b.ply") ? dir.file("a.ply") : a) + " ";
  ASSERT_EQ(lodforge(whole, dir).code, 0);
  interruptAfter(dir, args, "run:2");
  EXPECT_TRUE(std::filesystem::exists(dir.file("b.ply.work/run-1.pieces")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("b.ply")));
  std::string resume = "-v";
  for (std::size_t a = 1; a < args.size(); ++a) resume += " " + args[a];
  const Outcome o = lodforge(resume + " --resume", dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE((o.out + o.err).find(" resumed"), std::string::npos) << o.out << o.err;
  EXPECT_EQ(test::readFile(dir.file("a.ply")), test::readFile(dir.file("b.ply")));
  EXPECT_EQ(test::listFolder(dir.path()), (std::vector<std::string>{"a.ply", "b.ply", "p.ply"}));
}

TEST(CliBench, RunsEveryBudgetAndHitsItExactly) {
  test::TempDir dir;
  const std::string package = dir.file("engine.lfp");
  ASSERT_EQ(buildPackage("2CylinderEngine.glb", package, dir), 0);
  const std::uint64_t vertices = info(package, dir)["vertices"].get<std::uint64_t>();
  Outcome o = lodforge("bench " + package + " --frames 8 --budget 10%,20K,100% --json " +
                           dir.file("b.json") + " --record-path " + dir.file("path.json"),
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("sel ms"), std::string::npos) << o.out;
  const auto j = nlohmann::json::parse(test::readFile(dir.file("b.json")));
  ASSERT_EQ(j["runs"].size(), 3u);
  EXPECT_EQ(j["runs"][0]["budget"].get<std::uint64_t>(), (vertices + 5) / 10);
  EXPECT_EQ(j["runs"][1]["budget"].get<std::uint64_t>(), 20'000u);
  for (const auto& run : j["runs"]) {
    EXPECT_EQ(run["exact_frames"], 8u);
    EXPECT_EQ(run["frames"], 7u);  // the first frame is reported as the load
    EXPECT_EQ(run["load"]["bytes_moved"], 0u);
    EXPECT_EQ(run["mean"]["vertices"].get<double>(),
              static_cast<double>(std::min(run["budget"].get<std::uint64_t>(), vertices)));
  }
  // At 100 % nothing changes after the load: no reads, no re-formation.
  EXPECT_EQ(j["runs"][2]["mean"]["bytes_read"].get<double>(), 0.0);
  EXPECT_EQ(j["runs"][2]["mean"]["triangles_reformed"].get<double>(), 0.0);
  // The recorded path replays.
  o = lodforge(
      "bench " + package + " --path " + dir.file("path.json") + " --budget 5% --first-pass-only",
      dir);
  EXPECT_EQ(o.code, 0) << o.err;
  o = lodforge("bench " + package + " --path fly --frames 4 --target-error 2", dir);
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("error px"), std::string::npos) << o.out;
}

TEST(CliBench, BadArgumentsAndPathsGetExitCode2) {
  test::TempDir dir;
  const std::string package = dir.file("motor.lfp");
  ASSERT_EQ(buildPackage("as1_motor.glb", package, dir), 0);
  test::writeFile(dir.file("bad.json"), R"({"frames": [{"position": [0, 0, 0], "target": [0, 0)");
  Outcome o = lodforge("bench " + package + " --path " + dir.file("bad.json"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find(dir.file("bad.json") + ": byte "), std::string::npos) << o.err;
  o = lodforge("bench " + package + " --path " + dir.file("missing.json"), dir);
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.err.find("missing.json"), std::string::npos) << o.err;
  o = lodforge("bench " + package + " --budget 5%,lots", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("'lots' is not a vertex count"), std::string::npos) << o.err;
  EXPECT_EQ(lodforge("bench " + package + " --budget 120%", dir).code, 2);
  EXPECT_EQ(lodforge("bench " + package + " --size 100", dir).code, 2);
  o = lodforge("bench " + package + " --budget 100% --gpu-memory 64K", dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("does not fit --gpu-memory"), std::string::npos) << o.err;
  o = lodforge("bench " + dir.file("motor.lfp.missing"), dir);
  EXPECT_NE(o.code, 0);
}

Image gradient(std::uint32_t w, std::uint32_t h, std::uint8_t shift) {
  Image image(w, h);
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    image.rgba[4 * i] = static_cast<std::uint8_t>(i + shift);
    image.rgba[4 * i + 1] = static_cast<std::uint8_t>(i / 3);
    image.rgba[4 * i + 2] = 90;
    image.rgba[4 * i + 3] = 255;
  }
  return image;
}

TEST(CliCompare, FilesAndFoldersWithHeatMapsAndJson) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("a"));
  std::filesystem::create_directories(dir.file("b"));
  ASSERT_TRUE(writePng(dir.file("a/f0.png"), gradient(64, 32, 0)).ok());
  ASSERT_TRUE(writePng(dir.file("b/f0.png"), gradient(64, 32, 0)).ok());
  ASSERT_TRUE(writePng(dir.file("a/f1.png"), gradient(64, 32, 0)).ok());
  ASSERT_TRUE(writePng(dir.file("b/f1.png"), gradient(64, 32, 40)).ok());
  // Two equal files: nothing above the threshold, infinite PSNR.
  Outcome o = lodforge("compare " + dir.file("a/f0.png") + " " + dir.file("b/f0.png") + " --json " +
                           dir.file("one.json"),
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("inf"), std::string::npos) << o.out;
  auto j = nlohmann::json::parse(test::readFile(dir.file("one.json")));
  EXPECT_EQ(j["frames"][0]["share_above"], 0.0);
  // Folders: frames pair by name; the shifted one differs, and its heat map is written.
  o = lodforge("compare " + dir.file("a") + " " + dir.file("b") + " --diff " + dir.file("heat") +
                   " --json " + dir.file("two.json"),
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  j = nlohmann::json::parse(test::readFile(dir.file("two.json")));
  ASSERT_EQ(j["frames"].size(), 2u);
  EXPECT_EQ(j["frames"][0]["share_above"], 0.0);
  EXPECT_GT(j["frames"][1]["share_above"].get<double>(), 0.5);
  const auto heat = readPng(dir.file("heat/f1.png"));
  ASSERT_TRUE(heat.ok());
  EXPECT_EQ(heat->width, 64u);
  // The library's own figures agree with the command's.
  const ImageDifference d = compareImages(gradient(64, 32, 0), gradient(64, 32, 40));
  EXPECT_NEAR(j["frames"][1]["mean_delta_e"].get<double>(), d.meanDeltaE, 1e-9);
  // A JPEG against its PNG source, paired by name without the extension: a finite PSNR that
  // agrees with the library's for the decoded JPEG.
  std::filesystem::create_directories(dir.file("jpeg"));
  auto jpeg = encodeImage(gradient(64, 32, 0), {.format = ImageFormat::kJpeg, .quality = 80});
  ASSERT_TRUE(jpeg.ok());
  test::writeFile(dir.file("jpeg/f0.jpg"),
                  std::string(reinterpret_cast<const char*>(jpeg->data()), jpeg->size()));
  std::filesystem::remove(dir.file("b/f1.png"));
  std::filesystem::remove(dir.file("a/f1.png"));
  o = lodforge(
      "compare " + dir.file("a") + " " + dir.file("jpeg") + " --json " + dir.file("three.json"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  j = nlohmann::json::parse(test::readFile(dir.file("three.json")));
  ASSERT_EQ(j["frames"].size(), 1u);
  auto decoded = decodeImage(*jpeg, "f0.jpg");
  ASSERT_TRUE(decoded.ok());
  const ImageDifference lossy = compareImages(gradient(64, 32, 0), *decoded);
  ASSERT_TRUE(std::isfinite(lossy.psnr));
  EXPECT_GT(lossy.psnr, 15);
  EXPECT_NEAR(j["frames"][0]["psnr_db"].get<double>(), lossy.psnr, 1e-9);
}

// Two textured meshes with the same image: their texture-space error in texels — none from a
// mesh to itself, 2 texels everywhere against a copy whose coordinates are shifted by 0.02 on a
// texture 100 texels wide (the JSON too).
TEST(CliCompare, TexturedMeshesGiveTheirTextureErrorInTexels) {
  test::TempDir dir;
  Image texels(100, 50);
  auto png = encodeImage(texels, {.format = ImageFormat::kPng});
  ASSERT_TRUE(png.ok());
  test::writeFile(dir.file("t.png"),
                  std::string(reinterpret_cast<const char*>(png->data()), png->size()));
  test::writeFile(dir.file("t.mtl"), "newmtl t\nmap_Kd t.png\n");
  const auto quad = [&](const std::string& name, double shift) {
    test::writeFile(dir.file(name), fmt::format("mtllib t.mtl\nv 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\n"
                                                "vt {0} 0.1\nvt {1} 0.1\nvt {1} 0.9\nvt {0} 0.9\n"
                                                "usemtl t\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
                                                0.1 + shift, 0.9 + shift));
  };
  quad("a.obj", 0);
  quad("b.obj", 0.02);
  Outcome o = lodforge("compare " + dir.file("a.obj") + " " + dir.file("a.obj") +
                           " --samples 2000 --json " + dir.file("same.json"),
                       dir);
  ASSERT_EQ(o.code, 0) << o.err;
  auto j = nlohmann::json::parse(test::readFile(dir.file("same.json")));
  ASSERT_TRUE(j.contains("texture_texels")) << j.dump();
  EXPECT_NEAR(j["texture_texels"]["max"].get<double>(), 0.0, 1e-4);
  o = lodforge("compare " + dir.file("a.obj") + " " + dir.file("b.obj") +
                   " --samples 2000 --json " + dir.file("shifted.json"),
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("texture error"), std::string::npos) << o.out;
  j = nlohmann::json::parse(test::readFile(dir.file("shifted.json")));
  EXPECT_NEAR(j["texture_texels"]["mean"].get<double>(), 2.0, 1e-3);
  EXPECT_NEAR(j["texture_texels"]["max"].get<double>(), 2.0, 1e-3);
  EXPECT_EQ(j["texture_texels"]["other_texture"].get<int>(), 0);
}

// Two meshes: their surface distance — none from a mesh to itself, the offset between a mesh
// and a copy moved along its normal (a flat square), in the text and the JSON.
TEST(CliCompare, MeshesGiveTheirSurfaceDistance) {
  test::TempDir dir;
  const auto square = [&](const std::string& name, double z) {
    test::writeFile(dir.file(name), fmt::format("v 0 0 {0}\nv 10 0 {0}\nv 10 10 {0}\nv 0 10 {0}\n"
                                                "f 1 2 3\nf 1 3 4\n",
                                                z));
  };
  square("a.obj", 1);
  square("b.obj", 1.25);
  Outcome o = lodforge(
      "compare " + dir.file("a.obj") + " " + dir.file("a.obj") + " --json " + dir.file("self.json"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("hausdorff "), std::string::npos) << o.out;
  EXPECT_LT(nlohmann::json::parse(test::readFile(dir.file("self.json")))["hausdorff"].get<double>(),
            1e-9);
  o = lodforge("compare " + dir.file("a.obj") + " " + dir.file("b.obj") +
                   " --samples 5000 --json " + dir.file("d.json"),
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const nlohmann::json d = nlohmann::json::parse(test::readFile(dir.file("d.json")));
  EXPECT_NEAR(d["hausdorff"].get<double>(), 0.25, 1e-6);
  EXPECT_NEAR(d["rms"].get<double>(), 0.25, 1e-6);
  EXPECT_EQ(d["samples"], 5000);
  test::writeFile(dir.file("points.obj"), "v 0 0 0\nv 1 0 0\n");
  o = lodforge("compare " + dir.file("a.obj") + " " + dir.file("points.obj"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("no triangles"), std::string::npos) << o.err;
}

TEST(CliCompare, MismatchedOrBadImagesAreExitCode2) {
  test::TempDir dir;
  ASSERT_TRUE(writePng(dir.file("small.png"), gradient(8, 8, 0)).ok());
  ASSERT_TRUE(writePng(dir.file("big.png"), gradient(9, 8, 0)).ok());
  test::writeFile(dir.file("text.png"), "not an image");
  Outcome o = lodforge("compare " + dir.file("small.png") + " " + dir.file("big.png"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("big.png"), std::string::npos) << o.err;
  o = lodforge("compare " + dir.file("small.png") + " " + dir.file("text.png"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("text.png"), std::string::npos) << o.err;
  o = lodforge("compare " + dir.file("small.png") + " " + dir.path().string(), dir);
  EXPECT_EQ(o.code, 2) << "a file and a folder";
}

TEST(CliRender, FramesAlongAPathMatchTheReferenceAtFullBudget) {
  test::TempDir dir;
  const std::string package = dir.file("engine.lfp");
  ASSERT_EQ(buildPackage("2CylinderEngine.glb", package, dir), 0);
  Outcome o =
      lodforge("render " + package + " --reference --frames 3 --size 200x150 -o " + dir.file("ref"),
               dir, glSubprocess());
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("render " + package + " --budget 100% --frames 3 --size 200x150 -o " +
                   dir.file("full") + " --json " + dir.file("full.json"),
               dir, glSubprocess());
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge("render " + package + " --budget 5% --frames 3 --size 200x150 --color lod -o " +
                   dir.file("low"),
               dir, glSubprocess());
  ASSERT_EQ(o.code, 0) << o.err;
  // The compute-shader reformation draws the same frames as the CPU path.
  o = lodforge("render " + package +
                   " --budget 5% --frames 3 --size 200x150 --color lod --gpu-reform -o " +
                   dir.file("low-gpu"),
               dir, glSubprocess());
  ASSERT_EQ(o.code, 0) << o.err;
  o = lodforge(
      "compare " + dir.file("low") + " " + dir.file("low-gpu") + " --json " + dir.file("g.json"),
      dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(nlohmann::json::parse(test::readFile(dir.file("g.json")))["mean_delta_e"], 0.0);
  // Three frames each, and nothing else but the summary (no temporary left behind).
  auto files = test::listFolder(dir.file("ref"));
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"frame_0000.png", "frame_0001.png", "frame_0002.png",
                                             "render.json"}));
  for (const auto& name : test::listFolder(dir.path()))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
  const auto frame = readPng(dir.file("ref/frame_0001.png"));
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->width, 200u);
  EXPECT_EQ(frame->height, 150u);
  // 100 % of the budget is the full model: identical pixels.
  o = lodforge(
      "compare " + dir.file("ref") + " " + dir.file("full") + " --json " + dir.file("c.json"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const auto c = nlohmann::json::parse(test::readFile(dir.file("c.json")));
  EXPECT_EQ(c["mean_delta_e"], 0.0);
  const auto j = nlohmann::json::parse(test::readFile(dir.file("full.json")));
  ASSERT_EQ(j["frames"].size(), 3u);
  EXPECT_EQ(j["frames"][0]["vertices"].get<std::uint64_t>(),
            info(package, dir)["vertices"].get<std::uint64_t>());
  // 5 % in LOD colours differs from the reference.
  o = lodforge(
      "compare " + dir.file("ref") + " " + dir.file("low") + " --json " + dir.file("d.json"), dir);
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_GT(
      nlohmann::json::parse(test::readFile(dir.file("d.json")))["mean_share_above"].get<double>(),
      0.01);
}

TEST(CliRender, BadArgumentsAndPackagesAreExitCode2) {
  test::TempDir dir;
  test::writeFile(dir.file("bad.lfp"), "not a package");
  Outcome o = lodforge("render " + dir.file("bad.lfp") + " -o " + dir.file("out"), dir);
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("bad.lfp"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
  const std::string package = dir.file("motor.lfp");
  ASSERT_EQ(buildPackage("as1_motor.glb", package, dir), 0);
  EXPECT_EQ(lodforge("render " + package + " --budget 0 -o " + dir.file("out"), dir).code, 2);
  EXPECT_EQ(lodforge("render " + package + " --budget 150% -o " + dir.file("out"), dir).code, 2);
  EXPECT_EQ(lodforge("render " + package + " --size 10 -o " + dir.file("out"), dir).code, 2);
  EXPECT_EQ(lodforge("render " + package + " --color rainbow -o " + dir.file("out"), dir).code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
}

// The viewer needs a display: the tests give it a virtual one (Debian's xvfb, installed by
// scripts/install-deps.sh; missing, the test fails rather than skips).
Outcome viewUnderXvfb(const std::string& args, const test::TempDir& dir) {
  return lodforge("view " + args, dir, "xvfb-run -a -s '-screen 0 1280x1024x24' ");
}

TEST(CliView, WithoutADisplayItSaysSoAndPointsAtRender) {
  test::TempDir dir;
  const std::string package = dir.file("motor.lfp");
  ASSERT_EQ(buildPackage("as1_motor.glb", package, dir), 0);
  const Outcome o = lodforge("view " + package, dir, "env -u DISPLAY -u WAYLAND_DISPLAY ");
  ASSERT_NE(o.code, -1) << "exited normally";
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("lodforge render"), std::string::npos) << o.err;
}

TEST(CliView, ScriptedRunRecordsAPathWhoseReplayMatchesHeadlessRender) {
  test::TempDir dir;
  const std::string package = dir.file("engine.lfp");
  ASSERT_EQ(buildPackage("2CylinderEngine.glb", package, dir), 0);
  // An orbit played in the window, recorded, with a screenshot of the last frame.
  Outcome o = viewUnderXvfb(package + " --play orbit --frames 12 --stop-after 12 --size 320x240" +
                                " --budget 10% --record " + dir.file("rec.json") +
                                " --screenshot " + dir.file("a.png"),
                            dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const auto path = nlohmann::json::parse(test::readFile(dir.file("rec.json")));
  ASSERT_EQ(path["frames"].size(), 12u);
  const auto shot = readPng(dir.file("a.png"));
  ASSERT_TRUE(shot.ok());
  EXPECT_EQ(shot->width, 320u);
  // The recorded path replayed headless at the same budget draws the same last frame.
  o = lodforge("render " + package + " --path " + dir.file("rec.json") +
                   " --frames 12 --budget 10% -o " + dir.file("r"),
               dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const auto frame = readPng(dir.file("r/frame_0011.png"));
  ASSERT_TRUE(frame.ok());
  ASSERT_EQ(frame->width, 320u);
  const ImageDifference d = compareImages(*shot, *frame);
  EXPECT_LT(d.maxDeltaE, kJustNoticeableDeltaE) << "window and offscreen frames should agree";
  // Replayed in the window with the paper's GPU streaming: the same frame again.
  o = viewUnderXvfb(package + " --play " + dir.file("rec.json") +
                        " --stop-after 12 --size 320x240" +
                        " --budget 10% --gpu-stream --screenshot " + dir.file("b.png"),
                    dir);
  ASSERT_EQ(o.code, 0) << o.err;
  const auto replay = readPng(dir.file("b.png"));
  ASSERT_TRUE(replay.ok());
  EXPECT_LT(compareImages(*replay, *frame).maxDeltaE, kJustNoticeableDeltaE);
  // And the frame shows the model.
  const ImageDifference empty = compareImages(*shot, Image(320, 240));
  EXPECT_GT(empty.shareAbove, 0.05);
}

TEST(CliBench, RenderAddsTheOpenGlColumn) {
  test::TempDir dir;
  const std::string package = dir.file("motor.lfp");
  ASSERT_EQ(buildPackage("as1_motor.glb", package, dir), 0);
  for (const char* extra : {"", " --gpu-reform", " --gpu-stream"}) {
    const Outcome o =
        lodforge("bench " + package + " --frames 4 --budget 10%,100% --size 160x120 --render" +
                     extra + " --json " + dir.file("b.json"),
                 dir);
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_NE(o.out.find("render ms"), std::string::npos) << o.out;
    const auto j = nlohmann::json::parse(test::readFile(dir.file("b.json")));
    const std::string mode = extra;
    EXPECT_EQ(j["render"], mode.empty()              ? "cpu"
                           : mode == " --gpu-reform" ? "cpu-stream-gpu-reform"
                                                     : "gpu");
    // Σ vc = N and what was read match whichever side streams.
    EXPECT_EQ(j["runs"][1]["mean"]["bytes_read"], 0.0)
        << "100 % after the first frame reads nothing";
    for (const auto& run : j["runs"]) EXPECT_GT(run["mean"]["render_ms"].get<double>(), 0.0);
    // Which platform drew (Mesa's surfaceless here; an EGL device on NVIDIA's driver).
    EXPECT_NE(o.out.find(" (EGL "), std::string::npos) << o.out;
    // The CPU stream sends what changed: at 10 % some, at 100 % (unchanged) only the commands;
    // the GPU stream's copies are not counted.
    const auto& sent0 = j["runs"][0]["mean"]["uploaded_bytes"];
    const auto& sent1 = j["runs"][1]["mean"]["uploaded_bytes"];
    if (mode == " --gpu-stream") {
      EXPECT_TRUE(sent0.is_null()) << sent0;
    } else {
      EXPECT_GT(sent0.get<double>(), sent1.get<double>());
      EXPECT_GT(sent1.get<double>(), 0.0);
    }
  }
  // Without --render the column stays empty and --gpu-reform alone is a usage error.
  EXPECT_EQ(lodforge("bench " + package + " --frames 2 --gpu-reform", dir).code, 2);
}

}  // namespace
}  // namespace lodforge
