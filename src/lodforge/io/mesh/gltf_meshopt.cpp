#include "lodforge/io/mesh/gltf_meshopt.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "lodforge/io/mesh/glb_container.h"
#include "lodforge/io/mesh/gltf_constants.h"

namespace lodforge {
namespace {

using Json = nlohmann::json;
constexpr const char* kExtension = "EXT_meshopt_compression";
// The most a GLB's BIN chunk can hold, less room for the JSON chunk (a 32-bit file length).
constexpr std::uint64_t kGlbBytes = std::uint64_t{0xffffffff} - (std::uint64_t{64} << 20);

// A non-negative integer member, or nothing.
std::optional<std::uint64_t> unsignedMember(const Json& object, const char* key) {
  if (!object.contains(key) || !object[key].is_number_unsigned()) return std::nullopt;
  return object[key].get<std::uint64_t>();
}

bool isCompressed(const Json& view) {
  return view.is_object() && view.contains("extensions") && view["extensions"].is_object() &&
         view["extensions"].contains(kExtension);
}

// One compressed view, as its extension object describes it.
struct CompressedView {
  std::uint64_t byteOffset = 0;  // in the BIN chunk
  std::uint64_t byteLength = 0;
  std::uint64_t byteStride = 0;
  std::uint64_t count = 0;
  std::string mode;
  std::string filter = "NONE";
};

Result<CompressedView> describe(const Json& extension, std::size_t view, const std::string& name) {
  const auto fail = [&](std::string_view what) {
    return badInput(name, fmt::format("bufferViews[{}].extensions.{}: {}", view, kExtension, what));
  };
  if (!extension.is_object()) return fail("not an object");
  CompressedView c;
  const std::optional<std::uint64_t> buffer = unsignedMember(extension, "buffer");
  const std::optional<std::uint64_t> offset = unsignedMember(extension, "byteOffset");
  const std::optional<std::uint64_t> length = unsignedMember(extension, "byteLength");
  const std::optional<std::uint64_t> stride = unsignedMember(extension, "byteStride");
  const std::optional<std::uint64_t> elements = unsignedMember(extension, "count");
  if (!buffer || !length || !stride || !elements || !extension.contains("mode") ||
      !extension["mode"].is_string())
    return fail("buffer, byteLength, byteStride, count and mode are required");
  if (*buffer != 0) return fail("compressed data outside the GLB's BIN chunk is not read");
  if (extension.contains("byteOffset") && !offset) return fail("byteOffset is not an offset");
  if (*length > std::numeric_limits<std::uint32_t>::max())
    return fail(fmt::format("byteLength {} is more than a GLB holds", *length));
  c.byteOffset = offset.value_or(0);
  c.byteLength = *length;
  c.byteStride = *stride;
  c.count = *elements;
  c.mode = extension["mode"].get<std::string>();
  if (extension.contains("filter")) {
    if (!extension["filter"].is_string()) return fail("filter is not a string");
    c.filter = extension["filter"].get<std::string>();
  }
  const bool attributes = c.mode == "ATTRIBUTES";
  if (!attributes && c.mode != "TRIANGLES" && c.mode != "INDICES")
    return fail(fmt::format("unknown mode \"{}\"", c.mode));
  if (attributes ? (c.byteStride == 0 || c.byteStride > 256 || c.byteStride % 4 != 0)
                 : (c.byteStride != 2 && c.byteStride != 4))
    return fail(fmt::format("byteStride {} for mode {}", c.byteStride, c.mode));
  if (c.mode == "TRIANGLES" && c.count % 3 != 0)
    return fail(fmt::format("{} indices are not whole triangles", c.count));
  const bool filterFits = c.filter == "NONE" ||
                          (c.filter == "OCTAHEDRAL" && (c.byteStride == 4 || c.byteStride == 8)) ||
                          (c.filter == "QUATERNION" && c.byteStride == 8) ||
                          (c.filter == "EXPONENTIAL" && c.byteStride % 4 == 0);
  if (!filterFits || (c.filter != "NONE" && !attributes))
    return fail(
        fmt::format("filter {} with mode {} and byteStride {}", c.filter, c.mode, c.byteStride));
  // Every codec spends at least a byte on 64 decoded ones (an all-zero group of 16 elements
  // still costs its 2 header bits per byte), so a larger count is a lie, not a big file.
  if (c.count > 64 * c.byteLength / c.byteStride)
    return fail(fmt::format("{} elements cannot come from {} bytes", c.count, c.byteLength));
  return c;
}

// The view around the extension describes the decoded data (the extension's MUSTs): its stride,
// where it has one, is the stream's, and its length is count × byteStride.
Status checkParent(const Json& view, const CompressedView& c, std::size_t v,
                   const std::string& name) {
  const std::optional<std::uint64_t> stride = unsignedMember(view, "byteStride");
  const std::optional<std::uint64_t> length = unsignedMember(view, "byteLength");
  if (view.contains("byteStride") && stride != c.byteStride)
    return badInput(name, fmt::format("bufferViews[{}]: byteStride {} but its {} stream's is {}", v,
                                      view["byteStride"].dump(), kExtension, c.byteStride));
  if (length != c.count * c.byteStride)
    return badInput(name, fmt::format("bufferViews[{}]: byteLength {} but its {} stream decodes "
                                      "to {} elements of {} bytes",
                                      v,
                                      view.contains("byteLength") ? view["byteLength"].dump()
                                                                  : std::string("missing"),
                                      kExtension, c.count, c.byteStride));
  return {};
}

// Decodes one view into `out` (count × byteStride bytes).
Status decode(const CompressedView& c, std::span<const std::byte> bin, std::uint64_t binOffset,
              const std::string& name, std::span<char> out) {
  if (c.byteOffset > bin.size() || c.byteLength > bin.size() - c.byteOffset)
    return badInputAtByte(name, binOffset + std::min<std::uint64_t>(c.byteOffset, bin.size()),
                          fmt::format("a compressed view of {} bytes at byte {} of the BIN chunk "
                                      "runs past its end",
                                      c.byteLength, c.byteOffset));
  const auto* source = reinterpret_cast<const unsigned char*>(bin.data() + c.byteOffset);
  int rc = 0;
  if (c.mode == "ATTRIBUTES")
    rc = meshopt_decodeVertexBuffer(out.data(), c.count, c.byteStride, source, c.byteLength);
  else if (c.mode == "TRIANGLES")
    rc = meshopt_decodeIndexBuffer(out.data(), c.count, c.byteStride, source, c.byteLength);
  else
    rc = meshopt_decodeIndexSequence(out.data(), c.count, c.byteStride, source, c.byteLength);
  if (rc != 0)
    return badInputAtByte(name, binOffset + c.byteOffset,
                          fmt::format("{} stream of {} elements does not decode (meshoptimizer: "
                                      "{})",
                                      c.mode, c.count, rc));
  if (c.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), c.count, c.byteStride);
  if (c.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), c.count, c.byteStride);
  if (c.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), c.count, c.byteStride);
  return {};
}

