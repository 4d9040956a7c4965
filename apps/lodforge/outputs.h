// The outputs of the subcommands that write files, as kinds the output claim recognises (see
// lodforge/core/output_claim.h): each replaces only an earlier file of its own kind.
#pragma once

#include <string>
#include <vector>

#include "lodforge/core/output_claim.h"

namespace lodforge::cli {

// A model file of the kind its extension names (.ply .glb .gltf .obj .stl, and .las for
// convert's point copies), by its content.
OutputKind modelFileOutput(const std::string& path);
OutputKind packageOutput();  // .lfp, by its magic
OutputKind pngOutput();      // by the PNG signature
OutputKind jsonOutput();     // a JSON object or array
// A folder of frame_NNNN.png and render.json.
OutputKind renderFolderOutput();
// A folder of PNG images only (compare's heat maps of two folders).
OutputKind pngFolderOutput();

// An optional side output (--json, --screenshot, --record-path): claimed when given.
Status claimIfGiven(const std::string& output, const OutputKind& kind,
                    const std::vector<std::string>& inputs);

}  // namespace lodforge::cli
