// `lodforge compare A.png B.png` or `lodforge compare A/ B/`: the large-meshes paper's image
// difference — CIE76 ΔE per pixel — as the share of pixels above the just-noticeable 2.3, the
// mean ΔE and PSNR; `--diff` writes a heat map (for folders, one per frame pair into a folder).
// Images are PNG, JPEG or WebP (by their bytes), so an encoded texture compares with its source;
// frames of two folders pair by name without the extension.
// Two meshes go to compare_meshes (surface distance).
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "compare_meshes.h"
#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/render/image.h"
#include "outputs.h"

namespace lodforge::cli {
namespace {

struct CompareOptions {
  std::string a, b;
  std::string diff;
  double threshold = kJustNoticeableDeltaE;
  std::string json;
  std::uint32_t samples = 200'000;  // meshes: sample points on each surface
};

struct Pair {
  std::string name, a, b;
};

bool isImageFile(const std::filesystem::path& path) {
  const std::string e = fileExtension(path.string());  // lower case
  return e == "png" || e == "jpg" || e == "jpeg" || e == "webp";
}

// The image of `folder` whose name without its extension is `stem`; empty if none.
std::filesystem::path imageNamed(const std::string& folder, const std::string& stem) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error))
    if (isImageFile(entry.path()) && entry.path().stem().string() == stem) return entry.path();
  return {};
}

Result<Image> readImageFile(const std::string& path) {
  auto file = MappedFile::open(path);
  if (!file) return file.status();
  return decodeImage(file->bytes(), path);
}

Result<std::vector<Pair>> pairsOf(const CompareOptions& o) {
  namespace fs = std::filesystem;
  std::error_code error;
  const bool folderA = fs::is_directory(o.a, error), folderB = fs::is_directory(o.b, error);
  if (folderA != folderB)
    return Error{
        ErrorKind::kUsage,
        fmt::format("compare two images or two folders of them, not '{}' and '{}'", o.a, o.b)};
  if (!folderA) return std::vector<Pair>{{fs::path(o.a).filename().string(), o.a, o.b}};
  // Frames pair up by file name; a frame missing on either side is an error, not a skip.
  std::vector<Pair> pairs;
  for (const auto& entry : fs::directory_iterator(o.a, error)) {
    if (!isImageFile(entry.path())) continue;
    const std::string name = entry.path().stem().string();
    if (std::any_of(pairs.begin(), pairs.end(), [&](const Pair& p) { return p.name == name; }))
      return Error{ErrorKind::kBadInput,
                   fmt::format("{}: two frames named '{}' (by name without the extension): "
                               "which to compare is ambiguous",
                               o.a, name)};
    const fs::path other = imageNamed(o.b, name);
    if (other.empty())
      return Error{ErrorKind::kBadInput, fmt::format("{}: no frame '{}' to compare with {}", o.b,
                                                     name, entry.path().string())};
    pairs.push_back({name, entry.path().string(), other.string()});
  }
  if (error) return Error{ErrorKind::kIo, fmt::format("{}: {}", o.a, error.message())};
  if (pairs.empty())
    return Error{ErrorKind::kBadInput, fmt::format("{}: no .png, .jpg or .webp frames", o.a)};
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& x, const Pair& y) { return x.name < y.name; });
  return pairs;
}

