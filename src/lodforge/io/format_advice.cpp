#include "lodforge/io/format_advice.h"

#include <array>

#include "lodforge/core/file.h"

namespace lodforge {

namespace {

struct Advice {
  std::string_view extensions;  // space-separated, each surrounded by spaces
  std::string_view what;
  std::string_view how;
};

// Only tools that read the format: Debian's assimp reads none of these.
constexpr std::array<Advice, 7> kAdvice = {{
    {" wrl vrml ", "a VRML scene",
     "export it as .glb, .ply or .obj first, e.g. with MeshLab or Blender (File > Import > "
     "X3D/VRML)"},
    {" vtk vtp ", "a VTK mesh", "save it as .ply first, e.g. with ParaView (File > Save Data)"},
    {" usd usda usdc usdz ", "a USD scene",
     "export it as .glb first, e.g. with Blender (File > Export > glTF 2.0)"},
    {" pcd ", "a PCL point cloud",
     "save it as .ply or as text .xyz first, e.g. with `pcl_pcd2ply` or CloudCompare"},
    {" e57 ", "an E57 scan",
     "export it as .las or .ply first, e.g. with CloudCompare or `pdal translate IN.e57 OUT.las`"},
    {" ptx ", "a Leica PTX scan", "export it as .las or .ply first, e.g. with CloudCompare"},
    {" zip gz bz2 xz 7z tar ", "an archive", "unpack it first and give lodforge the file inside"},
}};

}  // namespace

Error unknownFormatError(const std::string& path, std::string_view reads) {
  const std::string ext = fileExtension(path);
  if (!ext.empty()) {
    const std::string key = " " + ext + " ";
    for (const Advice& a : kAdvice) {
      if (a.extensions.find(key) != std::string_view::npos)
        return {ErrorKind::kUsage,
                fmt::format("{}: {} (.{}), which lodforge does not read: {}; this command reads {}",
                            path, a.what, ext, a.how, reads)};
    }
  }
  return {ErrorKind::kUsage,
          fmt::format("{}: unknown format (this command reads {})", path, reads)};
}

}  // namespace lodforge
