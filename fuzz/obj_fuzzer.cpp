// The OBJ reader on any bytes; inputs whose first byte is a multiple of 4 are a material
// library instead (its map_Kd names, options and paths), read beside a fixed textured OBJ and
// a real PNG: either a consistent model (a texture that cannot be used is a warning) or a
// bad-input error naming the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_check.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/obj_reader.h"

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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
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
