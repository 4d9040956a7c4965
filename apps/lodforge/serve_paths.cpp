#include "serve_paths.h"

#include <unistd.h>

#include <array>
#include <system_error>

#include "lodforge/core/file.h"

namespace lodforge::cli {

namespace fs = std::filesystem;

ResolvedPath resolveInside(const fs::path& root, const std::string& relative) {
  ResolvedPath out;
  if (relative.find('\0') != std::string::npos || relative.find('\\') != std::string::npos ||
      relative.starts_with('/')) {
    out.status = 403;
    return out;
  }
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t end = std::min(relative.find('/', start), relative.size());
    if (relative.compare(start, end - start, "..") == 0 && end - start == 2) {
      out.status = 403;
      return out;
    }
    start = end + 1;
  }
  std::error_code error;
  const fs::path realRoot = fs::canonical(root, error);
  if (error) return out;
  const fs::path real = fs::canonical(realRoot / relative, error);
  if (error) return out;  // missing (or a dangling link)
  // Symlinks are followed: the real location must still be inside.
  const auto [rootEnd, realIt] =
      std::mismatch(realRoot.begin(), realRoot.end(), real.begin(), real.end());
  if (rootEnd != realRoot.end()) {
    out.status = 403;
    return out;
  }
  (void)realIt;
  if (!fs::is_regular_file(real, error)) return out;
  out.status = 200;
  out.path = real;
  return out;
}

std::string contentTypeFor(const std::string& path) {
  static const std::array<std::pair<const char*, const char*>, 14> kTypes = {{
      {"json", "application/json"},
      {"glb", "model/gltf-binary"},
      {"gltf", "model/gltf+json"},
      {"bin", "application/octet-stream"},
      {"js", "text/javascript"},
      {"mjs", "text/javascript"},
      {"wasm", "application/wasm"},
      {"css", "text/css"},
      {"html", "text/html; charset=utf-8"},
      {"png", "image/png"},
      {"jpg", "image/jpeg"},
      {"svg", "image/svg+xml"},
      {"txt", "text/plain; charset=utf-8"},
      {"xml", "application/xml"},
  }};
  const std::string ext = fileExtension(path);
  for (const auto& [e, type] : kTypes)
    if (ext == e) return type;
  return "application/octet-stream";
}

fs::path findWebDirectory() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path beside = exe.parent_path() / "web";
    if (fs::exists(beside / "cesium" / "index.html", error)) return beside;
  }
#ifdef LODFORGE_WEB_DIR
  const fs::path built = LODFORGE_WEB_DIR;
  if (fs::exists(built / "cesium" / "index.html", error)) return built;
#endif
  return {};
}

}  // namespace lodforge::cli
