// Never destroy what is not ours: every command that writes, run at outputs that are not its own,
// leaves every byte that was there as it was and no temporary behind; only its own earlier
// output is replaced. The real binary on real files.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <map>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "run_lodforge.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;
using test::lodforge;
using test::Outcome;

// Every file (by relative path, with its size and a hash of its bytes) and directory below
// `root`.
std::map<std::string, std::string> snapshot(const fs::path& root, const std::string& skip = "") {
  std::map<std::string, std::string> files;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator();
       ++it) {
    const std::string relative = fs::relative(it->path(), root).generic_string();
    if (!skip.empty() && (relative == skip || relative.starts_with(skip + "/") ||
                          relative.starts_with(fs::path(skip).replace_extension(".lfs").string())))
      continue;
    const std::string bytes = it->is_directory() ? "" : test::readFile(it->path().string());
    files[relative] = it->is_directory() ? "directory"
                                         : fmt::format("{} bytes, hash {:016x}", bytes.size(),
                                                       std::hash<std::string>{}(bytes));
  }
  return files;
}

std::uint64_t inode(const std::string& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return info.st_ino;
}

// A command that writes: its input (a file made once in `sources`, copied into each case's
// folder; empty for generate), its output's name and whether it is a directory, its arguments.
struct Command {
  std::string name;
  std::string input;
  std::string output;
  bool directory = false;
  std::function<std::string(const std::string& in, const std::string& out)> args;
  std::string wrapper;  // in front of the binary
};

std::vector<Command> writingCommands() {
  return {
      {"tiles (mesh)", "scan.ply", "tiles", true,
       [](auto& in, auto& out) { return "-q tiles " + in + " -o " + out; }, ""},
      {"tiles (points)", "cloud.las", "tiles", true,
       [](auto& in, auto& out) { return "-q tiles " + in + " -o " + out; }, ""},
      {"points", "cloud.las", "cloud.lfc", false,
       [](auto& in, auto& out) { return "-q points " + in + " -o " + out; }, ""},
      {"build", "scan.ply", "model.lfp", false,
       [](auto& in, auto& out) { return "-q build " + in + " -o " + out; }, ""},
      {"extract", "model.lfp", "model.glb", false,
       [](auto& in, auto& out) { return "-q extract " + in + " --ratio 0.5 -o " + out; }, ""},
      {"convert", "scan.ply", "scan.obj", false,
       [](auto& in, auto& out) { return "-q convert " + in + " -o " + out; }, ""},
      {"convert (LAZ to LAS)", "cloud.laz", "cloud.las", false,
       [](auto& in, auto& out) { return "-q convert " + in + " -o " + out; }, ""},
      {"render", "model.lfp", "frames", true,
       [](auto& in, auto& out) { return "-q render " + in + " --frames 1 --size 32x24 -o " + out; },
       test::glSubprocess()},
      {"reconstruct", "points.ply", "surface.ply", false,
       [](auto& in, auto& out) { return "-q reconstruct " + in + " -o " + out; }, ""},
      {"generate", "", "made.ply", false,
       [](auto&, auto& out) { return "-q generate scan --triangles 2K -o " + out; }, ""},
  };
}

class WritingCommands : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sources_ = new test::TempDir();
    const std::string scan = sources_->file("scan.ply");
    ASSERT_EQ(lodforge("-q generate scan --triangles 20K -o " + scan, *sources_).code, 0);
    ASSERT_EQ(
        lodforge("-q generate points --points 5K -o " + sources_->file("points.ply"), *sources_)
            .code,
        0);
    fs::copy_file(test::dataPath("points/simple.las"), sources_->file("cloud.las"));
    fs::permissions(sources_->file("cloud.las"), fs::perms::owner_write, fs::perm_options::add);
    fs::copy_file(test::dataPath("points/simple-v1.laz"), sources_->file("cloud.laz"));
    fs::permissions(sources_->file("cloud.laz"), fs::perms::owner_write, fs::perm_options::add);
    ASSERT_EQ(lodforge("-q build " + scan + " -o " + sources_->file("model.lfp"), *sources_).code,
              0);
  }
  static void TearDownTestSuite() { delete sources_; }

  // A fresh folder for one case, holding a copy of the command's input.
  fs::path caseFolder(const Command& command, const std::string& scenario) {
    const fs::path folder = dir_.path() / fmt::format("{}-{}", cases_++, scenario);
    fs::create_directories(folder);
    if (!command.input.empty())
      fs::copy_file(sources_->file(command.input), folder / command.input);
    return folder;
  }

  Outcome run(const Command& command, const fs::path& folder, const std::string& output,
              const std::string& wrapper = "") {
    const std::string in = command.input.empty() ? "" : (folder / command.input).string();
    // An environment prefix (the command's) goes first, in front of a wrapper such as setpriv.
    return lodforge(command.args(in, output), dir_, command.wrapper + wrapper);
  }

  // Runs `command` at `output` and checks that it is refused with `code` and that nothing in
  // the case's folder changed (every byte, no temporary).
  void expectRefused(const Command& command, const fs::path& folder, const std::string& output,
                     int code, const std::string& wrapper = "", std::string named = "") {
    const auto before = snapshot(folder);
    const Outcome o = run(command, folder, output, wrapper);
    EXPECT_EQ(o.code, code) << command.name << " -o " << output << "\n" << o.err;
    if (named.empty()) named = fs::path(output).filename().string();
    EXPECT_NE(o.err.find(named), std::string::npos)
        << command.name << ": the message names the output\n"
        << o.err;
    EXPECT_EQ(snapshot(folder), before) << command.name << " -o " << output;
  }

  static test::TempDir* sources_;
  test::TempDir dir_;
  int cases_ = 0;
};

