#include "outputs.h"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "lodforge/core/file.h"
#include "lodforge/simplify/package.h"

namespace lodforge::cli {

namespace {

// The first bytes of a file (up to `bytes`), empty when it cannot be read.
std::string head(const std::string& path, std::uint64_t bytes) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return {};
  std::string text(std::min(bytes, source->size()), '\0');
  try {
    if (!source->read(text.data(), text.size())) return {};
  } catch (const ErrorException&) {
    return {};
  }
  return text;
}

std::string_view firstNonSpace(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  return text;
}

// OBJ is text whose first statement (after comments) is one of its keywords.
bool looksLikeObj(const std::string& path) {
  const std::string text = head(path, 4096);
  if (text.find('\0') != std::string::npos) return false;
  static constexpr std::string_view kStatements[] = {
      "#", "v ", "vt ", "vn ", "vp ", "f ", "l ", "p ", "o ", "g ", "s ", "mtllib ", "usemtl "};
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = firstNonSpace(std::string_view(text).substr(start, end - start));
    if (!line.empty())
      return std::any_of(std::begin(kStatements), std::end(kStatements),
                         [&](std::string_view keyword) { return line.starts_with(keyword); });
    start = end + 1;
  }
  return false;
}

// What `lodforge render` writes into its folder: frame_NNNN.png (four digits or more) and
// render.json.
bool isRenderFile(std::string_view name) {
  if (name == "render.json") return true;
  if (!name.starts_with("frame_") || !name.ends_with(".png")) return false;
  const std::string_view digits = name.substr(6, name.size() - 10);
  return digits.size() >= 4 && std::all_of(digits.begin(), digits.end(), [](char c) {
           return std::isdigit(static_cast<unsigned char>(c)) != 0;
         });
}

// Binary STL: 80 bytes of header, a count, 50 bytes per triangle; or ASCII "solid".
bool looksLikeStl(const std::string& path) {
  if (fileStartsWith(path, "solid")) return true;
  const std::string bytes = head(path, 84);
  const Result<std::uint64_t> size = fileSize(path);
  if (bytes.size() < 84 || !size) return false;
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  return *size == 84 + std::uint64_t{50} * count;
}

bool looksLikeJson(const std::string& path) {
  const std::string text = head(path, 4096);
  const std::string_view start = firstNonSpace(text);
  return !start.empty() && (start.front() == '{' || start.front() == '[');
}

}  // namespace

OutputKind modelFileOutput(const std::string& path) {
  const std::string ext = fileExtension(path);
  if (ext == "ply")
    return {.name = "a PLY file", .isOwn = [](const std::string& p) {
              return fileStartsWith(p, "ply\n") || fileStartsWith(p, "ply\r\n");
            }};
  if (ext == "glb")
    return {.name = "a GLB file",
            .isOwn = [](const std::string& p) { return fileStartsWith(p, "glTF"); }};
  if (ext == "gltf") return {.name = "a glTF file", .isOwn = looksLikeJson};
  if (ext == "obj") return {.name = "an OBJ file", .isOwn = looksLikeObj};
  if (ext == "stl") return {.name = "an STL file", .isOwn = looksLikeStl};
  if (ext == "las")
    return {.name = "a LAS file",
            .isOwn = [](const std::string& p) { return fileStartsWith(p, "LASF"); }};
  return {.name = "a model file", .isOwn = {}};
}

OutputKind packageOutput() {
  return {.name = "a package (.lfp)", .isOwn = [](const std::string& p) {
            return fileStartsWith(p, std::string_view(kPackageMagic.data(), kPackageMagic.size()));
          }};
}

OutputKind pngOutput() {
  return {.name = "a PNG image",
          .isOwn = [](const std::string& p) { return fileStartsWith(p, "\x89PNG\r\n\x1a\n"); }};
}

OutputKind jsonOutput() {
  return {.name = "a JSON file", .isOwn = looksLikeJson};
}

OutputKind renderFolderOutput() {
  return {.name = "a folder of rendered frames",
          .directory = true,
          .isOwn = [](const std::string& folder) {
            return directoryHoldsOnly(folder, [](const std::string& name, bool isDirectory) {
              return !isDirectory && isRenderFile(name);
            });
          }};
}

OutputKind pngFolderOutput() {
  return {.name = "a folder of PNG images", .directory = true, .isOwn = [](const std::string& f) {
            return directoryHoldsOnly(f, [](const std::string& name, bool isDirectory) {
              return !isDirectory && fileExtension(name) == "png";
            });
          }};
}

Status claimIfGiven(const std::string& output, const OutputKind& kind,
                    const std::vector<std::string>& inputs) {
  if (output.empty()) return {};
  return claimOutput(output, kind, inputs);
}

}  // namespace lodforge::cli
