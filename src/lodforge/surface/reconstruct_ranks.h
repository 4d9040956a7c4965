// `reconstruct` across the ranks of an MPI job (ReconstructOptions::acrossRanks,
// docs/distributed.md): rank 0 sorts the points into runs, the ranks estimate missing normals run
// by run and make the runs, each taken by the first rank free (claimInJob), into their pieces
// files; rank 0 joins every run's pieces in chunk order, the bytes one process writes.
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/surface/mesh_join.h"
#include "lodforge/surface/reconstruct.h"

namespace lodforge {

// Every rank calls it with the same input, work directory (on a file system every rank shares)
// and options; rank 0's sink gets the pieces. Every step's outcome is agreed between the ranks.
Result<ReconstructStats> reconstructAcrossRanks(const std::string& input,
                                                const std::string& workDirectory,
                                                const ReconstructOptions& options, PieceSink& sink);

}  // namespace lodforge
