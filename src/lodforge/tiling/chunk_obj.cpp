#include "lodforge/tiling/chunk_obj.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/obj_materials.h"
#include "lodforge/tiling/chunk_sizing.h"
#include "lodforge/tiling/vertex_cache.h"

namespace lodforge {
namespace {

constexpr std::size_t kReadBlock = std::size_t{4} << 20;
constexpr std::uint32_t kNoIndex = ~0u;

// The words of a line, split at spaces and tabs (a '#' starts a comment), into `words`.
std::size_t splitWords(std::string_view line, std::vector<std::string_view>& words) {
  words.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size() || line[i] == '#') break;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    words.push_back(line.substr(start, i - start));
  }
  return words.size();
}

// Twice the signed area of 2D triangle abc.
double cross2(const std::array<double, 2>& a, const std::array<double, 2>& b,
              const std::array<double, 2>& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

bool insideTriangle(const std::array<double, 2>& p, const std::array<double, 2>& a,
                    const std::array<double, 2>& b, const std::array<double, 2>& c) {
  return cross2(a, b, p) > 0 && cross2(b, c, p) > 0 && cross2(c, a, p) > 0;
}

// A polygon's triangles as triples of its corner numbers: a fan where it is convex, ear clipping
// in its plane where it is not (a fan would cover what the polygon leaves out).
void triangulatePolygon(std::span<const Vec3d> points, std::vector<std::uint32_t>& out) {
  out.clear();
  const std::size_t n = points.size();
  // Newell's normal; the polygon projected on the plane of its two other axes, counter-clockwise.
  Vec3d normal{};
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3d& a = points[k];
    const Vec3d& b = points[(k + 1) % n];
    normal = normal +
             Vec3d{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
  }
  const int drop =
      std::abs(normal.x) >= std::abs(normal.y) && std::abs(normal.x) >= std::abs(normal.z) ? 0
      : std::abs(normal.y) >= std::abs(normal.z)                                           ? 1
                                                                                           : 2;
  const double sign = normal[drop] >= 0 ? 1 : -1;
  std::vector<std::array<double, 2>> p(n);
  for (std::size_t k = 0; k < n; ++k)
    p[k] = {points[k][(drop + 1) % 3], sign * points[k][(drop + 2) % 3]};
  bool convex = true;
  for (std::size_t k = 0; k < n && convex; ++k)
    convex = cross2(p[k], p[(k + 1) % n], p[(k + 2) % n]) >= 0;
  std::vector<std::uint32_t> left(n);
  for (std::size_t k = 0; k < n; ++k) left[k] = static_cast<std::uint32_t>(k);
  while (!convex && left.size() > 3) {
    bool clipped = false;
    for (std::size_t i = 0; i < left.size() && !clipped; ++i) {
      const std::uint32_t a = left[(i + left.size() - 1) % left.size()], b = left[i],
                          c = left[(i + 1) % left.size()];
      if (cross2(p[a], p[b], p[c]) <= 0) continue;  // a reflex corner is no ear
      bool empty = true;
      for (std::uint32_t q : left)
        if (q != a && q != b && q != c && insideTriangle(p[q], p[a], p[b], p[c])) empty = false;
      if (!empty) continue;
      out.insert(out.end(), {a, b, c});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) break;  // degenerate (self-touching, collinear): the rest as a fan
  }
  for (std::size_t k = 1; k + 1 < left.size(); ++k)
    out.insert(out.end(), {left[0], left[k], left[k + 1]});
}

// Calls fn(line number, line) for every line of the file, reading it in blocks (a line is never
// longer than a block); progress in bytes.
template <class Fn>
Status forEachObjLine(const std::string& path, const std::string& label, Fn&& fn) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ioErrorFromErrno(path, "open");
  Result<std::uint64_t> size = fileSize(path);
  Progress progress(label, size ? *size : 0, Progress::Unit::kBytes);
  std::vector<char> buffer(kReadBlock);
  std::size_t kept = 0;
  std::uint64_t lineNumber = 0;
  Status status;
  while (status.ok()) {
    const ssize_t got = ::read(fd, buffer.data() + kept, buffer.size() - kept);
    if (got < 0) {
      status = ioErrorFromErrno(path, "read");
      break;
    }
    const std::size_t end = kept + static_cast<std::size_t>(got);
    std::size_t start = 0;
    for (std::size_t i = 0; i < end && status.ok(); ++i) {
      if (buffer[i] != '\n') continue;
      status = fn(++lineNumber, std::string_view(buffer.data() + start, i - start));
      start = i + 1;
    }
    if (!status.ok()) break;
    if (got == 0) {
      if (start < end)
        status = fn(++lineNumber, std::string_view(buffer.data() + start, end - start));
      break;
    }
    if (start == 0 && end == buffer.size()) {
      status = badInput(
          path, fmt::format("line {}: longer than {} MiB", lineNumber + 1, kReadBlock >> 20));
      break;
    }
    std::memmove(buffer.data(), buffer.data() + start, end - start);
    kept = end - start;
    progress.advance(static_cast<std::uint64_t>(got));
    if (Status cancelled = checkCancelled(); !cancelled.ok()) status = cancelled;
  }
  ::close(fd);
  if (status.ok()) progress.finish();
  return status;
}

