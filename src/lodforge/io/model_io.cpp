#include "lodforge/io/model_io.h"

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/io/format_advice.h"
#include "lodforge/io/mesh/assimp_reader.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "lodforge/io/mesh/obj_writer.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/io/mesh/stl_reader.h"
#include "lodforge/io/mesh/stl_writer.h"
#include "lodforge/io/part21.h"

namespace lodforge {

FileFormat formatFromPath(const std::string& path) {
  const std::string ext = fileExtension(path);
  if (ext == "ply") return FileFormat::kPly;
  if (ext == "obj") return FileFormat::kObj;
  if (ext == "stl") return FileFormat::kStl;
  if (ext == "gltf") return FileFormat::kGltf;
  if (ext == "glb") return FileFormat::kGlb;
  if (isCadPath(path)) return FileFormat::kCad;
  if (isAssimpExtension(ext)) return FileFormat::kAssimp;
  return FileFormat::kUnknown;
}

std::string_view formatName(FileFormat format) {
  switch (format) {
    case FileFormat::kPly:
      return "PLY";
    case FileFormat::kObj:
      return "OBJ";
    case FileFormat::kStl:
      return "STL";
    case FileFormat::kGltf:
      return "glTF";
    case FileFormat::kGlb:
      return "GLB";
    case FileFormat::kCad:
      return "CAD (STEP, IGES, BREP)";
    case FileFormat::kAssimp:
      return "interchange scene (assimp)";
    case FileFormat::kUnknown:
      break;
  }
  return "unknown";
}

bool canRead(FileFormat format) {
  return format != FileFormat::kUnknown;
}
bool canWrite(FileFormat format) {
  return format == FileFormat::kPly || format == FileFormat::kGlb || format == FileFormat::kObj ||
         format == FileFormat::kStl;
}

Result<Model> readModel(const std::string& path, const ReadOptions& options) {
  switch (formatFromPath(path)) {
    case FileFormat::kPly: {
      PlyReadOptions ply;
      ply.salvageTruncated = options.salvageTruncated;
      ply.warnings = options.warnings;
      return readPly(path, ply);
    }
    case FileFormat::kObj:
      return readObj(path, options.warnings);
    case FileFormat::kStl:
      return readStl(path);
    case FileFormat::kGltf:
    case FileFormat::kGlb:
      return readGltf(path, {.warnings = options.warnings});
    case FileFormat::kCad: {
      CadReadOptions cad = options.cad;
      cad.salvageTruncated = cad.salvageTruncated || options.salvageTruncated;
      return readCad(path, cad, options.warnings);
    }
    case FileFormat::kAssimp:
      // IFC is an ISO 10303-21 exchange structure, whose end assimp does not check.
      if (fileExtension(path) == "ifc")
        LODFORGE_TRY(checkPart21Whole(path, options.salvageTruncated, options.warnings));
      return readAssimp(path, options.warnings);
    case FileFormat::kUnknown:
      break;
  }
  return unknownFormatError(path, kMeshFormats);
}

Status writeModel(const Model& model, const std::string& path) {
  switch (formatFromPath(path)) {
    case FileFormat::kPly:
      return writePly(model, path);
    case FileFormat::kGlb:
      return writeGlb(model, path);
    case FileFormat::kObj:
      return writeObj(model, path);
    case FileFormat::kStl:
      return writeStl(model, path);
    default:
      break;
  }
  return Error{
      ErrorKind::kUsage,
      fmt::format("{}: cannot write this format (lodforge writes .ply .glb .obj .stl)", path)};
}

}  // namespace lodforge