test::TempDir* WritingCommands::sources_ = nullptr;

TEST_F(WritingCommands, RefuseADirectoryHoldingForeignFiles) {
  for (const Command& command : writingCommands()) {
    const fs::path folder = caseFolder(command, "foreign");
    const fs::path output = folder / command.output;
    fs::create_directories(output);
    test::writeFile((output / "notes.txt").string(), "my notes\n");
    expectRefused(command, folder, output.string(), 2);
  }
}

TEST_F(WritingCommands, RefuseTheInputItselfAsOutput) {
  for (const Command& command : writingCommands()) {
    if (command.input.empty()) continue;  // generate reads nothing
    const fs::path folder = caseFolder(command, "input");
    expectRefused(command, folder, (folder / command.input).string(), 2);
  }
}

TEST_F(WritingCommands, ReportAPlaceTheyCannotWriteAsExitCode1) {
  // root writes anywhere: the command runs as nobody there (the folder and input stay readable).
  const std::string wrapper =
      ::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
  for (const Command& command : writingCommands()) {
    const fs::path folder = caseFolder(command, "readonly");
    fs::create_directories(folder / "locked");
    fs::permissions(folder / "locked", fs::perms(0555));
    expectRefused(command, folder, (folder / "locked" / command.output).string(), 1, wrapper);
    fs::permissions(folder / "locked", fs::perms(0755));
  }
}

TEST_F(WritingCommands, RefuseAFileOfAnotherKind) {
  for (const Command& command : writingCommands()) {
    const fs::path folder = caseFolder(command, "other-kind");
    const fs::path output = folder / command.output;
    test::writeFile(output.string(), "\x01\x02 not what this command writes\n");
    expectRefused(command, folder, output.string(), 2);
  }
}

TEST_F(WritingCommands, ReplaceTheirOwnEarlierOutput) {
  for (const Command& command : writingCommands()) {
    const fs::path folder = caseFolder(command, "again");
    const std::string output = (folder / command.output).string();
    Outcome o = run(command, folder, output);
    ASSERT_EQ(o.code, 0) << command.name << "\n" << o.err;
    const auto others = snapshot(folder, command.output);
    const std::uint64_t first = inode(output);
    o = run(command, folder, output);
    ASSERT_EQ(o.code, 0) << command.name << ": an earlier output of its own is replaced\n" << o.err;
    EXPECT_NE(inode(output), first) << command.name << ": a new output took its place";
    EXPECT_EQ(snapshot(folder, command.output), others)
        << command.name << ": nothing else changed, no temporary left";
  }
}

TEST_F(WritingCommands, RefuseADirectoryAsInput) {
  for (const Command& command : writingCommands()) {
    if (command.input.empty()) continue;
    const fs::path folder = dir_.path() / fmt::format("{}-directory-input", cases_++);
    fs::create_directories(folder / command.input);  // a directory named like the input
    const auto before = snapshot(folder);
    const Outcome o = run(command, folder, (folder / command.output).string());
    EXPECT_EQ(o.code, 2) << command.name << "\n" << o.err;
    EXPECT_NE(o.err.find("is a directory"), std::string::npos) << command.name << "\n" << o.err;
    EXPECT_EQ(snapshot(folder), before) << command.name << ": nothing left behind";
  }
}

// The segment directory beside a point package is the user's when it holds anything else.
TEST_F(WritingCommands, PointsKeepFilesTheUserKeepsBesideThePackage) {
  const Command points = writingCommands()[2];
  ASSERT_EQ(points.name, "points");
  const fs::path folder = caseFolder(points, "segments");
  fs::create_directories(folder / "cloud.lfs");
  test::writeFile((folder / "cloud.lfs/keep.txt").string(), "mine\n");
  expectRefused(points, folder, (folder / "cloud.lfc").string(), 2, "", "cloud.lfs");
}

// Stable work directories (tiles --resume) are claimed only when lodforge made them.
TEST_F(WritingCommands, MeshTilesKeepAWorkDirectoryThatIsNotTheirs) {
  const Command tiles = writingCommands()[0];
  const fs::path folder = caseFolder(tiles, "work");
  fs::create_directories(folder / "tiles.work");
  test::writeFile((folder / "tiles.work/state.json").string(), "{}\n");
  expectRefused(tiles, folder, (folder / "tiles").string(), 2, "", "tiles.work");
}

}  // namespace
}  // namespace lodforge
