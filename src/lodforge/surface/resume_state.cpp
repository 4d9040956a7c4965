#include "lodforge/surface/resume_state.h"

#include <algorithm>
#include <cassert>
#include <cstdio>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/progress.h"

namespace lodforge {

namespace {

// 2: the unit scale (lengths in the cloud's units); 3: the run budget the runs were cut with.
constexpr int kStateFormat = 3;

struct PieceHeader {
  std::uint64_t chunk = 0, vertices = 0, indices = 0, colors = 0;
};

template <class T>
bool readArray(std::FILE* file, std::vector<T>& values, std::uint64_t count) {
  values.resize(static_cast<std::size_t>(count));
  return std::fread(values.data(), sizeof(T), values.size(), file) == values.size();
}

// What the reconstruction relies on in a state read back (a damaged or edited file is not
// taken).
bool wellFormed(const ReconstructState& state) {
  const ChunkRuns& runs = state.runs;
  bool ok = state.layout.n > 0 && state.layout.grid.voxel > 0 && state.runBudget > 0 &&
            !runs.firstChunk.empty() && runs.firstChunk.front() == 0 &&
            runs.firstChunk.back() == runs.chunks.size() &&
            runs.points.size() == runs.chunks.size();
  for (std::size_t a = 0; a < 3; ++a)
    ok = ok && state.layout.chunks[a] > 0 && state.layout.grid.corners[a] > 0;
  for (std::size_t r = 1; ok && r < runs.firstChunk.size(); ++r)
    ok = runs.firstChunk[r] > runs.firstChunk[r - 1];
  for (std::size_t c = 0; ok && c < runs.chunks.size(); ++c)
    ok = runs.chunks[c] < state.layout.chunkCount() &&
         (c == 0 || runs.chunks[c] > runs.chunks[c - 1]);
  return ok;
}

}  // namespace

std::string reconstructStatePath(const std::string& workDirectory) {
  return workDirectory + "/reconstruct.json";
}

Status saveReconstructState(const std::string& path, const nlohmann::json& identity,
                            const ReconstructState& state) {
  const VoxelGrid& grid = state.layout.grid;
  const nlohmann::json json = {{"format", kStateFormat},
                               {"identity", identity},
                               {"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
                               {"voxel", grid.voxel},
                               {"corners", grid.corners},
                               {"chunkVoxels", state.layout.n},
                               {"chunks", state.layout.chunks},
                               {"runChunks", state.runs.chunks},
                               {"runPoints", state.runs.points},
                               {"firstChunk", state.runs.firstChunk},
                               {"runBudget", state.runBudget},
                               {"points", state.points},
                               {"hasColors", state.hasColors},
                               {"estimatedNormals", state.estimatedNormals},
                               {"unitScale", state.unitScale}};
  // (A path that is not UTF-8 is kept with its bad bytes replaced: it then resumes nothing.)
  return OutputFile::writeWhole(
      path, json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

std::optional<ReconstructState> loadReconstructState(const std::string& path,
                                                     const nlohmann::json& identity) {
  Result<std::string> text = readFileToString(path, std::uint64_t{1} << 30);
  if (!text) return std::nullopt;
  try {
    const nlohmann::json json = nlohmann::json::parse(*text);
    if (json.at("format") != kStateFormat || json.at("identity") != identity) return std::nullopt;
    ReconstructState state;
    const auto& origin = json.at("origin");
    state.layout.grid.origin = {origin.at(0).get<double>(), origin.at(1).get<double>(),
                                origin.at(2).get<double>()};
    state.layout.grid.voxel = json.at("voxel").get<double>();
    state.layout.grid.corners = json.at("corners").get<std::array<std::uint64_t, 3>>();
    state.layout.n = json.at("chunkVoxels").get<std::uint32_t>();
    state.layout.chunks = json.at("chunks").get<std::array<std::uint64_t, 3>>();
    state.runs.chunks = json.at("runChunks").get<std::vector<std::uint64_t>>();
    state.runs.points = json.at("runPoints").get<std::vector<std::uint64_t>>();
    state.runs.firstChunk = json.at("firstChunk").get<std::vector<std::size_t>>();
    state.runBudget = json.at("runBudget").get<std::uint64_t>();
    state.points = json.at("points").get<std::uint64_t>();
    state.hasColors = json.at("hasColors").get<bool>();
    state.estimatedNormals = json.at("estimatedNormals").get<bool>();
    state.unitScale = json.at("unitScale").get<double>();
    return wellFormed(state) ? std::optional(std::move(state)) : std::nullopt;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

std::string piecesPath(const std::string& workDirectory, std::size_t run) {
  return fmt::format("{}/run-{}.pieces", workDirectory, run);
}

Result<PieceWriter> PieceWriter::create(const std::string& path) {
  Result<OutputFile> file = OutputFile::create(path, 1 << 20);
  if (!file) return file.status();
  return PieceWriter(std::move(*file));
}

Status PieceWriter::add(std::uint64_t chunk, const SurfacePiece& piece) {
  // The header gives one count for every per-vertex array.
  assert(piece.normals.size() == piece.positions.size() &&
         piece.edges.size() == piece.positions.size());
  assert(piece.colors.empty() || piece.colors.size() == piece.positions.size());
  assert(piece.indices.size() % 3 == 0);
  const PieceHeader header{chunk, piece.positions.size(), piece.indices.size(),
                           piece.colors.empty() ? 0u : 1u};
  LODFORGE_TRY(file_.write(&header, sizeof header));
  LODFORGE_TRY(file_.writeSpan(std::span<const Vec3d>(piece.positions)));
  LODFORGE_TRY(file_.writeSpan(std::span<const Vec3f>(piece.normals)));
  LODFORGE_TRY(file_.writeSpan(std::span<const Rgba8>(piece.colors)));
  LODFORGE_TRY(file_.writeSpan(std::span<const std::uint64_t>(piece.edges)));
  return file_.writeSpan(std::span<const std::uint32_t>(piece.indices));
}

Status replayPieces(const std::string& path, PieceSink& sink) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return ioErrorFromErrno(path, "open");
  Status status;
  SurfacePiece piece;
  Result<std::uint64_t> bytes = fileSize(path);
  std::uint64_t left = bytes ? *bytes : 0;
  for (PieceHeader header; status.ok() && std::fread(&header, sizeof header, 1, file) == 1;) {
    // The counts fit the bytes left (a damaged header allocates nothing), the indices their
    // vertices.
    constexpr std::uint64_t kVertexBytes = sizeof(Vec3d) + sizeof(Vec3f) + sizeof(std::uint64_t);
    left = left >= sizeof header ? left - sizeof header : 0;
    const bool fits =
        header.vertices <= left / kVertexBytes && header.indices <= left / 4 &&
        header.vertices * (kVertexBytes + (header.colors ? 4 : 0)) + header.indices * 4 <= left;
    if (fits)
      left -= header.vertices * (kVertexBytes + (header.colors ? 4 : 0)) + header.indices * 4;
    const bool whole = fits && readArray(file, piece.positions, header.vertices) &&
                       readArray(file, piece.normals, header.vertices) &&
                       readArray(file, piece.colors, header.colors ? header.vertices : 0) &&
                       readArray(file, piece.edges, header.vertices) &&
                       readArray(file, piece.indices, header.indices) &&
                       std::all_of(piece.indices.begin(), piece.indices.end(),
                                   [&](std::uint32_t i) { return i < header.vertices; });
    status = whole ? sink.add(header.chunk, piece)
                   : Error{ErrorKind::kIo, fmt::format("{}: damaged (delete the work directory "
                                                       "and start again)",
                                                       path)};
    if (status.ok()) status = checkCancelled();
  }
  if (status.ok() && std::ferror(file)) status = ioError(path, "read failed");
  std::fclose(file);
  return status;
}

}  // namespace lodforge
