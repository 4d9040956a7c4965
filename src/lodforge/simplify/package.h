// The progressive package (.lfp): one mmap-able file with every object's progressive mesh, read
// in place by the runtime. Layout (little-endian, every section 64-byte aligned; also in
// docs/formats.md):
//
//   header        512 bytes: magic, version, counts, origin, bounds, section table, checksum
//   objects       PackageObject[objectCount]                   (80 bytes each)
//   names         object names, assembly paths and material names, back to back (UTF-8, no
//                 terminator)
//   positions     float[3] per vertex, rearranged, relative to the origin
//   normals       float[3] per vertex (flag bit 0)
//   colors        RGBA8 per vertex (flag bit 1)
//   triangles     uint32[3] per triangle, rearranged, object-local vertex indices, full detail
//   ecol          uint32 per vertex, object-local: ecol[i] < i for i >= q, ecol[i] = i below q
//   map           uint32 per level: triangles at n vertices, n = q..p for each object
//   error         float per level: geometric error at n vertices (model units)
//   assembly      PackageAssembly[objectCount]: each object's path and material (16 bytes each)
//   materials     PackageMaterial per material the objects use (64 bytes each)
//   objectLayers  uint32 per object: its CAD layer, into layers, or ~0u
//   layers        PackageLayer per layer the objects are on (16 bytes each)
//   uvs           float[2] per vertex (flag bit 2: textured; a textured object's vertices are
//                 its wedges, ProgressiveMesh::uvs)
//   whole         uint32 per level (flag bit 2): the largest count <= n that leaves no surface
//                 point half collapsed (n itself for an untextured object)
//   images        PackageImage[imageCount], then the images' encoded bytes (JPEG, PNG, ...)
//
// Each section carries an XXH3-64 checksum; the header checksums itself. Package::open checks
// all of it, and every index a kernel will follow, before handing out a single span.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "lodforge/core/file.h"
#include "lodforge/core/image_source.h"
#include "lodforge/core/material.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/simplify/progressive.h"

namespace lodforge {

enum class PackageSection : std::uint32_t {
  kObjects,
  kNames,
  kPositions,
  kNormals,
  kColors,
  kTriangles,
  kEcol,
  kMap,
  kError,
  kAssembly,
  kMaterials,
  kObjectLayers,
  kLayers,
  kUvs,
  kWhole,
  kImages,
  kCount
};
inline constexpr std::uint32_t kPackageSections =
    static_cast<std::uint32_t>(PackageSection::kCount);
std::string_view packageSectionName(PackageSection section);

// Version 2 added the assembly and materials sections, version 3 the layers, version 4 textures
// (uvs, whole counts, images, a material's texture).
inline constexpr std::uint32_t kPackageVersion = 4;
inline constexpr std::size_t kPackageAlignment = 64;
// PNG-style magic: a high byte and CR LF / ^Z / LF catch text-mode transfers that damage files.
inline constexpr std::array<char, 8> kPackageMagic = {'\x89', 'L',  'F',    'P',
                                                      '\r',   '\n', '\x1a', '\n'};

struct PackageSectionEntry {
  std::uint64_t offset = 0;
  std::uint64_t bytes = 0;
  std::uint64_t checksum = 0;
};

struct PackageHeader {
  std::array<char, 8> magic = kPackageMagic;
  std::uint32_t version = kPackageVersion;
  std::uint32_t flags = 0;  // bit 0: normals, bit 1: colors, bit 2: uvs (textured)
  std::uint64_t objectCount = 0;
  std::uint64_t vertexCount = 0;
  std::uint64_t triangleCount = 0;
  std::uint64_t levelCount = 0;  // entries of map and error: sum over objects of p - q + 1
  double origin[3] = {0, 0, 0};
  float boundsMin[3] = {0, 0, 0};
  float boundsMax[3] = {0, 0, 0};
  std::uint32_t sectionCount = kPackageSections;
  std::uint32_t imageCount = 0;  // entries of the images section's table
  PackageSectionEntry sections[kPackageSections];
  std::uint8_t padding[512 - 104 - kPackageSections * sizeof(PackageSectionEntry) - 8] = {};
  std::uint64_t headerChecksum = 0;  // XXH3-64 of the 504 bytes before it