bool parseNumber(std::string_view word, double& out) {
  const char* first = word.data();
  if (!word.empty() && word[0] == '+') ++first;
  const auto [end, error] = std::from_chars(first, word.data() + word.size(), out);
  return error == std::errc() && end == word.data() + word.size() && std::isfinite(out);
}

// One corner of a face: its position, texture coordinate and normal (kNoIndex: none), 0-based.
struct ObjCorner {
  std::uint32_t v = kNoIndex, vt = kNoIndex, vn = kNoIndex;
};

// How many of each record the file has so far: what negative indices count back from.
struct ObjCounts {
  std::uint64_t v = 0, vt = 0, vn = 0;
};

// "v", "v/vt", "v//vn" or "v/vt/vn"; 1-based or negative (counting back). False when malformed
// or outside what the file has so far.
bool parseCorner(std::string_view word, const ObjCounts& counts, ObjCorner& corner) {
  std::array<std::string_view, 3> parts{};
  std::size_t part = 0, start = 0;
  for (std::size_t i = 0; i <= word.size(); ++i) {
    if (i < word.size() && word[i] != '/') continue;
    if (part == 3) return false;
    parts[part++] = word.substr(start, i - start);
    start = i + 1;
  }
  const std::array<std::uint64_t, 3> limits = {counts.v, counts.vt, counts.vn};
  std::array<std::uint32_t, 3> out = {kNoIndex, kNoIndex, kNoIndex};
  for (std::size_t k = 0; k < part; ++k) {
    if (parts[k].empty()) {
      if (k == 0) return false;
      continue;
    }
    long long index = 0;
    const auto [end, error] =
        std::from_chars(parts[k].data(), parts[k].data() + parts[k].size(), index);
    if (error != std::errc() || end != parts[k].data() + parts[k].size() || index == 0)
      return false;
    const long long resolved = index > 0 ? index - 1 : static_cast<long long>(limits[k]) + index;
    if (resolved < 0 || static_cast<std::uint64_t>(resolved) >= limits[k] ||
        resolved >= static_cast<long long>(kNoIndex))
      return false;
    out[k] = static_cast<std::uint32_t>(resolved);
  }
  corner = {out[0], out[1], out[2]};
  return true;
}

class ObjChunking {
 public:
  ObjChunking(const std::string& path, const ChunkInputOptions& options)
      : path_(path),
        options_(options),
        work_(options.workDirectory + "/obj"),
        baseDir_(baseDirectoryOf(path)) {}
  ~ObjChunking() {
    for (int fd : {vertexFd_, uvFd_, normalFd_})
      if (fd >= 0) ::close(fd);
    std::error_code ignored;  // the work files go however the chunking ended
    std::filesystem::remove_all(work_, ignored);
  }
  ObjChunking(const ObjChunking&) = delete;
  ObjChunking& operator=(const ObjChunking&) = delete;

