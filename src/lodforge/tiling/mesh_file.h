// A mesh on disk (large-meshes paper §3.4): a node's mesh saved once it is built and loaded back
// when its parent needs it, as a work file of `lodforge tiles` (`LFMESH4`: magic, seven counts,
// then each array of MeshPart as it is in memory). Read back checked: sizes against the counts,
// indices against the vertex count.
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiling/mesh_part.h"

namespace lodforge {

Status saveMesh(const MeshPart& mesh, const std::string& path);
// kBadInput naming `name` when a position or texture coordinate is not a finite number: what
// both work-file parsers check before the mesh goes on.
Status checkFinite(const MeshPart& mesh, const std::string& name);

Result<MeshPart> loadMesh(const std::string& path);
// The same from bytes in memory (`name` for messages): what loadMesh parses.
Result<MeshPart> parseMesh(std::span<const std::byte> bytes, const std::string& name);

}  // namespace lodforge
