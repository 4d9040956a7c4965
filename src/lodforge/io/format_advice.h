// What to tell a user whose file lodforge cannot read: the formats the command reads, and for a
// format we know but do not read, what it is and how to bring it in.
#pragma once

#include <string>
#include <string_view>

#include "lodforge/core/status.h"

namespace lodforge {

// What each kind of command reads, for the message.
inline constexpr std::string_view kMeshFormats =
    ".ply .obj .stl .gltf .glb meshes, .step .stp .iges .igs .brep CAD models and .off .fbx .dae "
    ".3ds .3mf .ifc .x3d (assimp) scenes";
inline constexpr std::string_view kPointFormats = ".las .laz .ply .xyz .txt .csv .pts point clouds";

// A usage error (exit 2): "PATH: unknown format (this command reads READS)", or for a known
// extension "PATH: a STEP CAD model, which lodforge does not read yet: ADVICE".
Error unknownFormatError(const std::string& path, std::string_view reads);

}  // namespace lodforge