  Status copyRecords();
  Status loadMaterials();
  std::vector<std::string> libraryNames() const;
  Status sumNormals();
  Status cutFaces();
  ChunkInput finish();

 private:
  static std::string baseDirectoryOf(const std::string& path) {
    const std::string parent = std::filesystem::path(path).parent_path().string();
    return (parent.empty() ? "." : parent) + "/";
  }
  Status openWorkFiles();
  Status scanLine(std::uint64_t line, std::string_view text);
  Status addVertex(std::uint64_t line, std::span<const std::string_view> words);
  Status addCoordinates(std::uint64_t line, std::span<const std::string_view> words, bool uv);
  Status countFace(std::uint64_t line, std::span<const std::string_view> words);
  Status appendRecord(int fd, std::vector<std::byte>& pending, const void* bytes, std::size_t size,
                      const char* what);
  Result<std::size_t> faceCorners(std::uint64_t line, std::span<const std::string_view> words);
  template <class OnFace>
  Status forEachFace(const char* label, OnFace&& onFace);
  Status trackLine(std::string_view keyword, std::span<const std::string_view> words);
  Status fetch(const ObjCorner& corner, CutCorner& out);
  Status cutFace(std::size_t corners);
  Status triangulate(std::size_t corners);
  Status facePositions(std::size_t corners);
  Status flushRecords(int fd, std::vector<std::byte>& pending, const char* what);

  const std::string& path_;
  const ChunkInputOptions& options_;
  const std::string work_, baseDir_;
  int vertexFd_ = -1, uvFd_ = -1, normalFd_ = -1;
  std::vector<std::byte> pendingVertices_, pendingUvs_, pendingNormals_;
  std::optional<VertexCache> vertices_, uvs_, normals_;
  ObjCounts counts_;             // while a pass reads: the records so far
  ObjCounts total_;              // after the first pass
  std::uint64_t triangles_ = 0;  // faces fan-triangulated
  bool vertexColors_ = false, cornersWithoutNormal_ = false;
  std::vector<std::string> libraries_;  // mtllib names, in order
  std::string currentName_;             // the first pass's usemtl
  std::set<std::string> usedNames_;     // the materials faces use
  std::vector<tinyobj::material_t> mtl_;
  std::map<std::string, int> mtlIndex_;
  ObjTextures textures_;
  int material_ = -1;  // the current usemtl, into mtl_
  std::uint64_t cornersWithoutUv_ = 0;
  std::vector<ObjCorner> face_;               // the face being read
  std::vector<std::string_view> words_;       // the line being read
  std::vector<Vec3d> polygon_;                // the face's positions, for its triangulation
  std::vector<std::uint32_t> faceTriangles_;  // its triangles (corner numbers)
  std::optional<ChunkGrid> grid_;
  ChunkInput input_;
  std::vector<ChunkCell> cells_;
  std::vector<CutCorner> pieces_;
};

Status ObjChunking::openWorkFiles() {
  std::error_code error;
  std::filesystem::create_directories(work_, error);
  if (error) return ioError(work_, "cannot create: " + error.message());
  const auto create = [&](const char* name, int& fd) -> Status {
    const std::string file = work_ + "/" + name;
    fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    return fd < 0 ? Status(ioErrorFromErrno(file, "create")) : Status();
  };
  LODFORGE_TRY(create("vertices.bin", vertexFd_));
  LODFORGE_TRY(create("uvs.bin", uvFd_));
  return create("normals.bin", normalFd_);
}

// Records are gathered and written a MiB at a time.
Status ObjChunking::appendRecord(int fd, std::vector<std::byte>& pending, const void* bytes,
                                 std::size_t size, const char* what) {
  const auto* from = static_cast<const std::byte*>(bytes);
  pending.insert(pending.end(), from, from + size);
  return pending.size() >= (std::size_t{1} << 20) ? flushRecords(fd, pending, what) : Status();
}

