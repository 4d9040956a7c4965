#include "lodforge/simplify/package.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <mutex>

#include <tbb/blocked_range.h>

#include <tbb/parallel_for.h>

#include "lodforge/core/checksum.h"

namespace lodforge {

std::string_view packageSectionName(PackageSection section) {
  static constexpr std::string_view kNames[] = {
      "objects", "names",    "positions", "normals",      "colors", "triangles", "ecol",  "map",
      "error",   "assembly", "materials", "objectLayers", "layers", "uvs",       "whole", "images"};
  return kNames[static_cast<std::uint32_t>(section)];
}

bool looksLikePackage(std::span<const std::byte> firstBytes) {
  return firstBytes.size() >= kPackageMagic.size() &&
         std::memcmp(firstBytes.data(), kPackageMagic.data(), kPackageMagic.size()) == 0;
}

namespace {

// Whether `count` items from `offset` run past `total` (written so that nothing overflows).
bool outside(std::uint64_t offset, std::uint64_t count, std::uint64_t total) {
  return offset > total || count > total - offset;
}

std::uint64_t headerChecksumOf(const PackageHeader& header) {
  return checksum64(
      {reinterpret_cast<const std::byte*>(&header), offsetof(PackageHeader, headerChecksum)});
}

}  // namespace

// --- writer -----------------------------------------------------------------------------------

struct PackageWriter::State {
  std::string path;
  PackageHeader header;
  Aabb bounds;
  struct Spill {
    std::optional<OutputFile> file;
    std::string path;
    Checksum64 checksum;
    std::uint64_t bytes = 0;
  };
  std::array<Spill, kPackageSections> spills;

  Status append(PackageSection section, const void* data, std::size_t size) {
    Spill& spill = spills[static_cast<std::uint32_t>(section)];
    spill.checksum.update(data, size);
    spill.bytes += size;
    return spill.file->write(data, size);
  }
  template <class T>
  Status append(PackageSection section, std::span<const T> values) {
    return append(section, values.data(), values.size_bytes());
  }
  void discard() {
    for (Spill& spill : spills) {
      spill.file.reset();  // removes its temporary
      if (!spill.path.empty()) std::remove(spill.path.c_str());
    }
  }
  ~State() { discard(); }
};

PackageWriter::PackageWriter(std::unique_ptr<State> state) : state_(std::move(state)) {}
PackageWriter::PackageWriter(PackageWriter&&) noexcept = default;
PackageWriter& PackageWriter::operator=(PackageWriter&&) noexcept = default;
PackageWriter::~PackageWriter() = default;
std::uint64_t PackageWriter::objectCount() const {
  return state_->header.objectCount;
}

Result<PackageWriter> PackageWriter::create(const std::string& path, Vec3d origin, bool normals,
                                            bool colors, bool uvs) {
  auto state = std::make_unique<State>();
  state->path = path;
  state->header.origin[0] = origin.x;
  state->header.origin[1] = origin.y;
  state->header.origin[2] = origin.z;
  state->header.flags = (normals ? PackageHeader::kHasNormals : 0) |
                        (colors ? PackageHeader::kHasColors : 0) |
                        (uvs ? PackageHeader::kHasUvs : 0);
  for (std::uint32_t s = 0; s < kPackageSections; ++s) {
    // Each section is spilled to "<path>.<section>", itself written under a temporary name.
    auto& spill = state->spills[s];
    Result<OutputFile> file =
        OutputFile::create(temporaryPathFor(path) + "." +
                               std::string(packageSectionName(static_cast<PackageSection>(s))),
                           1 << 20);
    if (!file) return file.status();
    spill.file.emplace(std::move(file.value()));
  }
  return PackageWriter(std::move(state));
}

namespace {

// A textured package's per-vertex coordinates and per-level whole counts (zeros and identity
// for an untextured object).
Status appendTexture(PackageWriter::State& s, const ProgressiveMesh& mesh, std::size_t levels) {
  if (!mesh.uvs.empty()) {
    LODFORGE_TRY(s.append<Vec2f>(PackageSection::kUvs, mesh.uvs));
  } else {
    const std::vector<Vec2f> zeros(mesh.vertexCount());
    LODFORGE_TRY(s.append<Vec2f>(PackageSection::kUvs, zeros));
  }
  if (!mesh.whole.empty()) return s.append<std::uint32_t>(PackageSection::kWhole, mesh.whole);
  std::vector<std::uint32_t> identity(levels);
  for (std::size_t k = 0; k < levels; ++k) identity[k] = mesh.q + static_cast<std::uint32_t>(k);
  return s.append<std::uint32_t>(PackageSection::kWhole, identity);
}

// The images table, then each image's encoded bytes (a file's read now, one at a time: the
// package stands alone, and 16 atlases of 8K never sit in memory together).
Status appendImages(PackageWriter::State& s, std::span<const ImageSource> images) {
  std::vector<std::uint64_t> sizes(images.size());
  std::uint64_t at = 0;
  for (std::size_t k = 0; k < images.size(); ++k) {
    const ImageSource& image = images[k];
    if (image.embedded()) {
      sizes[k] = image.bytes.size();
    } else {
      Result<std::uint64_t> size = fileSize(image.path);
      if (!size) return size.status();
      sizes[k] = *size;
    }
    PackageImage record;
    record.dataOffset = at;
    record.dataBytes = sizes[k];
    record.nameOffset = s.spills[static_cast<std::uint32_t>(PackageSection::kNames)].bytes;
    record.nameLength = static_cast<std::uint32_t>(image.name.size());
    record.format = static_cast<std::uint32_t>(image.format);
    record.width = image.width;
    record.height = image.height;
    record.channels = image.channels;
    LODFORGE_TRY(s.append(PackageSection::kNames, image.name.data(), image.name.size()));
    LODFORGE_TRY(s.append(PackageSection::kImages, &record, sizeof record));
    at += sizes[k];
  }
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (images[k].embedded()) {
      LODFORGE_TRY(s.append<std::byte>(PackageSection::kImages, images[k].bytes));
      continue;
    }
    Result<std::vector<std::byte>> bytes = readFileBytes(images[k].path);
    if (!bytes) return bytes.status();
    if (bytes->size() != sizes[k])
      return ioError(images[k].path, "changed size while the package was written");
    LODFORGE_TRY(s.append<std::byte>(PackageSection::kImages, *bytes));
  }
  s.header.imageCount = static_cast<std::uint32_t>(images.size());
  return {};
}

}  // namespace