Status runCompare(const Global& global, const CompareOptions& o) {
  auto pairs = pairsOf(o);
  if (!pairs) return pairs.status();
  std::error_code error;
  const bool folders = pairs->size() > 1 || std::filesystem::is_directory(o.a, error);
  // Two folders: the heat maps must not go into either (they would replace its frames).
  for (const std::string& folder : {o.a, o.b}) {
    if (folders && !o.diff.empty() && std::filesystem::equivalent(o.diff, folder, error))
      return Error{ErrorKind::kUsage,
                   fmt::format("--diff {}: is an input folder; choose another", o.diff)};
  }
  const std::vector<std::string> inputs =
      folders ? std::vector<std::string>{} : std::vector<std::string>{o.a, o.b};
  LODFORGE_TRY(claimIfGiven(o.json, jsonOutput(), inputs));
  LODFORGE_TRY(claimIfGiven(o.diff, folders ? pngFolderOutput() : pngOutput(), inputs));
  if (!o.diff.empty() && folders) {
    std::filesystem::create_directories(o.diff, error);
    if (error) return ioError(o.diff, fmt::format("cannot create: {}", error.message()));
  }
  nlohmann::json frames = nlohmann::json::array();
  say(global, fmt::format("| {:<24} | {:>9} | {:>8} | {:>8} | {:>9} |", "frame",
                          fmt::format("ΔE>{:.1f}", o.threshold), "mean ΔE", "max ΔE", "PSNR dB"));
  say(global, "|--------------------------|-----------|----------|----------|-----------|");
  double shareSum = 0, meanSum = 0;
  for (const Pair& pair : *pairs) {
    auto a = readImageFile(pair.a);
    if (!a) return a.status();
    auto b = readImageFile(pair.b);
    if (!b) return b.status();
    if (a->width != b->width || a->height != b->height)
      return Error{ErrorKind::kBadInput,
                   fmt::format("{} is {}x{} but {} is {}x{}: images must have the same size",
                               pair.a, a->width, a->height, pair.b, b->width, b->height)};
    std::vector<float> deltaE;
    const ImageDifference d = compareImages(*a, *b, o.threshold, &deltaE);
    if (!o.diff.empty()) {
      const std::string out =
          folders ? (std::filesystem::path(o.diff) / (pair.name + ".png")).string() : o.diff;
      LODFORGE_TRY(writePng(out, deltaEHeatMap(deltaE, a->width, a->height)));
    }
    say(global,
        fmt::format("| {:<24} | {:>8.3f}% | {:>8.3f} | {:>8.2f} | {:>9} |", pair.name,
                    100 * d.shareAbove, d.meanDeltaE, d.maxDeltaE,
                    std::isinf(d.psnr) ? std::string("inf") : fmt::format("{:.2f}", d.psnr)));
    shareSum += d.shareAbove;
    meanSum += d.meanDeltaE;
    frames.push_back(
        {{"frame", pair.name},
         {"pixels", d.pixels},
         {"share_above", d.shareAbove},
         {"mean_delta_e", d.meanDeltaE},
         {"max_delta_e", d.maxDeltaE},
         {"psnr_db", std::isinf(d.psnr) ? nlohmann::json(nullptr) : nlohmann::json(d.psnr)}});
  }
  const double n = static_cast<double>(pairs->size());
  if (pairs->size() > 1)
    say(global, fmt::format("| {:<24} | {:>8.3f}% | {:>8.3f} | {:>8} | {:>9} |", "mean",
                            100 * shareSum / n, meanSum / n, "", ""));
  if (!o.json.empty()) {
    const nlohmann::json report = {{"threshold", o.threshold},
                                   {"frames", frames},
                                   {"mean_share_above", shareSum / n},
                                   {"mean_delta_e", meanSum / n}};
    auto file = OutputFile::create(o.json);
    if (!file) return file.status();
    const std::string text = report.dump(2) + "\n";
    LODFORGE_TRY(file->write(text.data(), text.size()));
    LODFORGE_TRY(file->commit());
  }
  return {};
}

}  // namespace

void addCompare(CLI::App& app, const Global& global, Run& run) {
  auto options = std::make_shared<CompareOptions>();
  auto* command = app.add_subcommand(
      "compare",
      "Image difference (CIE76 ΔE, PSNR) of two images (PNG, JPEG, WebP) or two folders of "
      "frames; surface distance (Hausdorff, RMS) of two meshes");
  command->add_option("a", options->a, "First image (or folder, or mesh)")->required();
  command->add_option("b", options->b, "Second image (or folder, or mesh)")->required();
  command
      ->add_option("--samples", options->samples,
                   "Meshes: points sampled on each surface (default 200K)")
      ->check(CLI::Range(1000, 100'000'000));
  command->add_option("--diff", options->diff, "Write a ΔE heat map PNG (a folder for folders)");
  command->add_option("--threshold", options->threshold, "ΔE counted as visible (default 2.3)")
      ->check(CLI::PositiveNumber);
  command->add_option("--json", options->json, "Write the figures as JSON");
  command->callback([&global, &run, options] {
    run = [&global, options] {
      if (isMeshComparison(options->a, options->b))
        return runCompareMeshes(global, options->a, options->b, options->samples, options->json);
      return runCompare(global, *options);
    };
  });
}

}  // namespace lodforge::cli
