#include "lodforge/io/cad/cad_writer.h"

#include <cstdio>
#include <filesystem>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/cad/cad_reader.h"

namespace lodforge {

Status writeStepAssembly(cad::WriteRequest request) {
  void* entry = nullptr;
  LODFORGE_TRY(cadModuleSymbol(cad::kWriteSymbol, entry));
  const auto write = reinterpret_cast<cad::WriteFunction>(entry);
  const std::string path = request.path;
  request.path = temporaryPathFor(path);
  request.cancelled = [] { return cancelRequested(); };
  cad::WriteResult result;
  write(cad::kModuleVersion, request, result);
  std::error_code error;
  if (result.status != 0) {
    std::filesystem::remove(request.path, error);
    if (result.status == 3) return Error{ErrorKind::kCancelled, "cancelled"};
    return Error{ErrorKind::kIo, fmt::format("{}: {}", path, result.error)};
  }
  std::filesystem::rename(request.path, path, error);
  if (error) {
    std::filesystem::remove(request.path, error);
    return ioError(path, "cannot rename the finished file into place");
  }
  return {};
}

}  // namespace lodforge
