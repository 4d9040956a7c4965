#include "lodforge/io/points/point_reader.h"

#include <optional>
#include <string>
#include <variant>

#include "lodforge/core/file.h"
#include "lodforge/io/format_advice.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/points/las_reader.h"
#include "lodforge/io/points/xyz_reader.h"

namespace lodforge {

bool isPointCloudPath(const std::string& path) {
  const std::string ext = fileExtension(path);
  return ext == "las" || ext == "laz" || ext == "xyz" || ext == "txt" || ext == "csv" ||
         ext == "pts";
}

struct PointReader::State {
  std::variant<LasReader, PlyReader, XyzReader> reader;
  PointCloudInfo info;
  PlyBatch plyBatch;
};

PointReader::PointReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
PointReader::PointReader(PointReader&&) noexcept = default;
PointReader& PointReader::operator=(PointReader&&) noexcept = default;
PointReader::~PointReader() = default;

const PointCloudInfo& PointReader::info() const {
  return state_->info;
}

std::optional<std::string> PointReader::truncation() const {
  if (const auto* ply = std::get_if<PlyReader>(&state_->reader)) return ply->truncation();
  return std::nullopt;
}

namespace {

bool sliced(const PointReadOptions& options) {
  return options.first != 0 || options.count != ~std::uint64_t{0};
}

}  // namespace

Result<PointReader> PointReader::open(const std::string& path, const PointReadOptions& options) {
  const std::string ext = fileExtension(path);
  if (ext == "las" || ext == "laz") {
    Result<LasReader> las = LasReader::open(path, options.batchPoints);
    if (las && !options.readExtras) las->skipExtraBytes();
    if (las && sliced(options)) LODFORGE_TRY(las->restrictTo(options.first, options.count));
    if (!las) return las.status();
    const LasHeader& h = las->header();
    PointCloudInfo info;
    info.format = fmt::format("{} {}.{}, point format {}",
                              h.copc         ? "COPC"
                              : h.compressed ? "LAZ"
                                             : "LAS",
                              h.versionMajor, h.versionMinor, h.pointFormat);
    info.count = h.pointCount;
    info.bounds = h.bounds;
    info.crs = h.crs;
    info.grid = PointCloudInfo::Grid{{h.scale[0], h.scale[1], h.scale[2]},
                                     {h.offset[0], h.offset[1], h.offset[2]}};
    info.hasColors = h.hasColors;
    info.attributes = h.attributes;
    info.extras = h.extras;
    if (!info.extras.fields.empty()) info.attributes |= kAttrExtras;
    if (!h.extrasIgnored.empty()) info.warnings.push_back(h.extrasIgnored);
    return PointReader(std::make_unique<State>(State{std::move(*las), std::move(info), {}}));
  }
  if (ext == "ply") {
    Result<PlyReader> ply = PlyReader::open(path, {.batchSize = options.batchPoints,
                                                   .salvageTruncated = options.salvageTruncated,
                                                   .readFaces = false,
                                                   .vertexSlice = {options.first, options.count},
                                                   .readExtras = options.readExtras});
    if (!ply) return ply.status();
    const PlyHeader& h = ply->header();
    PointCloudInfo info;
    info.format = fmt::format("PLY {}", plyFormatName(h.format));
    info.count = h.vertexCount;
    info.hasNormals = h.hasNormals;
    info.hasColors = h.hasColors;
    info.extras = h.extras;
    if (!info.extras.fields.empty()) info.attributes |= kAttrExtras;
    if (std::optional<std::string> unread = unreadPlyElements(h, path))
      info.warnings.push_back(std::move(*unread));
    return PointReader(std::make_unique<State>(State{std::move(*ply), std::move(info), {}}));
  }
  if (isPointCloudPath(path)) {
    if (sliced(options))
      return Error{ErrorKind::kUnsupported,
                   fmt::format("{}: a text point file is not read in slices", path)};
    Result<XyzReader> xyz = XyzReader::open(path, options.batchPoints);
    if (!xyz) return xyz.status();
    const XyzLayout& layout = xyz->layout();
    PointCloudInfo info;
    info.format = fmt::format(
        "text, {} columns separated by {}", layout.columns,
        layout.separator == ' ' ? std::string("spaces") : fmt::format("'{}'", layout.separator));
    info.hasNormals = layout.normal >= 0;
    info.hasColors = layout.red >= 0;
    return PointReader(std::make_unique<State>(State{std::move(*xyz), std::move(info), {}}));
  }
  return unknownFormatError(path, kPointFormats);
}

Result<bool> PointReader::next(PointBatch& batch) {
  State& s = *state_;
  if (auto* las = std::get_if<LasReader>(&s.reader)) return las->next(batch);
  if (auto* xyz = std::get_if<XyzReader>(&s.reader)) return xyz->next(batch);
  // PLY: vertex batches only (faces are skipped by the reader's options).
  PlyReader& ply = std::get<PlyReader>(s.reader);
  batch.clear();
  while (true) {
    Result<bool> more = ply.next(s.plyBatch);
    if (!more || !*more) return more;
    if (s.plyBatch.kind != PlyBatch::Kind::kVertices) continue;
    batch.first = s.plyBatch.first;
    batch.positions = std::move(s.plyBatch.positions);
    batch.normals = std::move(s.plyBatch.normals);
    batch.colors = std::move(s.plyBatch.colors);
    batch.extras = std::move(s.plyBatch.extras);
    return true;
  }
}

}  // namespace lodforge