Status PackageWriter::add(const ProgressiveMesh& mesh, const PackageObjectInfo& info) {
  State& s = *state_;
  PackageHeader& h = s.header;
  assert(mesh.normals.empty() != h.hasNormals() || mesh.vertexCount() == 0);
  assert(mesh.colors.empty() != h.hasColors() || mesh.vertexCount() == 0);
  // A textured mesh's partial counts must stay undrawable: its whole counts need the section.
  assert((mesh.uvs.empty() && mesh.whole.empty()) || h.hasUvs());
  PackageObject record;
  record.vertexOffset = h.vertexCount;
  record.triangleOffset = h.triangleCount;
  record.levelOffset = h.levelCount;
  record.vertexCount = mesh.vertexCount();
  record.minVertexCount = mesh.q;
  record.triangleCount = mesh.triangleCount();
  record.minTriangleCount = mesh.map.empty() ? 0 : mesh.map.front();
  Aabb box;
  for (const Vec3f& p : mesh.positions) box.add(p);
  if (box.empty()) box.add(Vec3f{});
  std::memcpy(record.boundsMin, &box.min, 12);
  std::memcpy(record.boundsMax, &box.max, 12);
  s.bounds.add(box);
  const std::uint64_t namesAt = s.spills[static_cast<std::uint32_t>(PackageSection::kNames)].bytes;
  record.nameOffset = namesAt;
  record.nameLength = static_cast<std::uint32_t>(info.name.size());
  record.color = info.color;
  const PackageAssembly assembly{namesAt + info.name.size(),
                                 static_cast<std::uint32_t>(info.path.size()), info.material};

  // An empty object still gets its one level (n = q = 0, no triangles).
  const std::vector<std::uint32_t> emptyMap = {0};
  const std::vector<float> emptyError = {0.0f};
  const auto& map = mesh.map.empty() ? emptyMap : mesh.map;
  const auto& error = mesh.error.empty() ? emptyError : mesh.error;

  LODFORGE_TRY(s.append(PackageSection::kObjects, &record, sizeof record));
  LODFORGE_TRY(s.append(PackageSection::kNames, info.name.data(), info.name.size()));
  LODFORGE_TRY(s.append(PackageSection::kNames, info.path.data(), info.path.size()));
  LODFORGE_TRY(s.append(PackageSection::kAssembly, &assembly, sizeof assembly));
  LODFORGE_TRY(s.append(PackageSection::kObjectLayers, &info.layer, sizeof info.layer));
  LODFORGE_TRY(s.append<Vec3f>(PackageSection::kPositions, mesh.positions));
  if (h.hasNormals()) LODFORGE_TRY(s.append<Vec3f>(PackageSection::kNormals, mesh.normals));
  if (h.hasColors()) LODFORGE_TRY(s.append<Rgba8>(PackageSection::kColors, mesh.colors));
  LODFORGE_TRY(s.append<std::uint32_t>(PackageSection::kTriangles, mesh.triangles));
  LODFORGE_TRY(s.append<std::uint32_t>(PackageSection::kEcol, mesh.ecol));
  LODFORGE_TRY(s.append<std::uint32_t>(PackageSection::kMap, map));
  LODFORGE_TRY(s.append<float>(PackageSection::kError, error));
  if (h.hasUvs()) LODFORGE_TRY(appendTexture(s, mesh, map.size()));
  ++h.objectCount;
  h.vertexCount += mesh.vertexCount();
  h.triangleCount += mesh.triangleCount();
  h.levelCount += map.size();
  return {};
}

