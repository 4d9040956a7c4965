// The OpenCASCADE wrapper on short inputs: the bytes as a STEP, IGES or BREP file (chosen by the
// first byte), read through readCad. OCCT reads files only, so each input goes to a temporary file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "fuzz_check.h"
#include "lodforge/io/cad/cad_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {"step", "iges", "brep"};
  // In TMPDIR (scripts/fuzz.sh gives each run a folder of its own and removes it: a fork-mode
  // job stopped at the time limit leaves its file behind).
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("lodforge-fuzz-cad-" + std::to_string(getpid()) + "." + kExtensions[data[0] % 3]))
          .string();
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) std::abort();
  if (size > 1 && std::fwrite(data + 1, 1, size - 1, file) != size - 1) std::abort();
  std::fclose(file);
  fuzz::check(readCad(path), path);
  std::remove(path.c_str());
  return 0;
}