// Decodes every compressed view to the end of `bin` and points the view there (buffer 0).
Status decodeViews(Json& document, std::string& bin, std::span<const std::byte> original,
                   std::uint64_t binOffset, const std::string& name) {
  // Views may share compressed bytes; all of them together still decode to at most 64 times the
  // chunk (a stream's bound), so a file cannot make the reader allocate without end.
  std::uint64_t decodedBytes = 0;
  for (std::size_t v = 0; v < document["bufferViews"].size(); ++v) {
    Json& view = document["bufferViews"][v];
    if (!isCompressed(view)) continue;
    Result<CompressedView> c = describe(view["extensions"][kExtension], v, name);
    if (!c) return c.status();
    LODFORGE_TRY(checkParent(view, *c, v, name));
    decodedBytes += c->count * c->byteStride;
    if (decodedBytes > 64 * original.size())
      return badInput(name, fmt::format("bufferViews[{}]: the compressed views decode to more than "
                                        "64 times the BIN chunk's {} bytes",
                                        v, original.size()));
    if (bin.size() + c->count * c->byteStride > kGlbBytes)
      return Error{
          ErrorKind::kLimit,
          fmt::format("{}: bufferViews[{}]: decoded, the GLB would pass the 4 GiB GLB holds", name,
                      v)};
    // Straight into the chunk's tail: the decoders write every byte of it.
    const std::size_t at = (bin.size() + 3) / 4 * 4, bytes = c->count * c->byteStride;
    bin.resize(at + bytes);
    LODFORGE_TRY(decode(*c, original, binOffset, name, std::span(bin).subspan(at)));
    view["buffer"] = 0;
    view["byteOffset"] = at;
    view["byteLength"] = bytes;
    view["extensions"].erase(kExtension);
    if (view["extensions"].empty()) view.erase("extensions");
  }
  return {};
}