Status PackageWriter::finish(std::span<const Material> materials,
                             std::span<const std::string> layers,
                             std::span<const ImageSource> images) {
  State& s = *state_;
  PackageHeader& h = s.header;
  for (const Material& m : materials) {
    PackageMaterial record;
    std::copy(m.baseColor.begin(), m.baseColor.end(), record.baseColor);
    std::copy(m.emissive.begin(), m.emissive.end(), record.emissive);
    record.metallic = m.metallic;
    record.roughness = m.roughness;
    record.alphaCutoff = m.alphaCutoff;
    record.alphaMode = static_cast<std::uint32_t>(m.alphaMode);
    record.doubleSided = m.doubleSided ? 1 : 0;
    record.wrapS = static_cast<std::uint8_t>(m.wrapS);
    record.wrapT = static_cast<std::uint8_t>(m.wrapT);
    record.baseColorImage = m.baseColorImage;
    record.nameOffset = s.spills[static_cast<std::uint32_t>(PackageSection::kNames)].bytes;
    record.nameLength = static_cast<std::uint32_t>(m.name.size());
    LODFORGE_TRY(s.append(PackageSection::kNames, m.name.data(), m.name.size()));
    LODFORGE_TRY(s.append(PackageSection::kMaterials, &record, sizeof record));
  }
  for (const std::string& name : layers) {
    const PackageLayer record{s.spills[static_cast<std::uint32_t>(PackageSection::kNames)].bytes,
                              static_cast<std::uint32_t>(name.size())};
    LODFORGE_TRY(s.append(PackageSection::kNames, name.data(), name.size()));
    LODFORGE_TRY(s.append(PackageSection::kLayers, &record, sizeof record));
  }
  LODFORGE_TRY(appendImages(s, images));
  const Aabb bounds = s.bounds.empty() ? Aabb{Vec3f{}, Vec3f{}} : s.bounds;
  std::memcpy(h.boundsMin, &bounds.min, 12);
  std::memcpy(h.boundsMax, &bounds.max, 12);
  Result<OutputFile> out = OutputFile::create(s.path);
  if (!out) return out.status();
  LODFORGE_TRY(out->write(&h, sizeof h));  // placeholder; rewritten with offsets at the end
  static const std::byte zeros[kPackageAlignment] = {};
  for (std::uint32_t i = 0; i < kPackageSections; ++i) {
    State::Spill& spill = s.spills[i];
    const std::uint64_t pad =
        (kPackageAlignment - out->bytesWritten() % kPackageAlignment) % kPackageAlignment;
    LODFORGE_TRY(out->write(zeros, pad));
    h.sections[i] = {out->bytesWritten(), spill.bytes, spill.checksum.digest()};
    spill.path = spill.file->path();
    LODFORGE_TRY(spill.file->commit());
    spill.file.reset();
    LODFORGE_TRY(out->appendFileContents(spill.path, spill.bytes));
    std::remove(spill.path.c_str());
    spill.path.clear();
  }
  h.headerChecksum = headerChecksumOf(h);
  LODFORGE_TRY(out->writeAt(0, &h, sizeof h));
  return out->commit();
}

