#include "lodforge/io/mesh/ply_strips.h"

#include <algorithm>

#include <fmt/format.h>

namespace lodforge {

namespace {

constexpr std::uint64_t kStripRun = 4096;  // binary strip indices read at once

// A strip restarts at index -1; in an unsigned index type that is the all-ones value, when it
// is no vertex's index.
bool isStripRestart(double raw, PlyType type, std::uint64_t vertexCount) {
  switch (type) {
    case PlyType::kUint8:
      return raw == 0xFF && raw >= static_cast<double>(vertexCount);
    case PlyType::kUint16:
      return raw == 0xFFFF && raw >= static_cast<double>(vertexCount);
    case PlyType::kUint32:
      return raw == 0xFFFF'FFFF && raw >= static_cast<double>(vertexCount);
    default:
      return raw == -1;
  }
}

}  // namespace

void PlyStrips::read(PlyBatch& batch) {
  const PlyElement& e = in_.header.elements[in_.element];
  const std::size_t limit = 3 * std::max<std::size_t>(in_.options.batchSize, 1);
  while (in_.elementDone < e.count && batch.triangles.size() < limit) {
    if (!strip_.open) begin(e);
    readIndices(e, batch, limit);
    if (strip_.left > 0) continue;
    // The properties after the index list, if any.
    for (std::size_t i = static_cast<std::size_t>(in_.roles.stripIndices) + 1;
         i < e.properties.size(); ++i)
      in_.skipProperty(e, e.properties[i]);
    strip_.open = false;
    ++in_.elementDone;
  }
}

void PlyStrips::begin(const PlyElement& e) {
  in_.beginElement();
  const auto list = static_cast<std::size_t>(in_.roles.stripIndices);
  for (std::size_t i = 0; i < list; ++i) in_.skipProperty(e, e.properties[i]);
  // Salvaging reads a strip up to where the file ends: its whole triangles are good.
  strip_ = {.open = true,
            .left = in_.readListCount(e, e.properties[list], !in_.options.salvageTruncated),
            .run = 0};
}

// Reads indices of the open strip until it ends or the batch holds `limit` corners.
void PlyStrips::readIndices(const PlyElement& e, PlyBatch& batch, std::size_t limit) {
  const PlyProperty& p = e.properties[static_cast<std::size_t>(in_.roles.stripIndices)];
  const std::size_t size = plyTypeSize(p.type);
  while (strip_.left > 0 && batch.triangles.size() < limit) {
    if (in_.header.format == PlyFormat::kAscii) {
      const double raw = in_.readNumber(e, p, p.type);
      --strip_.left;
      addIndex(raw, p.type, in_.lineNumber, batch);
      continue;
    }
    // Binary: a run of indices in one read, no more than can fill the batch (each index adds a
    // triangle at most).
    const std::uint64_t room = (limit - batch.triangles.size() + 2) / 3;
    const std::uint64_t n = std::min({strip_.left, kStripRun, room, in_.source.remaining() / size});
    if (n == 0) {
      in_.fileEnds(fmt::format("{} {}: file ends inside list '{}' ({} indices to go)", e.name,
                               in_.elementDone, p.name, strip_.left));
    }
    in_.cornerBytes.resize(n * size);
    if (!in_.source.read(in_.cornerBytes.data(), in_.cornerBytes.size()))
      in_.fail("cannot read a strip's indices");
    const std::uint64_t start = in_.source.offset() - n * size;
    for (std::uint64_t k = 0; k < n; ++k)
      addIndex(in_.decodeNumber(in_.cornerBytes.data() + k * size, p.type), p.type,
               start + k * size, batch);
    strip_.left -= n;
  }
}

// Triangle k of a run (since the strip began or restarted) is (i[k], i[k+1], i[k+2]), with the
// first two swapped for odd k so that all face the same way. Triangles with a repeated index
// are how strips join (and turn): they are dropped, but still count for k. `at` is the index's
// byte (binary) or line (ascii), for the error.
void PlyStrips::addIndex(double raw, PlyType type, std::uint64_t at, PlyBatch& batch) {
  if (isStripRestart(raw, type, in_.header.vertexCount)) {
    strip_.run = 0;
    return;
  }
  if (raw < 0 || raw >= static_cast<double>(in_.header.vertexCount)) {
    in_.elementStart = at;
    in_.fail(fmt::format("{} {}: vertex index {} out of range (the file has {} vertices)",
                         in_.header.elements[in_.element].name, in_.elementDone, raw,
                         in_.header.vertexCount));
  }
  const auto c = static_cast<std::uint32_t>(raw);
  if (strip_.run >= 2 && strip_.a != strip_.b && strip_.b != c && strip_.a != c) {
    if (strip_.run % 2 == 0)
      batch.triangles.insert(batch.triangles.end(), {strip_.a, strip_.b, c});
    else
      batch.triangles.insert(batch.triangles.end(), {strip_.b, strip_.a, c});
  }
  strip_.a = strip_.b;
  strip_.b = c;
  ++strip_.run;
}

std::uint64_t PlyStrips::countTriangles(PlyRecords& in) {
  PlyStrips strips(in);
  PlyBatch batch;
  std::uint64_t triangles = 0;
  try {
    for (; in.element < static_cast<std::size_t>(in.roles.stripElement); ++in.element) {
      in.elementDone = 0;
      in.skipElement(in.header.elements[in.element]);
    }
    in.elementDone = 0;
    while (in.elementDone < in.header.elements[in.element].count) {
      batch.triangles.clear();
      strips.read(batch);
      triangles += batch.triangles.size() / 3;
    }
  } catch (const PlyRecords::Truncated&) {
    triangles += batch.triangles.size() / 3;
  }
  return triangles;
}

}  // namespace lodforge
