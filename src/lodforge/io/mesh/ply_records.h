// A PLY's element data, read value by value after its header (ply_header.h): ascii tokens or
// binary numbers in either byte order, lists checked against what the rest of the file can hold,
// binary elements of scalars read whole, a vertex or a face decoded into a batch. Errors name the
// element's line (ascii) or byte (binary); a file that ends early is an error or, when salvaging,
// where reading stops. What PlyReader reads with (ply_reader.cpp), strips too (ply_strips.h).
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/status.h"
#include "lodforge/io/mesh/ply_header.h"
#include "lodforge/io/mesh/ply_reader.h"

namespace lodforge {

struct PlyRecords {
  ByteSource source;
  PlyReadOptions options;
  PlyHeader header;
  PlyRoles roles;
  bool swap = false;              // binary data in the other byte order than this machine
  std::size_t element = 0;        // element being read
  std::uint64_t elementDone = 0;  // how many of it are read
  // ascii tokenizer
  std::string line;
  std::size_t linePos = 0;
  std::uint64_t lineNumber = 0;
  std::uint64_t elementStart = 0;  // byte or line where the current element began
  std::vector<double> values;      // scratch: scalar property values of one element

  explicit PlyRecords(ByteSource s) : source(std::move(s)) {}

  // The header, its counts checked against the file size when `checkCounts` (and not
  // salvaging), and the roles of its properties.
  void readHeader(bool checkCounts);

  [[noreturn]] void fail(std::string_view what) const { throw ErrorException{positioned(what)}; }
  Error positioned(std::string_view what) const;

  // The input stops early. An error, unless salvaging: then reading ends after the last
  // complete element and `truncation` says where.
  struct Truncated {};
  [[noreturn]] void fileEnds(std::string_view what);
  std::optional<std::string> truncation;
  std::size_t faceFirstCorner = 0;  // where the face being read began in batch.triangles

  // --- values ---------------------------------------------------------------------------------

  std::string_view nextToken(const PlyElement& e);
  double readNumber(const PlyElement& e, const PlyProperty& p, PlyType type);
  // A list's length, checked against what the rest of the file can hold (unless `mustFit` is
  // false: then the list is read up to where the file ends).
  std::uint64_t readListCount(const PlyElement& e, const PlyProperty& p, bool mustFit = true);
  void skipProperty(const PlyElement& e, const PlyProperty& p);
  void beginElement();

  // A binary element of scalar properties only has a fixed size: read whole, then decoded from
  // memory (one read per vertex instead of one per property). Empty: not fixed.
  std::vector<std::size_t> recordOffsets;  // per property
  int recordElement = -1;
  std::vector<std::byte> record;       // one element's bytes
  std::vector<std::byte> cornerBytes;  // a binary face's corners
  void planRecord(const PlyElement& e);
  template <class T>
  double decode(const std::byte* at) const {
    T value;
    std::memcpy(&value, at, sizeof value);
    if constexpr (sizeof(T) == 2) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap16(std::bit_cast<std::uint16_t>(value)));
    } else if constexpr (sizeof(T) == 4) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap32(std::bit_cast<std::uint32_t>(value)));
    } else if constexpr (sizeof(T) == 8) {
      if (swap) value = std::bit_cast<T>(__builtin_bswap64(std::bit_cast<std::uint64_t>(value)));
    }
    return static_cast<double>(value);
  }
  double decodeNumber(const std::byte* at, PlyType type) const {
    switch (type) {
      case PlyType::kInt8:
        return decode<std::int8_t>(at);
      case PlyType::kUint8:
        return decode<std::uint8_t>(at);
      case PlyType::kInt16:
        return decode<std::int16_t>(at);
      case PlyType::kUint16:
        return decode<std::uint16_t>(at);
      case PlyType::kInt32:
        return decode<std::int32_t>(at);
      case PlyType::kUint32:
        return decode<std::uint32_t>(at);
      case PlyType::kFloat32:
        return decode<float>(at);
      case PlyType::kFloat64:
        return decode<double>(at);
    }
    return 0;
  }

  // --- elements -------------------------------------------------------------------------------

  void readVertex(PlyBatch& batch);
  void readFace(PlyBatch& batch);
  std::vector<float> faceUvs;  // scratch: a face's 'texcoord' list (v turned to glTF's way)
  void readFaceTexcoords(const PlyElement& e, const PlyProperty& p);
  void addCornerUvs(PlyBatch& batch, std::uint64_t corners, std::size_t triangles);
  void skipElement(const PlyElement& e);

  // --- slices (PlyReadOptions::vertexSlice, faceSlice) ----------------------------------------

  // Seeks to the slice's first element of `e`, the current element, and sets `sliceEnd`.
  void enterSlice(const PlyElement& e, const PlySlice& slice, bool faces);
  // A face of the slice: the size every face must have, checked after each one is read.
  void checkSliceFace(std::uint64_t began) const;
  int sliceElement = -1;       // the element the slice is in (-1: none entered)
  std::uint64_t sliceEnd = 0;  // the element index where it ends
  std::uint64_t sliceFaceBytes = 0;
};

}  // namespace lodforge