// --- reader -----------------------------------------------------------------------------------

template <class T>
std::span<const T> Package::section(PackageSection s) const {
  const PackageSectionEntry& e = header_->sections[static_cast<std::uint32_t>(s)];
  return {reinterpret_cast<const T*>(bytes_.data() + e.offset), e.bytes / sizeof(T)};
}

std::span<const PackageObject> Package::objects() const {
  return section<PackageObject>(PackageSection::kObjects);
}
std::span<const Vec3f> Package::allPositions() const {
  return section<Vec3f>(PackageSection::kPositions);
}
std::span<const Vec3f> Package::allNormals() const {
  return section<Vec3f>(PackageSection::kNormals);
}
std::span<const Rgba8> Package::allColors() const {
  return section<Rgba8>(PackageSection::kColors);
}
std::span<const Vec2f> Package::allUvs() const {
  return section<Vec2f>(PackageSection::kUvs);
}
std::span<const std::uint32_t> Package::allTriangles() const {
  return section<std::uint32_t>(PackageSection::kTriangles);
}
std::span<const std::uint32_t> Package::allEcol() const {
  return section<std::uint32_t>(PackageSection::kEcol);
}

std::span<const std::uint32_t> Package::allMap() const {
  return section<std::uint32_t>(PackageSection::kMap);
}
std::span<const std::uint32_t> Package::allWhole() const {
  return section<std::uint32_t>(PackageSection::kWhole);
}