  static constexpr std::uint32_t kHasNormals = 1, kHasColors = 2, kHasUvs = 4;
  bool hasNormals() const { return (flags & kHasNormals) != 0; }
  bool hasColors() const { return (flags & kHasColors) != 0; }
  bool hasUvs() const { return (flags & kHasUvs) != 0; }
};
static_assert(sizeof(PackageHeader) == 512);

struct PackageObject {
  std::uint64_t vertexOffset = 0;      // into positions, normals, colors, ecol (vertices)
  std::uint64_t triangleOffset = 0;    // into triangles (triangles)
  std::uint64_t levelOffset = 0;       // into map and error (entries)
  std::uint32_t vertexCount = 0;       // p
  std::uint32_t minVertexCount = 0;    // q
  std::uint32_t triangleCount = 0;     // map(p)
  std::uint32_t minTriangleCount = 0;  // map(q)
  float boundsMin[3] = {0, 0, 0};      // relative to the origin
  float boundsMax[3] = {0, 0, 0};
  std::uint64_t nameOffset = 0;
  std::uint32_t nameLength = 0;
  Rgba8 color;  // the object's base colour
};
static_assert(sizeof(PackageObject) == 80);

// Where an object sits in its assembly and what it is made of (kept beside PackageObject so the
// runtime's hot table stays 80 bytes).
struct PackageAssembly {
  std::uint64_t pathOffset = 0;  // into names
  std::uint32_t pathLength = 0;
  std::uint32_t material = kNoMaterial;  // into materials
};
static_assert(sizeof(PackageAssembly) == 16);

// A Material as stored (glTF's metallic-roughness model; core/material.h).
struct PackageMaterial {
  float baseColor[4] = {1, 1, 1, 1};
  float emissive[3] = {0, 0, 0};
  float metallic = 0;
  float roughness = 0.5f;
  float alphaCutoff = 0.5f;
  std::uint32_t alphaMode = 0;  // AlphaMode
  std::uint8_t doubleSided = 0;
  std::uint8_t wrapS = 0, wrapT = 0;  // TextureWrap
  std::uint8_t reserved = 0;
  std::uint64_t nameOffset = 0;  // into names
  std::uint32_t nameLength = 0;
  std::uint32_t baseColorImage = kNoImage;  // into the images table
};
static_assert(sizeof(PackageMaterial) == 64);

// A texture image as stored: its encoded bytes in the images section after the table.
struct PackageImage {
  std::uint64_t dataOffset = 0;  // from the end of the table
  std::uint64_t dataBytes = 0;
  std::uint64_t nameOffset = 0;  // into names
  std::uint32_t nameLength = 0;
  std::uint32_t format = 0;  // ImageFormat
  std::uint32_t width = 0, height = 0, channels = 0;
  std::uint32_t reserved = 0;
};
static_assert(sizeof(PackageImage) == 48);

// A CAD layer's name as stored.
struct PackageLayer {
  std::uint64_t nameOffset = 0;  // into names
  std::uint32_t nameLength = 0;
  std::uint32_t reserved = 0;
};
static_assert(sizeof(PackageLayer) == 16);

// What the package says of an object besides its mesh.
struct PackageObjectInfo {
  std::string_view name = {};
  Rgba8 color = {};  // the object's base colour
  std::string_view path = {};
  std::uint32_t material = kNoMaterial;  // into the materials given to finish()
  std::uint32_t layer = kNoLayer;        // into the layers given to finish()
};

// Writes a package object by object, each section streamed to its own temporary file, then
// joined under a temporary name and renamed. Memory does not grow with the number of objects.
class PackageWriter {
 public:
  // `uvs`: a textured package (objects may then carry ProgressiveMesh::uvs and whole).
  static Result<PackageWriter> create(const std::string& path, Vec3d origin, bool normals,
                                      bool colors, bool uvs = false);
  PackageWriter(PackageWriter&&) noexcept;
  PackageWriter& operator=(PackageWriter&&) noexcept;
  ~PackageWriter();

  Status add(const ProgressiveMesh& mesh, const PackageObjectInfo& info);
  // `materials` and `layers` are what the objects' material and layer indices refer to, `images`
  // what the materials' textures refer to (a file's bytes are read here and stored).
  Status finish(std::span<const Material> materials = {}, std::span<const std::string> layers = {},
                std::span<const ImageSource> images = {});
  std::uint64_t objectCount() const;

 public:
  struct State;  // (its helpers in package.cpp take it)

