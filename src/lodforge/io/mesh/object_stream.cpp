#include "lodforge/io/mesh/object_stream.h"

#include <algorithm>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "lodforge/io/mesh/ply_reader.h"

namespace lodforge {

namespace {

class ModelStream final : public ObjectStream {
 public:
  explicit ModelStream(Model model) : model_(std::move(model)) {}

  Result<bool> next(SourceObject& out) override {
    if (next_ >= model_.objectCount()) return false;
    const std::size_t o = next_++;
    const ObjectRecord& r = model_.objects[o];
    out.name = std::string(model_.objectName(o));
    out.path = std::string(model_.objectPath(o));
    out.material = r.material;
    out.layer = r.layer;  // the readers keep it kNoLayer or inside the table
    const auto positions = model_.objectPositions(o);
    out.positions.assign(positions.begin(), positions.end());
    out.normals.clear();
    out.colors.clear();
    out.uvs.clear();
    const bool textured = model_.hasUvs() && r.material != kNoMaterial &&
                          model_.materials[r.material].baseColorImage != kNoImage;
    if (textured)
      out.uvs.assign(
          model_.uvs.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset),
          model_.uvs.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset + r.vertexCount));
    if (model_.hasNormals())
      out.normals.assign(
          model_.normals.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset),
          model_.normals.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset + r.vertexCount));
    if (model_.hasColors())
      out.colors.assign(
          model_.colors.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset),
          model_.colors.begin() + static_cast<std::ptrdiff_t>(r.vertexOffset + r.vertexCount));
    const auto indices = model_.objectIndices(o);
    out.indices.assign(indices.begin(), indices.end());
    return true;
  }
  Vec3d origin() const override { return model_.origin; }
  bool hasNormals() const override { return model_.hasNormals(); }
  bool hasColors() const override { return model_.hasColors(); }
  bool streaming() const override { return false; }
  std::uint64_t triangleCountHint() const override { return model_.triangleCount(); }
  std::span<const Material> materials() const override { return model_.materials; }
  std::span<const std::string> layers() const override { return model_.layers; }
  std::span<const ImageSource> images() const override { return model_.images; }

 private:
  Model model_;
  std::size_t next_ = 0;
};

// Two readers over one file: `vertices_` walks the vertex section, `faces_` the face section.
class GroupedPlyStream final : public ObjectStream {
 public:
  static Result<std::unique_ptr<ObjectStream>> open(const std::string& path,
                                                    const ReadOptions& read) {
    PlyReadOptions vertexOptions, faceOptions;
    vertexOptions.readFaces = false;
    faceOptions.readVertices = false;
    vertexOptions.salvageTruncated = faceOptions.salvageTruncated = read.salvageTruncated;
    Result<PlyReader> vertices = PlyReader::open(path, vertexOptions);
    if (!vertices) return vertices.status();
    Result<PlyReader> faces = PlyReader::open(path, faceOptions);
    if (!faces) return faces.status();
    std::optional<std::string> unread = unreadPlyElements(vertices->header(), path);
    if (unread && read.warnings != nullptr) read.warnings->push_back(std::move(*unread));
    auto stream = std::unique_ptr<GroupedPlyStream>(
        new GroupedPlyStream(path, std::move(vertices.value()), std::move(faces.value())));
    LODFORGE_TRY(stream->readVertices());  // the first batch decides the origin
    return std::unique_ptr<ObjectStream>(std::move(stream));
  }

  Result<bool> next(SourceObject& out) override {
    if (!ensureFaces()) return error_;
    if (facePos_ >= faceIds_.size()) return false;
    const std::uint32_t id = faceIds_[facePos_];
    if (started_ && id <= lastId_)
      return notGrouped(fmt::format("faces of object {} come after object {}", id, lastId_));
    started_ = true;
    lastId_ = id;
    // The object's triangles: the run of faces with this id, across face batches.
    triangles_.clear();
    while (true) {
      while (facePos_ < faceIds_.size() && faceIds_[facePos_] == id) {
        triangles_.insert(triangles_.end(),
                          faceTriangles_.begin() + static_cast<std::ptrdiff_t>(3 * facePos_),
                          faceTriangles_.begin() + static_cast<std::ptrdiff_t>(3 * facePos_ + 3));
        ++facePos_;
      }
      if (facePos_ < faceIds_.size()) break;
      if (!ensureFaces()) return error_;
      if (facePos_ >= faceIds_.size()) break;  // no more faces
    }
    const auto [low, high] = std::minmax_element(triangles_.begin(), triangles_.end());
    const std::uint64_t first = *low, last = *high;
    if (first < vertexStart_)
      return notGrouped(
          fmt::format("object {} uses vertex {} that an earlier object used", id, first));
    while (vertexStart_ + positions_.size() <= last) {
      if (!vertices_.next(batch_).ok() || batch_.positions.empty()) {
        return Error{
            ErrorKind::kBadInput,
            fmt::format("{}: object {} uses vertex {} beyond the vertices read", path_, id, last)};
      }
      LODFORGE_TRY(appendVertexBatch());
    }
    const std::size_t from = first - vertexStart_, to = last - vertexStart_ + 1;
    out.name = fmt::format("object {}", id);
    out.positions.assign(positions_.begin() + static_cast<std::ptrdiff_t>(from),
                         positions_.begin() + static_cast<std::ptrdiff_t>(to));
    out.normals.clear();
    out.colors.clear();
    out.uvs.clear();
    if (!normals_.empty())
      out.normals.assign(normals_.begin() + static_cast<std::ptrdiff_t>(from),
                         normals_.begin() + static_cast<std::ptrdiff_t>(to));
    if (!colors_.empty())
      out.colors.assign(colors_.begin() + static_cast<std::ptrdiff_t>(from),
                        colors_.begin() + static_cast<std::ptrdiff_t>(to));
    out.indices.resize(triangles_.size());
    for (std::size_t i = 0; i < triangles_.size(); ++i)
      out.indices[i] = static_cast<std::uint32_t>(triangles_[i] - first);
    dropVerticesBefore(last + 1);
    return true;
  }