std::string_view Package::objectName(std::size_t i) const {
  const auto names = section<char>(PackageSection::kNames);
  return {names.data() + object(i).nameOffset, object(i).nameLength};
}
std::string_view Package::objectPath(std::size_t i) const {
  const auto names = section<char>(PackageSection::kNames);
  const PackageAssembly& a = section<PackageAssembly>(PackageSection::kAssembly)[i];
  return {names.data() + a.pathOffset, a.pathLength};
}
std::uint32_t Package::objectMaterial(std::size_t i) const {
  return section<PackageAssembly>(PackageSection::kAssembly)[i].material;
}
std::uint32_t Package::objectLayerIndex(std::size_t i) const {
  return section<std::uint32_t>(PackageSection::kObjectLayers)[i];
}
std::string_view Package::objectLayer(std::size_t i) const {
  const std::uint32_t l = objectLayerIndex(i);
  return l == kNoLayer ? std::string_view() : layer(l);
}
std::size_t Package::layerCount() const {
  return section<PackageLayer>(PackageSection::kLayers).size();
}
std::string_view Package::layer(std::size_t l) const {
  const auto names = section<char>(PackageSection::kNames);
  const PackageLayer& r = section<PackageLayer>(PackageSection::kLayers)[l];
  return {names.data() + r.nameOffset, r.nameLength};
}
std::size_t Package::materialCount() const {
  return section<PackageMaterial>(PackageSection::kMaterials).size();
}
Material Package::material(std::size_t m) const {
  const auto names = section<char>(PackageSection::kNames);
  const PackageMaterial& r = section<PackageMaterial>(PackageSection::kMaterials)[m];
  Material material;
  material.name.assign(names.data() + r.nameOffset, r.nameLength);
  std::copy(std::begin(r.baseColor), std::end(r.baseColor), material.baseColor.begin());
  std::copy(std::begin(r.emissive), std::end(r.emissive), material.emissive.begin());
  material.metallic = r.metallic;
  material.roughness = r.roughness;
  material.alphaCutoff = r.alphaCutoff;
  material.alphaMode = static_cast<AlphaMode>(r.alphaMode);
  material.doubleSided = r.doubleSided != 0;
  material.baseColorImage = r.baseColorImage;
  material.wrapS = static_cast<TextureWrap>(r.wrapS);
  material.wrapT = static_cast<TextureWrap>(r.wrapT);
  return material;
}
std::span<const Vec3f> Package::positions(std::size_t i) const {
  return allPositions().subspan(object(i).vertexOffset, object(i).vertexCount);
}
std::span<const Vec3f> Package::normals(std::size_t i) const {
  if (!header_->hasNormals()) return {};
  return allNormals().subspan(object(i).vertexOffset, object(i).vertexCount);
}
std::span<const Rgba8> Package::colors(std::size_t i) const {
  if (!header_->hasColors()) return {};
  return allColors().subspan(object(i).vertexOffset, object(i).vertexCount);
}
std::span<const Vec2f> Package::uvs(std::size_t i) const {
  if (!header_->hasUvs()) return {};
  return allUvs().subspan(object(i).vertexOffset, object(i).vertexCount);
}
std::uint32_t Package::wholeAt(std::size_t i, std::uint32_t n) const {
  const PackageObject& o = object(i);
  assert(n >= o.minVertexCount && n <= o.vertexCount);
  if (!header_->hasUvs()) return n;
  return section<std::uint32_t>(PackageSection::kWhole)[o.levelOffset + (n - o.minVertexCount)];
}
ImageSource Package::image(std::size_t k) const {
  const auto table = section<PackageImage>(PackageSection::kImages).first(imageCount());
  const PackageImage& r = table[k];
  const auto names = section<char>(PackageSection::kNames);
  const auto data = section<std::byte>(PackageSection::kImages).subspan(table.size_bytes());
  ImageSource image;
  image.name.assign(names.data() + r.nameOffset, r.nameLength);
  const auto bytes = data.subspan(r.dataOffset, r.dataBytes);
  image.bytes.assign(bytes.begin(), bytes.end());
  image.format = static_cast<ImageFormat>(r.format);
  image.width = r.width;
  image.height = r.height;
  image.channels = r.channels;
  return image;
}
std::span<const std::uint32_t> Package::triangles(std::size_t i) const {
  return allTriangles().subspan(3 * object(i).triangleOffset,
                                3 * std::size_t{object(i).triangleCount});
}
std::span<const std::uint32_t> Package::ecol(std::size_t i) const {
  return allEcol().subspan(object(i).vertexOffset, object(i).vertexCount);
}
std::span<const std::uint32_t> Package::map(std::size_t i) const {
  const PackageObject& o = object(i);
  return section<std::uint32_t>(PackageSection::kMap)
      .subspan(o.levelOffset, std::uint64_t{o.vertexCount} - o.minVertexCount + 1);
}
std::span<const float> Package::error(std::size_t i) const {
  const PackageObject& o = object(i);
  return section<float>(PackageSection::kError)
      .subspan(o.levelOffset, std::uint64_t{o.vertexCount} - o.minVertexCount + 1);
}
std::uint32_t Package::trianglesAt(std::size_t i, std::uint32_t n) const {
  const PackageObject& o = object(i);
  assert(n >= o.minVertexCount && n <= o.vertexCount);
  return map(i)[n - o.minVertexCount];
}

Result<Package> Package::open(const std::string& path, const OpenOptions& options) {
  Result<MappedFile> file = MappedFile::open(path);
  if (!file) return file.status();
  Package package;
  package.name_ = path;
  package.file_ = std::make_shared<MappedFile>(std::move(file.value()));
  package.bytes_ = package.file_->bytes();
  LODFORGE_TRY(package.validate(options));
  return package;
}

Result<Package> Package::fromBytes(std::span<const std::byte> bytes, const std::string& name,
                                   const OpenOptions& options) {
  Package package;
  package.name_ = name;
  package.bytes_ = bytes;
  LODFORGE_TRY(package.validate(options));
  return package;
}

Status Package::badAt(std::uint64_t at, std::string_view what) const {
  return badInputAtByte(name_, at, what);
}

Status Package::validate(const OpenOptions& options) {
  LODFORGE_TRY(validateHeader());
  LODFORGE_TRY(validateSections(options));
  LODFORGE_TRY(validateMaterials());
  LODFORGE_TRY(validateLayers());
  LODFORGE_TRY(validateImages());
  return validateObjects();
}