Status ObjChunking::flushRecords(int fd, std::vector<std::byte>& pending, const char* what) {
  if (!pending.empty() &&
      ::write(fd, pending.data(), pending.size()) != static_cast<ssize_t>(pending.size()))
    return ioErrorFromErrno(work_ + "/" + what, "write");
  pending.clear();
  return {};
}

// Pass 1: positions, texture coordinates and normals to their work files, the bounds, the faces
// counted (and checked), the material libraries named.
Status ObjChunking::copyRecords() {
  input_.streamed = true;
  LODFORGE_TRY(openWorkFiles());
  LODFORGE_TRY(forEachObjLine(
      path_, "tiles: vertices",
      [&](std::uint64_t line, std::string_view text) { return scanLine(line, text); }));
  LODFORGE_TRY(flushRecords(vertexFd_, pendingVertices_, "vertices.bin"));
  LODFORGE_TRY(flushRecords(uvFd_, pendingUvs_, "uvs.bin"));
  LODFORGE_TRY(flushRecords(normalFd_, pendingNormals_, "normals.bin"));
  if (triangles_ == 0) return badInput(path_, "no faces: a tileset needs a mesh");
  total_ = counts_;
  vertices_.emplace(vertexFd_, total_.v, options_.vertexCacheBytes, VertexLayout{});
  uvs_.emplace(uvFd_, total_.vt, options_.vertexCacheBytes / 4, sizeof(Vec2f));
  normals_.emplace(normalFd_, total_.vn, options_.vertexCacheBytes / 4, sizeof(Vec3f));
  input_.colors = vertexColors_;
  return {};
}

Status ObjChunking::scanLine(std::uint64_t line, std::string_view text) {
  std::vector<std::string_view>& words = words_;
  const std::size_t count = splitWords(text, words);
  if (count == 0) return {};
  const std::span<const std::string_view> args(words.data() + 1, count - 1);
  if (words[0] == "v") return addVertex(line, args);
  if (words[0] == "vt") return addCoordinates(line, args, true);
  if (words[0] == "vn") return addCoordinates(line, args, false);
  if (words[0] == "f") return countFace(line, args);
  if (words[0] == "usemtl") currentName_ = count > 1 ? std::string(args.front()) : std::string();
  if (words[0] == "mtllib" && count > 1) {
    // A name may hold spaces: the rest of the line.
    const std::string_view rest(
        args.front().data(),
        static_cast<std::size_t>(args.back().data() + args.back().size() - args.front().data()));
    libraries_.emplace_back(rest);
  }
  return {};
}

Status ObjChunking::addVertex(std::uint64_t line, std::span<const std::string_view> words) {
  double xyz[3], rgb[3] = {1, 1, 1};
  if (words.size() < 3)
    return badInput(path_, fmt::format("line {}: a vertex needs three coordinates", line));
  for (std::size_t k = 0; k < 3; ++k)
    if (!parseNumber(words[k], xyz[k]))
      return badInput(path_, fmt::format("line {}: '{}' is not a finite number", line, words[k]));
  const bool colored = words.size() >= 6;
  for (std::size_t k = 0; colored && k < 3; ++k)
    if (!parseNumber(words[3 + k], rgb[k]))
      return badInput(path_, fmt::format("line {}: '{}' is not a colour", line, words[3 + k]));
  vertexColors_ |= colored;
  Vec3d p{xyz[0], xyz[1], xyz[2]};
  if (options_.transform && !options_.transform(p, p))
    return badInput(path_, fmt::format("line {}: the vertex cannot be transformed to the "
                                       "tileset's frame (outside the coordinate system?)",
                                       line));
  input_.bounds.add(p);
  std::array<std::byte, VertexLayout{}.bytes()> record{};
  writeVertexRecord(record.data(), VertexLayout{}, p, toRgba8(rgb[0], rgb[1], rgb[2]), Vec3f{});
  ++counts_.v;
  return appendRecord(vertexFd_, pendingVertices_, record.data(), record.size(), "vertices.bin");
}

