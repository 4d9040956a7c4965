// PLY reader: ascii, binary little- and big-endian, any property order, every PLY scalar type,
// faces as lists of any count/index type (polygons fan-triangulated), triangle strips (a
// 'tristrips' element), optional per-face object ids. PlyReader streams: it yields batches of
// vertices or faces in file order, so a file larger than RAM is processed with a fixed amount of
// memory. readPly builds a whole Model. The header is ply_header.h; the data is read by
// ply_records (values, vertices, faces) and ply_strips, objects split by ply_objects.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/model.h"
#include "lodforge/core/status.h"
#include "lodforge/io/mesh/ply_header.h"

namespace lodforge {

// A run of elements by index: what one rank of a distributed job reads (docs/distributed.md).
struct PlySlice {
  std::uint64_t first = 0;
  std::uint64_t count = std::numeric_limits<std::uint64_t>::max();
  bool whole() const { return first == 0 && count == std::numeric_limits<std::uint64_t>::max(); }
};

struct PlyReadOptions {
  std::size_t batchSize = 1 << 16;  // elements per batch
  // A file that ends early is bad input. With this set, reading stops after the last complete
  // element instead and truncation() tells where the file was cut.
  bool salvageTruncated = false;
  // Which elements to deliver; the others are skipped (binary fixed-size ones by seeking).
  bool readVertices = true;
  bool readFaces = true;
  // End once the delivered elements are done instead of reading past the rest (a face list has
  // no fixed size to seek over: skipping a billion faces reads 13 GB). For a pass whose
  // partner pass reads, and checks, what follows.
  bool stopAfterDelivered = false;
  // Binary files only: deliver just these vertices or these faces, found by seeking, and end
  // after them. A face is found by its index as if every face before it had the first face's
  // size (its lists as long); a face of another size inside the slice, an ascii file, strips or
  // a vertex with a list fail as ErrorKind::kUnsupported (read the whole element then).
  PlySlice vertexSlice = {}, faceSlice = {};
  bool readExtras = false;  // deliver the vertices' other scalar properties (PlyBatch::extras)
  std::vector<std::string>* warnings = nullptr;  // readPly adds what it salvaged, if anything
  // Face properties recognised as an object (part) id, first match wins.
  std::vector<std::string> objectIdProperties = {"object_id", "objectid", "obj_id",
                                                 "part_id",   "object",   "part"};
};

struct PlyBatch {
  enum class Kind : std::uint8_t { kVertices, kFaces };
  Kind kind = Kind::kVertices;
  // Index of the batch's first vertex or face in the file, and how many the batch has (faces,
  // not triangles). Strips count as their triangles, numbered after the faces; a strip longer
  // than a batch goes on in the next one.
  std::uint64_t first = 0;
  std::uint64_t count = 0;
  // kVertices
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;     // when the header has nx ny nz
  std::vector<Rgba8> colors;      // when the header has red green blue
  std::vector<std::byte> extras;  // header.extras.stride bytes per vertex, with readExtras
  std::vector<Vec2f> uvs;         // when the header has vertex texture coordinates (glTF's way
                                  // up: v = 1 - t)
  // kFaces: 3 indices per triangle (polygons fan-triangulated, strips with every triangle facing
  // the way the first does), global vertex indices
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint32_t> triangleObjects;  // per triangle, when the header has object ids
  std::vector<Vec2f> cornerUvs;                // 3 per triangle, when faces have a 'texcoord' list
  // Per triangle, when faces have a 'texnumber' (~0u: -1 in the file, a face of no texture).
  std::vector<std::uint32_t> triangleTextures;
};

class PlyReader {
 public:
  static Result<PlyReader> open(const std::string& path, const PlyReadOptions& options = {});
  static Result<PlyReader> fromMemory(std::span<const std::byte> bytes, std::string name,
                                      const PlyReadOptions& options = {});
  PlyReader(PlyReader&&) noexcept;
  PlyReader& operator=(PlyReader&&) noexcept;
  ~PlyReader();

  const PlyHeader& header() const;
  // Where a salvaged file was cut short (after next() returned false); empty if it was whole.
  const std::optional<std::string>& truncation() const;
  std::uint64_t bytesAfterHeader() const;
  // Fills `batch` with the next vertices or faces; false when the file is done. Elements other
  // than vertex and face are skipped.
  Result<bool> next(PlyBatch& batch);

 private:
  struct State;
  explicit PlyReader(std::unique_ptr<State> state);
  static Result<PlyReader> start(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Reads a whole PLY into a Model: one object, or one per distinct object id when the faces carry
// one (vertices shared between objects are duplicated so each object is self-contained).
Result<Model> readPly(const std::string& path, const PlyReadOptions& options = {});
Result<Model> readPlyFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                const PlyReadOptions& options = {});

}  // namespace lodforge