// Magic, alignment, version, the header's checksum and the section count.
Status Package::validateHeader() {
  const std::uint64_t size = bytes_.size();
  if (size < sizeof(PackageHeader) || !looksLikePackage(bytes_)) {
    if (looksLikePackage(bytes_))
      return badAt(size, "the package ends inside its 512-byte header (truncated)");
    return badAt(0, "not a lodforge package (wrong magic)");
  }
  if (reinterpret_cast<std::uintptr_t>(bytes_.data()) % alignof(std::uint64_t) != 0) {
    return Error{ErrorKind::kInternal, name_ + ": package bytes are not 8-byte aligned"};
  }
  header_ = reinterpret_cast<const PackageHeader*>(bytes_.data());
  const PackageHeader& h = *header_;
  if (h.version != kPackageVersion) {
    return badAt(8, fmt::format("package version {} (this lodforge reads version {}): build it "
                                "again from its source with `lodforge build`",
                                h.version, kPackageVersion));
  }
  if (h.headerChecksum != headerChecksumOf(h))
    return badAt(504, "header checksum mismatch: the package is corrupted");
  if (h.sectionCount != kPackageSections)
    return badAt(96, fmt::format("{} sections (expected {})", h.sectionCount, kPackageSections));
  return {};
}

// Section sizes follow from the counts (counts the file cannot hold are refused before
// multiplying); every section lies inside the file; checksums when asked.
Status Package::validateSections(const OpenOptions& options) const {
  const std::uint64_t size = bytes_.size();
  const PackageHeader& h = *header_;
  auto sectionAt = [&](std::uint32_t s) {
    return offsetof(PackageHeader, sections) + s * sizeof(PackageSectionEntry);
  };
  for (std::uint64_t count :
       {h.objectCount, h.vertexCount, h.triangleCount, h.levelCount, std::uint64_t{h.imageCount}}) {
    if (count > size)
      return badAt(16, "counts larger than the file can hold: the package is corrupted");
  }
  const std::uint64_t expected[kPackageSections] = {
      h.objectCount * sizeof(PackageObject),
      h.sections[static_cast<std::uint32_t>(PackageSection::kNames)].bytes,
      h.vertexCount * sizeof(Vec3f),
      h.hasNormals() ? h.vertexCount * sizeof(Vec3f) : 0,
      h.hasColors() ? h.vertexCount * sizeof(Rgba8) : 0,
      h.triangleCount * 3 * sizeof(std::uint32_t),
      h.vertexCount * sizeof(std::uint32_t),
      h.levelCount * sizeof(std::uint32_t),
      h.levelCount * sizeof(float),
      h.objectCount * sizeof(PackageAssembly),
      h.sections[static_cast<std::uint32_t>(PackageSection::kMaterials)].bytes /
          sizeof(PackageMaterial) * sizeof(PackageMaterial),
      h.objectCount * sizeof(std::uint32_t),
      h.sections[static_cast<std::uint32_t>(PackageSection::kLayers)].bytes / sizeof(PackageLayer) *
          sizeof(PackageLayer),
      h.hasUvs() ? h.vertexCount * sizeof(Vec2f) : 0,
      h.hasUvs() ? h.levelCount * sizeof(std::uint32_t) : 0,
      std::max<std::uint64_t>(h.sections[static_cast<std::uint32_t>(PackageSection::kImages)].bytes,
                              std::uint64_t{h.imageCount} * sizeof(PackageImage))};
  for (std::uint32_t s = 0; s < kPackageSections; ++s) {
    const PackageSectionEntry& e = h.sections[s];
    const auto name = packageSectionName(static_cast<PackageSection>(s));
    if (e.offset % kPackageAlignment != 0 || e.offset < sizeof(PackageHeader) || e.offset > size ||
        e.bytes > size - e.offset) {
      return badAt(
          sectionAt(s),
          fmt::format("section '{}' ({} bytes at byte {}) lies outside the {}-byte file{}", name,
                      e.bytes, e.offset, size, e.offset <= size ? " (truncated?)" : ""));
    }
    if (e.bytes != expected[s]) {
      return badAt(sectionAt(s), fmt::format("section '{}' has {} bytes, the counts need {}", name,
                                             e.bytes, expected[s]));
    }
  }
  if (!options.verifyChecksums) return {};
  std::atomic<int> failed{-1};
  tbb::parallel_for(std::uint32_t{0}, kPackageSections, [&](std::uint32_t s) {
    const PackageSectionEntry& e = h.sections[s];
    if (checksum64(bytes_.subspan(e.offset, e.bytes)) != e.checksum) failed = static_cast<int>(s);
  });
  if (failed < 0) return {};
  const auto s = static_cast<std::uint32_t>(failed.load());
  return badAt(h.sections[s].offset,
               fmt::format("section '{}' checksum mismatch: the package is corrupted",
                           packageSectionName(static_cast<PackageSection>(s))));
}

