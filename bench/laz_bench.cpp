// LAZ decode throughput: every LAZ given (default: those in the data folder) read to its end
// through LasReader, with one thread and with all, beside the same points read as plain LAS
// (written first by the LAS copy). Prints a table; best of three runs each.
//   bench_laz [FILE.laz ...]
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "lodforge/io/points/las_copy.h"
#include "lodforge/io/points/las_reader.h"

namespace {

using namespace lodforge;

// Seconds to read every record of `path`, best of three; negative on an error.
double readSeconds(const std::string& path) {
  double best = 1e30;
  for (int run = 0; run < 3; ++run) {
    const auto start = std::chrono::steady_clock::now();
    Result<LasReader> reader = LasReader::open(path);
    if (!reader) {
      std::fprintf(stderr, "%s\n", reader.status().message().c_str());
      return -1;
    }
    std::vector<std::byte> records;
    while (true) {
      Result<bool> more = reader->nextRecords(records);
      if (!more) {
        std::fprintf(stderr, "%s\n", more.status().message().c_str());
        return -1;
      }
      if (!*more) break;
    }
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

double withThreads(std::size_t threads, const std::string& path) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  return readSeconds(path);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files(argv + 1, argv + argc);
  if (files.empty()) {
    for (const auto& entry : std::filesystem::directory_iterator(LODFORGE_DATA_DIR "/points"))
      if (entry.path().extension() == ".laz") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
  }
  const std::size_t cores = std::max(1u, std::thread::hardware_concurrency());
  std::printf(
      "| file | points | LAZ MiB | LAZ 1 thread Mpts/s | LAZ %zu threads Mpts/s | LAS Mpts/s | "
      "LAZ %zu threads / LAS time |\n|---|---:|---:|---:|---:|---:|---:|\n",
      cores, cores);
  const std::string las = (std::filesystem::temp_directory_path() / "bench_laz.las").string();
  for (const std::string& file : files) {
    Result<LasHeader> header = LasReader::readHeader(file);
    if (!header) {
      std::fprintf(stderr, "%s\n", header.status().message().c_str());
      return 1;
    }
    std::error_code ignored;
    std::filesystem::remove(las, ignored);
    Result<LasCopyReport> copied = writeUncompressedLas(file, las);
    if (!copied) {
      std::fprintf(stderr, "%s\n", copied.status().message().c_str());
      return 1;
    }
    const double one = withThreads(1, file), all = withThreads(cores, file);
    const double plain = withThreads(cores, las);
    if (one < 0 || all < 0 || plain < 0) return 1;
    const double points = static_cast<double>(header->pointCount) / 1e6;
    std::printf("| %s | %llu | %.1f | %.1f | %.1f | %.1f | %.2f |\n",
                std::filesystem::path(file).filename().c_str(),
                static_cast<unsigned long long>(header->pointCount),
                static_cast<double>(std::filesystem::file_size(file)) / (1 << 20), points / one,
                points / all, points / plain, all / plain);
    std::filesystem::remove(las, ignored);
  }
  return 0;
}