  Vec3d origin() const override { return origin_; }
  bool hasNormals() const override { return header().hasNormals; }
  bool hasColors() const override { return header().hasColors; }
  bool streaming() const override { return true; }
  std::uint64_t triangleCountHint() const override { return header().faceCount; }

 private:
  GroupedPlyStream(std::string path, PlyReader vertices, PlyReader faces)
      : path_(std::move(path)), vertices_(std::move(vertices)), faces_(std::move(faces)) {}
  const PlyHeader& header() const { return vertices_.header(); }

  Error notGrouped(const std::string& what) const {
    return {ErrorKind::kUnsupported,
            fmt::format("{}: faces are not grouped by object ({}); it cannot be streamed", path_,
                        what)};
  }

  Status readVertices() {
    Result<bool> more = vertices_.next(batch_);
    if (!more) return more.status();
    if (*more && !batch_.positions.empty()) {
      Aabbd first;
      first.add(batch_.positions.front());
      origin_ = chooseOrigin(first);
      return appendVertexBatch();
    }
    return {};
  }
  Status appendVertexBatch() {
    for (const Vec3d& p : batch_.positions) positions_.push_back(toFloat(p - origin_));
    normals_.insert(normals_.end(), batch_.normals.begin(), batch_.normals.end());
    colors_.insert(colors_.end(), batch_.colors.begin(), batch_.colors.end());
    return {};
  }
  void dropVerticesBefore(std::uint64_t index) {
    const std::size_t drop =
        static_cast<std::size_t>(std::min<std::uint64_t>(index - vertexStart_, positions_.size()));
    positions_.erase(positions_.begin(), positions_.begin() + static_cast<std::ptrdiff_t>(drop));
    if (!normals_.empty())
      normals_.erase(normals_.begin(), normals_.begin() + static_cast<std::ptrdiff_t>(drop));
    if (!colors_.empty())
      colors_.erase(colors_.begin(), colors_.begin() + static_cast<std::ptrdiff_t>(drop));
    vertexStart_ += drop;
  }
  // Makes faces available at facePos_ (keeping none that were consumed); false on error.
  bool ensureFaces() {
    if (facePos_ < faceIds_.size() || facesDone_) return true;
    faceIds_.clear();
    faceTriangles_.clear();
    facePos_ = 0;
    while (faceIds_.empty()) {
      Result<bool> more = faces_.next(faceBatch_);
      if (!more) {
        error_ = more.error();
        return false;
      }
      if (!*more) {
        facesDone_ = true;
        return true;
      }
      faceIds_ = faceBatch_.triangleObjects;
      faceTriangles_ = faceBatch_.triangles;
    }
    return true;
  }

  std::string path_;
  PlyReader vertices_, faces_;
  PlyBatch batch_, faceBatch_;
  Vec3d origin_;
  std::vector<Vec3f> positions_, normals_;
  std::vector<Rgba8> colors_;
  std::uint64_t vertexStart_ = 0;  // global index of positions_[0]
  std::vector<std::uint32_t> faceIds_, faceTriangles_;
  std::size_t facePos_ = 0;
  bool facesDone_ = false;
  std::vector<std::uint32_t> triangles_;
  std::uint32_t lastId_ = 0;
  bool started_ = false;
  Error error_;
};

}  // namespace

Result<std::unique_ptr<ObjectStream>> openObjectStream(const std::string& path,
                                                       const ObjectStreamOptions& options) {
  if (!options.load && formatFromPath(path) == FileFormat::kPly) {
    Result<PlyReader> probe = PlyReader::open(path);
    if (!probe) return probe.status();
    // A textured PLY is read whole (its images and per-corner coordinates come with the model).
    const PlyHeader& header = probe->header();
    const bool textured = header.hasUvs || header.hasFaceUvs || !header.textureFiles.empty();
    if (header.hasObjectIds && !textured) return GroupedPlyStream::open(path, options.read);
  }
  Result<Model> model = readModel(path, options.read);
  if (!model) return model.status();
  return std::unique_ptr<ObjectStream>(new ModelStream(std::move(model.value())));
}

}  // namespace lodforge
