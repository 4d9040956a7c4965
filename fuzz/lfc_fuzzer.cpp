// The point package reader on any bytes: either a bad-input error naming the file, or a package
// whose every block's Part II lies in the resident records with child links inside its segment.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "lodforge/points/cloud_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  // Packages are mapped page-aligned; give the reader the same alignment.
  std::vector<std::uint64_t> aligned(size / 8 + 1);
  std::memcpy(aligned.data(), data, size);
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(aligned.data()), size);
  Result<CloudFile> cloud = CloudFile::fromBytes(bytes, "fuzz.lfc");
  if (!cloud) {
    if (cloud.error().kind != ErrorKind::kBadInput ||
        cloud.error().message.rfind("fuzz.lfc", 0) != 0) {
      std::fprintf(stderr, "unexpected error: %s\n", cloud.error().message.c_str());
      std::abort();
    }
    return 0;
  }
  std::uint64_t resident = 0;
  for (std::size_t b = 0; b < cloud->blocks().size(); ++b) {
    for (const ClusterNode& n : cloud->residentOf(b)) {
      if (!n.leaf() && n.firstChild + std::size_t{1} >= cloud->blocks()[b].segmentCount)
        std::abort();
      resident += n.pointCount;
    }
  }
  (void)resident;
  return 0;
}