 private:
  explicit PackageWriter(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// A package opened for reading, in place (mmap) or over caller-owned bytes. Every accessor is
// bounds-checked at open time, so the spans it returns are safe to follow.
struct PackageOpenOptions {
  // Section checksums cost one pass over the file; the structure and every index are checked
  // regardless.
  bool verifyChecksums = true;
};

class Package {
 public:
  using OpenOptions = PackageOpenOptions;
  static Result<Package> open(const std::string& path, const PackageOpenOptions& options = {});
  // The bytes must outlive the Package.
  static Result<Package> fromBytes(std::span<const std::byte> bytes, const std::string& name,
                                   const PackageOpenOptions& options = {});

  const PackageHeader& header() const { return *header_; }
  const std::string& name() const { return name_; }
  std::uint64_t objectCount() const { return header_->objectCount; }
  Vec3d origin() const { return {header_->origin[0], header_->origin[1], header_->origin[2]}; }
  std::uint64_t fileBytes() const { return bytes_.size(); }

  const PackageObject& object(std::size_t i) const { return objects()[i]; }
  std::string_view objectName(std::size_t i) const;
  std::string_view objectPath(std::size_t i) const;   // empty without an assembly tree
  std::uint32_t objectMaterial(std::size_t i) const;  // kNoMaterial or < materialCount()
  std::size_t materialCount() const;
  std::uint32_t objectLayerIndex(std::size_t i) const;  // kNoLayer or < layerCount()
  std::string_view objectLayer(std::size_t i) const;    // empty: on no layer
  std::size_t layerCount() const;
  std::string_view layer(std::size_t l) const;
  Material material(std::size_t m) const;
  std::span<const Vec3f> positions(std::size_t i) const;
  std::span<const Vec3f> normals(std::size_t i) const;  // empty without normals
  std::span<const Rgba8> colors(std::size_t i) const;   // empty without colors
  std::span<const Vec2f> uvs(std::size_t i) const;      // empty unless textured
  // The largest count <= n (q <= n <= p) that leaves no point half collapsed: the count to
  // re-form at (n itself in an untextured package).
  std::uint32_t wholeAt(std::size_t i, std::uint32_t n) const;
  std::size_t imageCount() const { return header_->imageCount; }
  // Image k with its encoded bytes embedded (name, format, size as stored).
  ImageSource image(std::size_t k) const;
  std::span<const std::uint32_t> triangles(std::size_t i) const;  // 3 x triangleCount
  std::span<const std::uint32_t> ecol(std::size_t i) const;
  std::span<const std::uint32_t> map(std::size_t i) const;  // p - q + 1
  std::span<const float> error(std::size_t i) const;        // p - q + 1
  std::uint32_t trianglesAt(std::size_t i, std::uint32_t n) const;

  // Whole sections, for kernels that work across objects.
  std::span<const PackageObject> objects() const;
  std::span<const Vec3f> allPositions() const;
  std::span<const Vec3f> allNormals() const;
  std::span<const Rgba8> allColors() const;
  std::span<const Vec2f> allUvs() const;
  std::span<const std::uint32_t> allTriangles() const;
  std::span<const std::uint32_t> allEcol() const;
  std::span<const std::uint32_t> allMap() const;    // every object's map, at its levelOffset
  std::span<const std::uint32_t> allWhole() const;  // likewise; empty unless textured
  std::uint64_t sectionBytes(PackageSection section) const {
    return header_->sections[static_cast<std::uint32_t>(section)].bytes;
  }

 private:
  Package() = default;
  Status validate(const OpenOptions& options);
  Status validateHeader();
  Status validateSections(const OpenOptions& options) const;
  Status validateObjects() const;
  // What breaks object i's invariants (ranges inside the sections, ECol chains, corners, Map and
  // the error table), empty when nothing does.
  std::string objectProblem(std::size_t i) const;
  std::string wholeProblem(std::size_t i) const;
  Status validateMaterials() const;
  Status validateLayers() const;
  Status validateImages() const;
  Status badAt(std::uint64_t at, std::string_view what) const;
  template <class T>
  std::span<const T> section(PackageSection s) const;

  std::string name_;
  std::shared_ptr<MappedFile> file_;
  std::span<const std::byte> bytes_;
  const PackageHeader* header_ = nullptr;
};

// Whether a file starts with the package magic (for `info` and format detection).
bool looksLikePackage(std::span<const std::byte> firstBytes);

}  // namespace lodforge
