#include "lodforge/io/mesh/stl_reader.h"

#include <charconv>
#include <cstring>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"

namespace lodforge {

namespace {

constexpr std::uint64_t kBinaryHeader = 84;
constexpr std::uint64_t kBinaryTriangle = 50;

// Turns one object's triangle soup (3 positions per triangle) into an indexed mesh.
void appendWelded(Model& model, ModelBuilder& builder, std::string_view name,
                  const std::vector<Vec3f>& soup) {
  builder.beginObject(name);
  std::vector<std::uint32_t> remap(soup.size());
  const std::uint32_t unique = weldVertices(soup, {}, {}, WeldOptions{}, remap);
  const std::size_t base = model.positions.size();
  model.positions.resize(base + unique);
  remapVertexAttribute<Vec3f>(soup, remap, std::span(model.positions).subspan(base));
  model.indices.insert(model.indices.end(), remap.begin(), remap.end());
  builder.endObject();
}

Model readBinary(ByteSource& source) {
  std::uint32_t count = 0;
  source.skip(80);
  source.read(&count, 4);
  std::vector<Vec3f> soup;
  soup.reserve(3 * std::size_t{count});  // the caller checked the size matches
  for (std::uint32_t t = 0; t < count; ++t) {
    std::byte record[kBinaryTriangle];
    const std::uint64_t at = source.offset();
    if (!source.read(record, sizeof record)) {
      throw ErrorException{
          badInputAtByte(source.name(), at, fmt::format("triangle {}: file ends early", t))};
    }
    for (int k = 0; k < 3; ++k) {
      Vec3f p;
      std::memcpy(&p, record + 12 + 12 * k, 12);
      if (!isFinite(p)) {
        throw ErrorException{
            badInputAtByte(source.name(), at + 12 + 12 * static_cast<unsigned>(k),
                           fmt::format("triangle {}: coordinate is not finite", t))};
      }
      soup.push_back(p);
    }
  }
  Model model;
  ModelBuilder builder(model);
  appendWelded(model, builder, fileStem(source.name()), soup);
  return model;
}

class AsciiStl {
 public:
  explicit AsciiStl(ByteSource& source) : source_(source) {}

  Model read() {
    Model model;
    ModelBuilder builder(model);
    std::vector<Vec3f> soup;
    while (true) {
      const std::string_view keyword = token();
      if (keyword.empty()) break;
      if (keyword != "solid") fail(fmt::format("expected 'solid', found '{}'", clip(keyword)));
      std::string name = restOfLine();
      if (name.empty()) name = fileStem(source_.name());
      soup.clear();
      readFacets(soup);
      appendWelded(model, builder, name, soup);
    }
    if (model.objects.empty()) fail("no 'solid' in the file");
    return model;
  }

 private:
  static std::string_view clip(std::string_view s) { return s.substr(0, 40); }

  [[noreturn]] void fail(std::string_view what) {
    throw ErrorException{badInputAtLine(source_.name(), lineNumber_, what)};
  }

  // Next whitespace-separated word; empty at end of input.
  std::string_view token() {
    while (true) {
      while (pos_ < line_.size() && std::isspace(static_cast<unsigned char>(line_[pos_]))) ++pos_;
      if (pos_ < line_.size()) break;
      if (!source_.readLine(line_, 1 << 16)) return {};
      ++lineNumber_;
      pos_ = 0;
    }
    const std::size_t start = pos_;
    while (pos_ < line_.size() && !std::isspace(static_cast<unsigned char>(line_[pos_]))) ++pos_;
    return std::string_view(line_).substr(start, pos_ - start);
  }
  std::string restOfLine() {
    std::string rest = line_.substr(std::min(pos_, line_.size()));
    pos_ = line_.size();
    const auto first = rest.find_first_not_of(" \t");
    const auto last = rest.find_last_not_of(" \t\r");
    return first == std::string::npos ? std::string() : rest.substr(first, last - first + 1);
  }
  void expect(std::string_view word) {
    const std::string_view got = token();
    if (got != word) {
      fail(got.empty() ? fmt::format("file ends where '{}' was expected", word)
                       : fmt::format("expected '{}', found '{}'", word, clip(got)));
    }
  }
  float number() {
    const std::string_view t = token();
    if (t.empty()) fail("file ends where a number was expected");
    float value = 0;
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (error != std::errc() || end != t.data() + t.size())
      fail(fmt::format("expected a number, found '{}'", clip(t)));
    if (!std::isfinite(value)) fail(fmt::format("coordinate is not finite ('{}')", clip(t)));
    return value;
  }

  void readFacets(std::vector<Vec3f>& soup) {
    while (true) {
      const std::string_view keyword = token();
      if (keyword == "endsolid") {
        restOfLine();
        return;
      }
      if (keyword.empty()) fail("file ends inside a solid (no 'endsolid')");
      if (keyword != "facet")
        fail(fmt::format("expected 'facet' or 'endsolid', found '{}'", clip(keyword)));
      expect("normal");
      for (int k = 0; k < 3; ++k) number();  // facet normals are recomputed, not trusted
      expect("outer");
      expect("loop");
      for (int k = 0; k < 3; ++k) {
        expect("vertex");
        const float x = number(), y = number(), z = number();
        soup.push_back({x, y, z});
      }
      expect("endloop");
      expect("endfacet");
    }
  }

  ByteSource& source_;
  std::string line_;
  std::size_t pos_ = 0;
  std::uint64_t lineNumber_ = 0;
};

Result<Model> readSource(ByteSource& source) {
  try {
    const std::uint64_t size = source.size();
    std::uint32_t declared = 0;
    bool binary = false;
    if (size >= kBinaryHeader && source.ensure(kBinaryHeader) == kBinaryHeader) {
      std::memcpy(&declared, source.data() + 80, 4);
      binary = size == kBinaryHeader + kBinaryTriangle * std::uint64_t{declared};
    }
    if (binary) return readBinary(source);
    // Not a consistent binary file: ascii if it says "solid", otherwise a broken binary one.
    // What it holds now (a file cut short since its size was read holds less than `size`).
    const std::size_t held = source.ensure(512);
    const std::string_view start(reinterpret_cast<const char*>(source.data()),
                                 std::min<std::uint64_t>(size, held));
    const auto first = start.find_first_not_of(" \t\r\n");
    if (first != std::string_view::npos && start.substr(first).starts_with("solid")) {
      AsciiStl ascii(source);
      return ascii.read();
    }
    if (size < kBinaryHeader) {
      return badInputAtByte(source.name(), size,
                            "not an STL file: too short for a binary header and not ascii");
    }
    return badInputAtByte(
        source.name(), 80,
        fmt::format("binary STL declares {} triangles ({} bytes) but the file has "
                    "{} bytes",
                    declared, kBinaryHeader + kBinaryTriangle * std::uint64_t{declared}, size));
  } catch (const ErrorException& e) {
    return e.error;
  }
}

}  // namespace

Result<Model> readStl(const std::string& path) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  return readSource(*source);
}

Result<Model> readStlFromMemory(std::span<const std::byte> bytes, const std::string& name) {
  ByteSource source = ByteSource::fromMemory(bytes, name);
  return readSource(source);
}

}  // namespace lodforge
