// Where a tileset is written: what counts as a tileset of ours (which `lodforge tiles` may
// replace), and the staging and work directories beside it.
#pragma once

#include <string>

#include "lodforge/core/output_claim.h"

namespace lodforge {

// A directory is a lodforge tileset when its tileset.json names lodforge as `asset.generator`
// and it holds nothing but that file and GLB contents under tiles/ — so a tileset the user has
// put anything into is never replaced.
bool isLodforgeTileset(const std::string& directory);
OutputKind tilesetOutput();

// Claims `outputDirectory` for a tileset of `input` (nothing is written yet).
Status claimTilesetOutput(const std::string& input, const std::string& outputDirectory);

// Removes, under a staged tileset of a resumed run, the temporaries a killed run left (files
// that an OutputFile was writing: they would be renamed into the output with it). The work
// directory is locked, so no other run is writing them.
void removeOutputTemporaries(const std::string& stagingDirectory);

}  // namespace lodforge
