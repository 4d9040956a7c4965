#include "lodforge/io/mesh/ply_reader.h"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/ply_objects.h"
#include "lodforge/io/mesh/ply_records.h"
#include "lodforge/io/mesh/ply_strips.h"
#include "lodforge/io/mesh/ply_textures.h"

namespace lodforge {

// The records, the strips read through them, and the batches handed out.
struct PlyReader::State {
  PlyRecords in;
  PlyStrips strips{in};
  std::optional<std::span<const std::byte>> memory;  // the bytes, when read from memory
  std::uint64_t stripTriangles = 0;                  // delivered so far

  explicit State(ByteSource s) : in(std::move(s)) {}
  bool next(PlyBatch& batch);
  // The next batch of the current element, vertices or faces; false when a slice of it is done.
  bool readElements(const PlyElement& e, bool isVertex, PlyBatch& batch);
};

namespace {

// Whether an element after `element` is one the options deliver.
bool deliversAfter(const PlyRecords& in, std::size_t element) {
  const auto after = [&](int role) {
    return role >= 0 && static_cast<std::size_t>(role) > element;
  };
  return (in.options.readVertices && after(in.roles.vertexElement)) ||
         (in.options.readFaces && (after(in.roles.faceElement) || after(in.roles.stripElement)));
}

}  // namespace

bool PlyReader::State::next(PlyBatch& batch) {
  batch.positions.clear();
  batch.normals.clear();
  batch.colors.clear();
  batch.extras.clear();
  batch.triangles.clear();
  batch.triangleObjects.clear();
  batch.uvs.clear();
  batch.cornerUvs.clear();
  batch.triangleTextures.clear();
  batch.count = 0;
  bool reading = false, readingStrips = false;
  try {
    while (in.element < in.header.elements.size()) {
      const PlyElement& e = in.header.elements[in.element];
      const bool isVertex =
          static_cast<int>(in.element) == in.roles.vertexElement && in.options.readVertices;
      const bool isFace =
          static_cast<int>(in.element) == in.roles.faceElement && in.options.readFaces;
      const bool isStrip =
          static_cast<int>(in.element) == in.roles.stripElement && in.options.readFaces;
      if (in.elementDone == e.count || (!isVertex && !isFace && !isStrip)) {
        if (in.options.stopAfterDelivered && !deliversAfter(in, in.element)) break;
        if (in.elementDone < e.count) in.skipElement(e);
        ++in.element;
        in.elementDone = 0;
        continue;
      }
      reading = true;
      if (isStrip) {
        // Numbered after the faces, so that faces and strips together count to faceCount.
        readingStrips = true;
        batch.kind = PlyBatch::Kind::kFaces;
        batch.first = stripTriangles;
        if (in.roles.faceElement >= 0)
          batch.first += in.header.elements[static_cast<std::size_t>(in.roles.faceElement)].count;
        strips.read(batch);
        batch.count = batch.triangles.size() / 3;
        stripTriangles += batch.count;
        if (batch.count > 0) return true;
        continue;  // the last strips were all degenerate
      }
      if (readElements(e, isVertex, batch)) return true;
      break;
    }
    return false;
  } catch (const PlyRecords::Truncated&) {
    // Salvaging: keep the complete elements of this batch, drop the one cut short, and stop.
    in.element = in.header.elements.size();
    if (!reading) return false;
    if (readingStrips) {  // every triangle read so far is whole
      batch.count = batch.triangles.size() / 3;
      stripTriangles += batch.count;
      return batch.count > 0;
    }
    if (batch.kind == PlyBatch::Kind::kFaces) batch.triangles.resize(in.faceFirstCorner);
    batch.count = in.elementDone - batch.first;
    return batch.count > 0;
  }
}

bool PlyReader::State::readElements(const PlyElement& e, bool isVertex, PlyBatch& batch) {
  const PlySlice& slice = isVertex ? in.options.vertexSlice : in.options.faceSlice;
  const bool sliced = !slice.whole();
  if (sliced && in.sliceElement != static_cast<int>(in.element)) in.enterSlice(e, slice, !isVertex);
  if (sliced && in.elementDone == in.sliceEnd) {
    in.element = in.header.elements.size();  // reading ends after a slice
    return false;
  }
  batch.kind = isVertex ? PlyBatch::Kind::kVertices : PlyBatch::Kind::kFaces;
  batch.first = in.elementDone;
  const std::uint64_t end = std::min<std::uint64_t>(sliced ? in.sliceEnd : e.count,
                                                    in.elementDone + in.options.batchSize);
  for (; in.elementDone < end; ++in.elementDone) {
    const std::uint64_t began = in.source.offset();
    if (isVertex) {
      in.readVertex(batch);
    } else {
      in.readFace(batch);
      if (sliced) in.checkSliceFace(began);
    }
  }
  batch.count = end - batch.first;
  return true;
}

// --- PlyReader --------------------------------------------------------------------------------

PlyReader::PlyReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
PlyReader::PlyReader(PlyReader&&) noexcept = default;
PlyReader& PlyReader::operator=(PlyReader&&) noexcept = default;
PlyReader::~PlyReader() = default;

std::uint64_t PlyReader::bytesAfterHeader() const {
  return state_->in.source.size() - state_->in.header.dataOffset;
}

Result<PlyReader> PlyReader::start(std::unique_ptr<State> state) {
  try {
    PlyRecords& in = state->in;
    in.readHeader(/*checkCounts=*/true);
    if (in.roles.stripElement >= 0) {
      // A second reader over the same bytes counts the strips' triangles; this one stays at the
      // start of the data.
      Result<ByteSource> source = state->memory
                                      ? ByteSource::fromMemory(*state->memory, in.source.name())
                                      : ByteSource::openFile(in.source.name());
      if (!source) return source.status();
      PlyRecords counter(std::move(source.value()));
      counter.options = in.options;
      counter.readHeader(/*checkCounts=*/false);
      in.header.faceCount += PlyStrips::countTriangles(counter);
    }
  } catch (const ErrorException& e) {
    return e.error;
  }
  return PlyReader(std::move(state));
}

Result<PlyReader> PlyReader::open(const std::string& path, const PlyReadOptions& options) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  auto state = std::make_unique<State>(std::move(source.value()));
  state->in.options = options;
  return start(std::move(state));
}