std::string Package::objectProblem(std::size_t i) const {
  const PackageHeader& h = *header_;
  const std::uint64_t nameBytes =
      h.sections[static_cast<std::uint32_t>(PackageSection::kNames)].bytes;
  const PackageObject& o = objects()[i];
  const std::uint64_t levels = std::uint64_t{o.vertexCount} - o.minVertexCount + 1;
  if (o.minVertexCount > o.vertexCount) return "q > p";
  if (outside(o.vertexOffset, o.vertexCount, h.vertexCount)) return "vertices outside the section";
  if (outside(o.triangleOffset, o.triangleCount, h.triangleCount))
    return "triangles outside the section";
  if (outside(o.levelOffset, levels, h.levelCount)) return "levels outside the section";
  if (outside(o.nameOffset, o.nameLength, nameBytes)) return "name outside the section";
  const PackageAssembly& a = section<PackageAssembly>(PackageSection::kAssembly)[i];
  if (outside(a.pathOffset, a.pathLength, nameBytes))
    return "assembly path outside the names section";
  if (a.material != kNoMaterial && a.material >= materialCount())
    return fmt::format("material {} of {}", a.material, materialCount());
  if (const std::uint32_t l = objectLayerIndex(i); l != kNoLayer && l >= layerCount())
    return fmt::format("layer {} of {}", l, layerCount());
  if (o.minTriangleCount > o.triangleCount) return "map(q) > map(p)";
  const auto e = ecol(i);
  for (std::uint32_t v = 0; v < o.vertexCount; ++v) {
    if (v < o.minVertexCount ? e[v] != v : e[v] >= v)
      return fmt::format("ecol[{}] = {} breaks the decreasing chains", v, e[v]);
  }
  for (std::uint32_t c : triangles(i)) {
    if (c >= o.vertexCount)
      return fmt::format("triangle corner {} >= {} vertices", c, o.vertexCount);
  }
  const auto m = map(i);
  const auto err = error(i);
  if (m.front() != o.minTriangleCount || m.back() != o.triangleCount)
    return "map ends do not match";
  for (std::size_t k = 1; k < m.size(); ++k) {
    if (m[k] < m[k - 1]) return "map decreases";
  }
  for (std::size_t k = 0; k < err.size(); ++k) {
    if (!std::isfinite(err[k]) || err[k] < 0 || (k > 0 && err[k] > err[k - 1]))
      return "error table is not finite and non-increasing";
  }
  return wholeProblem(i);
}

// Every material's name inside the names section and its fields in their ranges.
Status Package::validateMaterials() const {
  const PackageSectionEntry& names =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kNames)];
  const PackageSectionEntry& table =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kMaterials)];
  const auto materials = section<PackageMaterial>(PackageSection::kMaterials);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    const PackageMaterial& r = materials[m];
    const bool finite =
        std::all_of(reinterpret_cast<const float*>(&r), reinterpret_cast<const float*>(&r) + 10,
                    [](float v) { return std::isfinite(v); });
    const char* problem = nullptr;
    if (outside(r.nameOffset, r.nameLength, names.bytes))
      problem = "name outside the names section";
    else if (r.alphaMode > static_cast<std::uint32_t>(AlphaMode::kBlend))
      problem = "alpha mode is not OPAQUE, MASK or BLEND";
    else if (r.doubleSided > 1)
      problem = "doubleSided is neither 0 nor 1";
    else if (r.wrapS > static_cast<std::uint8_t>(TextureWrap::kClamp) ||
             r.wrapT > static_cast<std::uint8_t>(TextureWrap::kClamp))
      problem = "a wrap mode is not REPEAT, MIRRORED_REPEAT or CLAMP_TO_EDGE";
    else if (r.baseColorImage != kNoImage && r.baseColorImage >= imageCount())
      problem = "texture image outside the images table";
    else if (!finite)
      problem = "a factor is not finite";
    if (problem)
      return badAt(table.offset + m * sizeof(PackageMaterial),
                   fmt::format("material {}: {}", m, problem));
  }
  return {};
}

