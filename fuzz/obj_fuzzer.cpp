// The OBJ reader on any bytes; inputs whose first byte is a multiple of 4 are a material
// library instead (its map_Kd names, options and paths), read beside a fixed textured OBJ and
// a real PNG: either a consistent model (a texture that cannot be used is a warning) or a
// bad-input error naming the file. Inputs whose first byte is 1 modulo 4 go through the
// streamed chunking of `tiles` (tiling/chunk_obj) instead: chunks whose triangles are all
// there, or a bad-input error naming the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_check.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "lodforge/tiling/chunk_input.h"

namespace {

// A folder of this process with the OBJ and a PNG, made once.
const std::string& folder() {
  static const std::string path = [] {
    const std::string dir = (std::filesystem::temp_directory_path() /
                             ("lodforge-fuzz-mtl-" + std::to_string(::getpid())))
                                .string();
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/scene.obj") << "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                         "vt 0 0\nvt 1 0\nvt 1 1\nusemtl a\nf 1/1 2/2 3/3\n"
                                         "usemtl b\nf 1/1 3/3 2/2\n";
    lodforge::Image image(4, 4);
    auto png = lodforge::encodeImage(image, {.format = lodforge::ImageFormat::kPng});
    std::ofstream(dir + "/tex.png", std::ios::binary)
        .write(reinterpret_cast<const char*>(png->data()),
               static_cast<std::streamsize>(png->size()));
    return dir;
  }();
  return path;
}

void checkStreamed(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::string path = folder() + "/stream.obj";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  ChunkInputOptions options;
  options.workDirectory = folder() + "/work";
  options.keepInMemory = true;
  options.vertexCacheBytes = 1;
  const Result<ChunkInput> input = chunkInput(path, options);
  if (!input) {
    if (input.error().kind != ErrorKind::kBadInput ||
        input.error().message.find(path) == std::string::npos) {
      std::fprintf(stderr, "unexpected error: %s\n", input.error().message.c_str());
      std::abort();
    }
    return;
  }
  if (input->inputTriangles == 0 || input->bounds.empty()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  if (size > 0 && data[0] % 4 == 1) {
    checkStreamed(data, size);
    return 0;
  }
  if (size == 0 || data[0] % 4 != 0) {
    fuzz::check(readObjFromMemory(bytes, "fuzz.obj"), "fuzz.obj");
    return 0;
  }
  std::ofstream(folder() + "/scene.mtl", std::ios::binary)
      .write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  std::vector<std::string> warnings;
  const std::string path = folder() + "/scene.obj";
  fuzz::check(readObj(path, &warnings), path);
  return 0;
}