Result<PlyReader> PlyReader::fromMemory(std::span<const std::byte> bytes, std::string name,
                                        const PlyReadOptions& options) {
  auto state = std::make_unique<State>(ByteSource::fromMemory(bytes, std::move(name)));
  state->memory = bytes;
  state->in.options = options;
  return start(std::move(state));
}

const PlyHeader& PlyReader::header() const {
  return state_->in.header;
}

const std::optional<std::string>& PlyReader::truncation() const {
  return state_->in.truncation;
}

Result<bool> PlyReader::next(PlyBatch& batch) {
  try {
    return state_->next(batch);
  } catch (const ErrorException& e) {
    return e.error;
  }
}

// --- readPly ----------------------------------------------------------------------------------

namespace {

// What a whole read gathers, before it becomes a model.
struct Gathered {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<Vec2f> uvs, cornerUvs;
  std::vector<std::uint32_t> triangles, triangleObjects, triangleTextures;
};

template <class T>
void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

Status gather(PlyReader& reader, const std::string& name, Model& model, Gathered& g) {
  const PlyHeader& header = reader.header();
  // Counts were checked against the file size, except when salvaging: bound them here too.
  const std::uint64_t dataBytes = reader.bytesAfterHeader();
  const std::uint64_t vertexGuess =
      std::min(header.vertexCount, dataBytes / 3 + 1);  // 3 x int8 at least
  g.positions.reserve(vertexGuess);
  if (header.hasNormals) g.normals.reserve(vertexGuess);
  if (header.hasColors) g.colors.reserve(vertexGuess);
  g.triangles.reserve(3 * std::min(header.faceCount, dataBytes / 4 + 1));
  bool originChosen = false;
  PlyBatch batch;
  Progress progress("reading " + std::filesystem::path(name).filename().string(),
                    header.vertexCount + header.faceCount);
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader.next(batch);
    if (!more) return more.status();
    if (!*more) break;
    if (batch.kind == PlyBatch::Kind::kVertices) {
      if (!originChosen && !batch.positions.empty()) {
        // Streaming cannot see the bounds first; the first vertex stands for them.
        Aabbd first;
        first.add(batch.positions.front());
        model.origin = chooseOrigin(first);
        originChosen = true;
      }
      for (const Vec3d& p : batch.positions) g.positions.push_back(toFloat(p - model.origin));
      append(g.normals, batch.normals);
      append(g.colors, batch.colors);
      append(g.uvs, batch.uvs);
    } else {
      append(g.triangles, batch.triangles);
      append(g.triangleObjects, batch.triangleObjects);
      append(g.cornerUvs, batch.cornerUvs);
      append(g.triangleTextures, batch.triangleTextures);
    }
    progress.advance(batch.count);
  }
  progress.finish();
  return {};
}