// A textured object's whole counts: each in [q, n], itself whole, never decreasing, p whole.
std::string Package::wholeProblem(std::size_t i) const {
  if (!header_->hasUvs()) return {};
  const PackageObject& o = objects()[i];
  const std::uint64_t levels = std::uint64_t{o.vertexCount} - o.minVertexCount + 1;
  const auto whole = section<std::uint32_t>(PackageSection::kWhole).subspan(o.levelOffset, levels);
  for (std::size_t k = 0; k < whole.size(); ++k) {
    const std::uint32_t n = o.minVertexCount + static_cast<std::uint32_t>(k), w = whole[k];
    if (w < o.minVertexCount || w > n || whole[w - o.minVertexCount] != w ||
        (k > 0 && w < whole[k - 1]))
      return fmt::format("whole count {} at {} vertices", w, n);
  }
  if (whole.back() != o.vertexCount) return "the full mesh is not a whole count";
  return {};
}

// The images table inside its section, each image's bytes and name inside theirs, a known
// format.
Status Package::validateImages() const {
  const PackageSectionEntry& entry =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kImages)];
  const std::uint64_t nameBytes =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kNames)].bytes;
  const auto table = section<PackageImage>(PackageSection::kImages).first(imageCount());
  const std::uint64_t dataBytes = entry.bytes - table.size_bytes();
  for (std::size_t k = 0; k < table.size(); ++k) {
    const PackageImage& r = table[k];
    const char* problem = nullptr;
    if (outside(r.dataOffset, r.dataBytes, dataBytes))
      problem = "bytes outside the images section";
    else if (outside(r.nameOffset, r.nameLength, nameBytes))
      problem = "name outside the names section";
    else if (r.format == 0 || r.format > static_cast<std::uint32_t>(ImageFormat::kTga))
      problem = "unknown image format";
    if (problem)
      return badAt(entry.offset + k * sizeof(PackageImage),
                   fmt::format("image {}: {}", k, problem));
  }
  return {};
}

// Every layer's name inside the names section.
Status Package::validateLayers() const {
  const PackageSectionEntry& names =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kNames)];
  const PackageSectionEntry& table =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kLayers)];
  const auto layers = section<PackageLayer>(PackageSection::kLayers);
  for (std::size_t l = 0; l < layers.size(); ++l) {
    if (outside(layers[l].nameOffset, layers[l].nameLength, names.bytes))
      return badAt(table.offset + l * sizeof(PackageLayer),
                   fmt::format("layer {}: name outside the names section", l));
  }
  return {};
}

// Per object, in parallel: the first broken object (by index) is reported.
Status Package::validateObjects() const {
  const auto objectList = objects();
  const std::uint64_t objectsAt =
      header_->sections[static_cast<std::uint32_t>(PackageSection::kObjects)].offset;
  std::atomic<std::uint64_t> firstBad{std::numeric_limits<std::uint64_t>::max()};
  std::string why;
  std::mutex whyMutex;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, objectList.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        if (i > firstBad.load()) return;
                        std::string problem = objectProblem(i);
                        if (problem.empty()) continue;
                        std::lock_guard lock(whyMutex);
                        if (i < firstBad.load()) {
                          firstBad = i;
                          why = std::move(problem);
                        }
                      }
                    });
  if (firstBad.load() == std::numeric_limits<std::uint64_t>::max()) return {};
  const std::uint64_t i = firstBad.load();
  return badAt(objectsAt + i * sizeof(PackageObject), fmt::format("object {}: {}", i, why));
}

}  // namespace lodforge