Status ObjChunking::addCoordinates(std::uint64_t line, std::span<const std::string_view> words,
                                   bool uv) {
  const std::size_t needed = uv ? 2 : 3;
  double values[3] = {0, 0, 0};
  if (words.size() < (uv ? 1u : 3u))
    return badInput(path_, fmt::format("line {}: too few numbers", line));
  for (std::size_t k = 0; k < std::min(needed, words.size()); ++k) {
    if (!parseNumber(words[k], values[k]) ||
        std::abs(values[k]) > std::numeric_limits<float>::max())
      return badInput(path_, fmt::format("line {}: '{}' is not a finite number of float range",
                                         line, words[k]));
  }
  if (uv) {
    const Vec2f t{static_cast<float>(values[0]), static_cast<float>(values[1])};
    ++counts_.vt;
    return appendRecord(uvFd_, pendingUvs_, &t, sizeof t, "uvs.bin");
  }
  const Vec3f n{static_cast<float>(values[0]), static_cast<float>(values[1]),
                static_cast<float>(values[2])};
  ++counts_.vn;
  return appendRecord(normalFd_, pendingNormals_, &n, sizeof n, "normals.bin");
}

Result<std::size_t> ObjChunking::faceCorners(std::uint64_t line,
                                             std::span<const std::string_view> words) {
  face_.resize(words.size());
  for (std::size_t k = 0; k < words.size(); ++k) {
    if (!parseCorner(words[k], counts_, face_[k]))
      return badInput(path_, fmt::format("line {}: corner '{}' is malformed or refers to a "
                                         "vertex, coordinate or normal the file does not have "
                                         "before it",
                                         line, words[k]));
  }
  return words.size();
}

Status ObjChunking::countFace(std::uint64_t line, std::span<const std::string_view> words) {
  Result<std::size_t> corners = faceCorners(line, words);
  if (!corners) return corners.status();
  if (*corners < 3) return {};  // a line or a point: not a surface
  triangles_ += *corners - 2;
  usedNames_.insert(currentName_);
  for (std::size_t k = 0; k < *corners; ++k) cornersWithoutNormal_ |= face_[k].vn == kNoIndex;
  return {};
}

// The libraries `mtllib` lines name: the rest of the line when a file of that name is there (a
// name with spaces), its words otherwise (several libraries, as tinyobjloader reads them).
std::vector<std::string> ObjChunking::libraryNames() const {
  std::vector<std::string> names;
  for (const std::string& rest : libraries_) {
    std::error_code error;
    if (std::filesystem::exists(baseDir_ + rest, error)) {
      names.push_back(rest);
      continue;
    }
    std::vector<std::string_view> words;
    splitWords(rest, words);
    names.insert(names.end(), words.begin(), words.end());
  }
  return names;
}

// The material libraries, read once the first pass has named them: a textured material's map_Kd
// becomes a texture (found as the whole-file reader finds it), the others give their Kd.
Status ObjChunking::loadMaterials() {
  std::vector<std::string> directories{baseDir_};
  for (const std::string& library : libraryNames()) {
    input_.sideFiles.push_back(baseDir_ + library);
    tinyobj::MaterialFileReader reader(baseDir_);
    std::string warning, error;
    if (!reader(library, &mtl_, &mtlIndex_, &warning, &error))
      input_.warnings.push_back(
          fmt::format("{}: material library '{}' not read ({}): its "
                      "materials draw white",
                      path_, library, error.empty() ? warning : error));
    const std::string parent = std::filesystem::path(baseDir_ + library).parent_path().string();
    if (!parent.empty() && parent + "/" != baseDir_) directories.push_back(parent + "/");
  }
  // Only the textures faces use are read (as the whole-file reader keeps only those).
  for (tinyobj::material_t& m : mtl_)
    if (usedNames_.count(m.name) == 0) m.diffuse_texname.clear();
  Model model;
  textures_ = resolveObjTextures(mtl_, directories, model, &input_.warnings);
  for (const tinyobj::material_t& m : mtl_)
    input_.colors |= m.diffuse[0] != 1 || m.diffuse[1] != 1 || m.diffuse[2] != 1;
  if (!model.images.empty())
    input_.textures = {std::move(model.materials), std::move(model.images)};
  return {};
}

