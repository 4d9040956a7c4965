// What `lodforge serve` decides about a request path: where it leads inside a root (or why it
// may not), the content type of a file, and where the viewers were built.
#pragma once

#include <filesystem>
#include <string>

namespace lodforge::cli {

struct ResolvedPath {
  int status = 404;  // 200 with `path`, 403 outside the root, 404 missing
  std::filesystem::path path;
};

// `relative` is the decoded request path below the route. Refused (403): "..", a NUL or a
// backslash in it, an absolute path, and any path whose real location (symlinks followed) lies
// outside `root`. Missing files and directories are 404.
ResolvedPath resolveInside(const std::filesystem::path& root, const std::string& relative);

// By extension: json, glb, gltf, bin, js/mjs, wasm, css, html, png, jpg, svg, txt; else
// application/octet-stream.
std::string contentTypeFor(const std::string& path);

// The built viewers: "web" beside the binary (installed), else the source tree's web/dist (set
// at configure time); empty when neither holds an index.
std::filesystem::path findWebDirectory();

}  // namespace lodforge::cli
