// Reading and writing whole models by file name: the format comes from the extension (and, for
// glTF, the content). One entry point for the command line and the tests.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"
#include "lodforge/io/cad/cad_reader.h"

namespace lodforge {

// kCad: STEP, IGES or BREP, read through OpenCASCADE (io/cad/cad_reader.h); kAssimp: OFF, FBX,
// Collada, 3DS, IFC and the other scenes assimp reads (io/mesh/assimp_reader.h). Neither is
// written.
enum class FileFormat : std::uint8_t { kUnknown, kPly, kObj, kStl, kGltf, kGlb, kCad, kAssimp };

FileFormat formatFromPath(const std::string& path);
std::string_view formatName(FileFormat format);
bool canRead(FileFormat format);
bool canWrite(FileFormat format);

struct ReadOptions {
  // Keep what a truncated PLY, STEP or IFC holds up to the cut instead of refusing it (adds a
  // warning).
  bool salvageTruncated = false;
  std::vector<std::string>* warnings = nullptr;
  CadReadOptions cad;  // tessellation of CAD files
};

Result<Model> readModel(const std::string& path, const ReadOptions& options = {});
// PLY, GLB, OBJ and STL; .gltf is read but not written (GLB carries the same in one file).
Status writeModel(const Model& model, const std::string& path);

}  // namespace lodforge