// A later pass: every face read into face_ (the material and record counts kept as it goes),
// handed to `onFace` with its corner count.
template <class OnFace>
Status ObjChunking::forEachFace(const char* label, OnFace&& onFace) {
  counts_ = {};
  material_ = -1;
  return forEachObjLine(path_, label, [&](std::uint64_t line, std::string_view text) -> Status {
    const std::size_t count = splitWords(text, words_);
    if (count == 0) return {};
    const std::span<const std::string_view> args(words_.data() + 1, count - 1);
    if (words_[0] != "f") return trackLine(words_[0], args);
    Result<std::size_t> corners = faceCorners(line, args);
    if (!corners) return corners.status();
    return onFace(*corners);
  });
}

// Keeps the current material and the record counts while a later pass reads.
Status ObjChunking::trackLine(std::string_view keyword, std::span<const std::string_view> words) {
  if (keyword == "v") {
    ++counts_.v;
  } else if (keyword == "vt") {
    ++counts_.vt;
  } else if (keyword == "vn") {
    ++counts_.vn;
  } else if (keyword == "usemtl") {
    const auto found = words.empty() ? mtlIndex_.end() : mtlIndex_.find(std::string(words[0]));
    material_ = found == mtlIndex_.end() ? -1 : found->second;
  }
  return {};
}

// One more pass where some corner has no normal (or a CRS turns the positions): area-weighted
// sums of the face normals per vertex, over the whole input, so that tiles agree along their
// borders.
Status ObjChunking::sumNormals() {
  if (!cornersWithoutNormal_ && !options_.transform) return {};
  LODFORGE_TRY(forEachFace("tiles: normals", [&](std::size_t corners) -> Status {
    LODFORGE_TRY(triangulate(corners));
    LODFORGE_TRY(facePositions(corners));
    for (std::size_t i = 0; i < faceTriangles_.size(); i += 3) {
      const std::array<std::uint32_t, 3> fan = {faceTriangles_[i], faceTriangles_[i + 1],
                                                faceTriangles_[i + 2]};
      const Vec3d a = polygon_[fan[0]], b = polygon_[fan[1]], c = polygon_[fan[2]];
      const Vec3f face = toFloat(cross(b - a, c - a));
      for (std::uint32_t k : fan)
        if (!vertices_->addNormal(face_[k].v, face))
          return ioErrorFromErrno(work_ + "/vertices.bin", "update");
    }
    return {};
  }));
  if (!vertices_->flush()) return ioErrorFromErrno(work_ + "/vertices.bin", "write");
  return {};
}

// A corner as the chunk files take it: the vertex's position, colour (its own, or the material's
// Kd: grey for a texture that could not be read) and normal (the file's, or the summed one), the
// texture coordinate of a textured material.
Status ObjChunking::fetch(const ObjCorner& corner, CutCorner& out) {
  out = CutCorner{};  // nothing of the corner before (a coordinate, a material) stays
  if (!vertices_->fetch(corner.v, out)) return ioErrorFromErrno(work_ + "/vertices.bin", "read");
  const bool textured = textures_.textured(material_);
  const bool kd = !vertexColors_ && !textured && material_ >= 0;
  bool shared = !kd;  // a vertex of one colour and normal everywhere: one record per vertex
  if (kd) {
    const auto& d = mtl_[static_cast<std::size_t>(material_)].diffuse;
    out.color = toRgba8(d[0], d[1], d[2]);
  }
  if (corner.vn != kNoIndex && !options_.transform) {
    const std::byte* n = normals_->at(corner.vn);
    if (n == nullptr) return ioErrorFromErrno(work_ + "/normals.bin", "read");
    Vec3f normal;
    std::memcpy(&normal, n, sizeof normal);
    out.normal = normalizeOr(normal, out.normal);
    shared = false;
  }
  if (textured) {
    out.material = textures_.material[static_cast<std::size_t>(material_)];
    if (corner.vt == kNoIndex) {
      ++cornersWithoutUv_;
    } else {
      const std::byte* t = uvs_->at(corner.vt);
      if (t == nullptr) return ioErrorFromErrno(work_ + "/uvs.bin", "read");
      Vec2f uv;
      std::memcpy(&uv, t, sizeof uv);
      out.uv = textures_.toUv(material_, uv.x, uv.y);
    }
    shared = false;
  }
  if (!shared) out.source = CutCorner::kNoSource;  // welded later by what it holds
  return {};
}