// Buffers no view uses any more (the fallbacks) go; the views' numbers follow. Buffer 0, the BIN
// chunk, stays. A view left on a buffer without data (a fallback, which only compressed views
// may name) is bad input: tinygltf would fill it from the BIN chunk, compressed bytes and all.
Status dropUnusedBuffers(Json& document, std::uint64_t binBytes, const std::string& name) {
  Json& buffers = document["buffers"];
  std::vector<bool> used(buffers.size(), false);
  if (!used.empty()) used[0] = true;
  for (std::size_t v = 0; v < document["bufferViews"].size(); ++v) {
    const std::optional<std::uint64_t> b = unsignedMember(document["bufferViews"][v], "buffer");
    if (!b || *b >= used.size()) continue;
    if (*b != 0 && !(buffers[*b].is_object() && buffers[*b].contains("uri")))
      return badInput(name, fmt::format("bufferViews[{}] reads buffer {}, which holds no data (a "
                                        "fallback for {} views)",
                                        v, *b, kExtension));
    used[*b] = true;
  }
  std::map<std::uint64_t, std::uint64_t> renumbered;
  Json kept = Json::array();
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    if (!used[b]) continue;
    renumbered[b] = kept.size();
    kept.push_back(buffers[b]);
  }
  kept[0]["byteLength"] = binBytes;
  buffers = std::move(kept);
  for (Json& view : document["bufferViews"])
    if (std::optional<std::uint64_t> b = unsignedMember(view, "buffer"); b && renumbered.count(*b))
      view["buffer"] = renumbered[*b];
  return {};
}

// The extension leaves the used and required lists once nothing is compressed.
void forgetExtension(Json& document) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (!document.contains(list) || !document[list].is_array()) continue;
    Json& names = document[list];
    names.erase(std::remove(names.begin(), names.end(), Json(kExtension)), names.end());
    if (names.empty()) document.erase(list);
  }
}

Result<std::string> glbOf(const Json& document, const std::string& bin, const std::string& name) {
  // decodeViews kept the chunk under kGlbBytes; glbWithJson checks the whole.
  const std::uint64_t binChunk = (bin.size() + 3) / 4 * 4;
  const std::array<std::uint32_t, 2> head = binChunkHead(binChunk);
  return glbWithJson(document.dump(),
                     {std::string_view(reinterpret_cast<const char*>(head.data()), sizeof head),
                      bin, std::string_view("\0\0\0", binChunk - bin.size())},
                     name);
}

}  // namespace

Result<std::optional<std::string>> withMeshoptDecoded(std::span<const std::byte> glb,
                                                      const std::string& name,
                                                      std::uint64_t binOffset,
                                                      std::uint64_t binLength) {
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  const std::string_view text(reinterpret_cast<const char*>(glb.data()) + 20, jsonLength);
  if (text.find(kExtension) == std::string_view::npos) return std::optional<std::string>();
  Json document = Json::parse(text, nullptr, false);
  if (document.is_discarded()) return badInputAtByte(name, 20, "the glTF JSON does not parse");
  if (!document.is_object() || !document.contains("bufferViews") ||
      !document["bufferViews"].is_array() || !document.contains("buffers") ||
      !document["buffers"].is_array() || document["buffers"].empty() ||
      !document["buffers"][0].is_object())
    return std::optional<std::string>();
  const Json& views = document["bufferViews"];
  if (std::none_of(views.begin(), views.end(), isCompressed)) return std::optional<std::string>();
  const Json& buffer0 = document["buffers"][0];
  if (buffer0.contains("uri"))
    return badInput(
        name, fmt::format("{} in a GLB whose buffer 0 is not its BIN chunk: not read", kExtension));
  // The reader's own check, made here before buffer 0 is given the decoded chunk's length.
  if (const std::optional<std::uint64_t> declared = unsignedMember(buffer0, "byteLength");
      declared && *declared > binLength)
    return badInputAtByte(
        name, binOffset - 8,
        fmt::format("buffer 0 declares {} bytes but the BIN chunk holds {}", *declared, binLength));
  const std::span<const std::byte> original =
      binLength == 0 ? std::span<const std::byte>() : glb.subspan(binOffset, binLength);
  std::string bin(reinterpret_cast<const char*>(original.data()), original.size());
  LODFORGE_TRY(decodeViews(document, bin, original, binOffset, name));
  LODFORGE_TRY(dropUnusedBuffers(document, bin.size(), name));
  forgetExtension(document);
  Result<std::string> out = glbOf(document, bin, name);
  if (!out) return out.status();
  return std::optional<std::string>(std::move(*out));
}

}  // namespace lodforge