// Salvaged: faces that come before a cut-short vertex list may name missing vertices.
void dropMissingVertices(Gathered& g) {
  std::size_t kept = 0;
  for (std::size_t t = 0; t < g.triangles.size() / 3; ++t) {
    if (std::max({g.triangles[3 * t], g.triangles[3 * t + 1], g.triangles[3 * t + 2]}) >=
        g.positions.size())
      continue;
    std::copy_n(&g.triangles[3 * t], 3, &g.triangles[3 * kept]);
    if (!g.triangleObjects.empty()) g.triangleObjects[kept] = g.triangleObjects[t];
    if (!g.triangleTextures.empty()) g.triangleTextures[kept] = g.triangleTextures[t];
    if (!g.cornerUvs.empty()) std::copy_n(&g.cornerUvs[3 * t], 3, &g.cornerUvs[3 * kept]);
    ++kept;
  }
  g.triangles.resize(3 * kept);
  if (!g.triangleObjects.empty()) g.triangleObjects.resize(kept);
  if (!g.triangleTextures.empty()) g.triangleTextures.resize(kept);
  if (!g.cornerUvs.empty()) g.cornerUvs.resize(3 * kept);
}

Result<Model> readAll(PlyReader& reader, const std::string& name,
                      std::vector<std::string>* warnings) {
  const PlyHeader& header = reader.header();
  if (std::optional<std::string> unread = unreadPlyElements(header, name); unread && warnings)
    warnings->push_back(std::move(*unread));
  Model model;
  Gathered g;
  LODFORGE_TRY(gather(reader, name, model, g));
  if (reader.truncation()) {
    if (warnings) warnings->push_back(*reader.truncation() + "; kept what came before");
    dropMissingVertices(g);
  }
  if (plyTextured(header)) {
    LODFORGE_TRY(addTexturedPly(model,
                                {g.positions, g.normals, g.colors, g.uvs, g.triangles, g.cornerUvs,
                                 g.triangleTextures, g.triangleObjects},
                                readPlyTextures(header, name, warnings), name));
    return model;
  }
  if ((header.hasUvs || header.hasFaceUvs) && warnings)
    warnings->push_back(
        fmt::format("{}: texture coordinates but no texture (no 'comment "
                    "TextureFile' line): drawn without one",
                    name));
  if (header.hasObjectIds) {
    splitPlyObjects(model, g.positions, g.normals, g.colors, g.triangles, g.triangleObjects);
    return model;
  }
  ModelBuilder builder(model);
  builder.beginObject(fileStem(name));
  model.positions = std::move(g.positions);
  model.normals = std::move(g.normals);
  model.colors = std::move(g.colors);
  model.indices = std::move(g.triangles);
  builder.endObject();
  return model;
}

}  // namespace

Result<Model> readPly(const std::string& path, const PlyReadOptions& options) {
  Result<PlyReader> reader = PlyReader::open(path, options);
  if (!reader) return reader.status();
  return readAll(*reader, path, options.warnings);
}

Result<Model> readPlyFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                const PlyReadOptions& options) {
  Result<PlyReader> reader = PlyReader::fromMemory(bytes, name, options);
  if (!reader) return reader.status();
  return readAll(*reader, name, options.warnings);
}

}  // namespace lodforge