// The triangles of the face read (its first `corners` corners) into faceTriangles_.
Status ObjChunking::triangulate(std::size_t corners) {
  if (corners == 3) {
    faceTriangles_ = {0, 1, 2};
    return {};
  }
  LODFORGE_TRY(facePositions(corners));
  triangulatePolygon(polygon_, faceTriangles_);
  return {};
}

// The positions of the face read into polygon_.
Status ObjChunking::facePositions(std::size_t corners) {
  polygon_.resize(corners);
  CutCorner c;
  for (std::size_t k = 0; k < corners; ++k) {
    if (!vertices_->fetch(face_[k].v, c)) return ioErrorFromErrno(work_ + "/vertices.bin", "read");
    polygon_[k] = c.position;
  }
  return {};
}

Status ObjChunking::cutFace(std::size_t corners) {
  LODFORGE_TRY(triangulate(corners));
  std::array<CutCorner, 3> triangle;
  for (std::size_t i = 0; i < faceTriangles_.size(); i += 3) {
    for (std::size_t k = 0; k < 3; ++k)
      LODFORGE_TRY(fetch(face_[faceTriangles_[i + k]], triangle[k]));
    cutSegmentTriangle(*grid_, nullptr, triangle, cells_, pieces_);
    ++input_.inputTriangles;
  }
  if (cells_.size() >= 1 << 14) {
    LODFORGE_TRY(input_.chunks->addPieces(cells_, pieces_));
    cells_.clear(), pieces_.clear();
  }
  return {};
}

// The last pass: faces, corners from the caches, cut into the chunk files.
Status ObjChunking::cutFaces() {
  Result<double> size = chunkSizeFor(options_, input_.bounds, triangles_);
  if (!size) return size.status();
  grid_ = ChunkGrid::over(input_.bounds, *size);
  input_.chunks = std::make_unique<ChunkWriter>(*grid_, options_.workDirectory + "/chunks",
                                                options_.chunkBufferBytes, options_.keepInMemory);
  input_.chunks->setTextured(!input_.textures.empty());
  LODFORGE_TRY(forEachFace("tiles: chunks", [&](std::size_t corners) { return cutFace(corners); }));
  LODFORGE_TRY(input_.chunks->addPieces(cells_, pieces_));
  LODFORGE_TRY(input_.chunks->flush());
  if (cornersWithoutUv_ > 0)
    input_.warnings.push_back(
        fmt::format("{}: {} corners of textured faces have no texture "
                    "coordinate (vt); they sample the texture's corner",
                    path_, cornersWithoutUv_));
  return {};
}

// The work files go.
ChunkInput ObjChunking::finish() {
  for (int* fd : {&vertexFd_, &uvFd_, &normalFd_}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
  std::error_code ignored;
  std::filesystem::remove_all(work_, ignored);
  return std::move(input_);
}

}  // namespace

Result<ChunkInput> chunkObj(const std::string& path, const ChunkInputOptions& options) {
  ObjChunking chunking(path, options);
  LODFORGE_TRY(chunking.copyRecords());
  LODFORGE_TRY(chunking.loadMaterials());
  LODFORGE_TRY(chunking.sumNormals());
  LODFORGE_TRY(chunking.cutFaces());
  return chunking.finish();
}

}  // namespace lodforge
