#include "lodforge/generate/points.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/random.h"
#include "lodforge/generate/terrain.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/io/points/las_writer.h"

namespace lodforge {

namespace {
constexpr std::uint64_t kBatch = 1 << 15;       // points per independently seeded batch
constexpr std::uint64_t kBatchesPerRound = 32;  // batches computed in parallel, then written

constexpr double kStripWidth = 250.0;  // metres across one flight line
constexpr double kFlightSpeed = 60.0;  // metres per second along it

struct PointBatch {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<LasPoint3> lidar;   // for LAS output
  std::vector<std::byte> extras;  // generatedExtraBytes().stride a point, when asked for
};

// The extra bytes of a lidar point: height above ground by class (none known for noise), the
// echo's width (wider in vegetation), the range from the aircraft flying 1,000 m above the
// terrain's base, and the amplitude in dB from the intensity.
void lidarExtras(const LasPoint3& point, Vec3d ground, Random& random, std::byte* out) {
  static const PointExtras layout = generatedExtraBytes();
  double height = 0;
  switch (point.classification) {
    case 3:
      height = random.uniform(0.1, 0.5);
      break;
    case 4:
      height = random.uniform(0.5, 2);
      break;
    case 5:
      height = random.uniform(2, 25);
      break;
    default:
      height = random.uniform(0, 0.05);
  }
  const auto heightCm =
      static_cast<std::uint16_t>(point.classification == 7 ? 65535 : std::lround(height * 100));
  const auto echo = static_cast<std::uint8_t>(point.classification >= 3 && point.classification <= 5
                                                  ? random.uniform(40, 90)
                                                  : random.uniform(25, 35));
  const double range = 1000.0 - ground.z + random.uniform(-0.02, 0.02);
  const auto amplitude = static_cast<float>(20 * std::log10(1 + point.intensity / 655.35));
  std::memcpy(out + layout.fields[0].offset, &heightCm, 2);
  std::memcpy(out + layout.fields[1].offset, &echo, 1);
  std::memcpy(out + layout.fields[2].offset, &range, 8);
  std::memcpy(out + layout.fields[3].offset, &amplitude, 4);
}

// What an airborne scanner would record at a point: the ASPRS class (ground, low, medium and
// high vegetation where the surface is green, water in the lowest hollows, rare noise above),
// returns (vegetation gives several), an intensity by material and incidence, the flight line
// (point source), the time along it and the scan angle across it.
LasPoint3 lidarPoint(Vec3d p, Vec3d n, Rgba8 c, double u, double v, Random& random) {
  LasPoint3 point;
  point.position = p;
  const bool green = c.g > c.r + 15 && c.g > c.b + 15;
  double reflectance = 0.45;  // soil
  point.classification = 2;
  if (p.z < -30.0) {
    point.classification = 9;
    reflectance = 0.05;
  } else if (green) {
    const double draw = random.uniform(0, 1);
    point.classification = draw < 0.35 ? 2 : draw < 0.6 ? 3 : draw < 0.8 ? 4 : 5;
    point.numberOfReturns =
        static_cast<std::uint8_t>(point.classification == 2 ? 1 : 2 + (draw > 0.9));
    point.returnNumber = static_cast<std::uint8_t>(1 + random.below(point.numberOfReturns));
    reflectance = point.classification == 2 ? 0.4 : 0.3;
  } else if (c.r > 200) {
    reflectance = 0.9;  // snow
  } else if (n.z < 0.6) {
    reflectance = 0.55;  // rock
  }
  if (random.uniform(0, 1) < 0.001) {  // a bird or a dust return, well above the ground
    point.classification = 7;
    point.returnNumber = point.numberOfReturns = 1;
    point.position.z += random.uniform(20, 80);
    reflectance = 0.1;
  }
  const double shade = 0.3 + 0.7 * std::abs(n.z);
  point.intensity = static_cast<std::uint16_t>(
      std::clamp(65535.0 * reflectance * shade * random.uniform(0.85, 1.15), 0.0, 65535.0));
  const double strip = std::floor(u / kStripWidth);
  point.pointSource = static_cast<std::uint16_t>(1 + strip);
  point.gpsTime = 300000.0 + strip * 900.0 + v / kFlightSpeed + random.uniform(0, 1e-4);
  point.scanAngle =
      static_cast<std::int8_t>(std::lround(((u - strip * kStripWidth) / kStripWidth - 0.5) * 40.0));
  point.rgb = {static_cast<std::uint16_t>(c.r * 257), static_cast<std::uint16_t>(c.g * 257),
               static_cast<std::uint16_t>(c.b * 257)};
  return point;
}

void sampleBatch(const Terrain& terrain, const PointsOptions& options, std::uint64_t batch,
                 std::uint64_t count, bool lidar, PointBatch& out) {
  Random random = Random::forItem(options.seed, batch);
  Random attributes = Random::forItem(options.seed ^ 0x4C4153ull, batch);  // "LAS"
  Random extra = Random::forItem(options.seed ^ 0x455842ull, batch);       // "EXB"
  const std::size_t stride = lidar && options.extraBytes ? generatedExtraBytes().stride : 0;
  out.extras.clear();
  out.positions.clear();
  out.normals.clear();
  out.colors.clear();
  out.lidar.clear();
  while (out.positions.size() < count) {
    const double u = random.uniform(0, terrain.width());
    const double v = random.uniform(0, terrain.depth());
    const double jitter = random.uniform(-1, 1) * options.noise;
    if (terrain.inHole(u, v)) continue;  // the scanner saw nothing there
    const Vec3d n = terrain.normal(u, v);
    const Vec3d p = terrain.position(u, v) + n * jitter;
    const Rgba8 color = terrain.color(u, v, p, n);
    out.positions.push_back(toFloat(p));
    out.normals.push_back(toFloat(n));
    out.colors.push_back(color);
    if (!lidar) continue;
    out.lidar.push_back(lidarPoint(p, n, color, u, v, attributes));
    if (stride == 0) continue;
    out.extras.resize(out.extras.size() + stride);
    lidarExtras(out.lidar.back(), p, extra, out.extras.data() + out.extras.size() - stride);
  }
}

// Where the points go: a PLY (positions, normals, colours) or a LAS (format 3, lidar fields).
struct PointSink {
  std::optional<PlyWriter> ply;
  std::optional<LasWriter> las;
  Status write(const PointBatch& batch) {
    if (las) return las->write(batch.lidar, batch.extras);
    return ply->writeVertices(batch.positions, batch.normals, batch.colors);
  }
  std::uint64_t fileBytes() const { return las ? las->fileBytes() : ply->fileBytes(); }
  Status finish() { return las ? las->finish() : ply->finish(); }
};

Result<PointSink> openSink(const PointsOptions& options, const std::string& path) {
  PointSink sink;
  const std::string command =
      fmt::format("lodforge generate points --points {} --seed {}", options.points, options.seed);
  if (fileExtension(path) == "las") {
    // Millimetres: the terrain spans kilometres at most, far inside 32-bit integers.
    Result<LasWriter> las =
        LasWriter::create(path, {0.001, 0.001, 0.001}, {0, 0, 0}, "lodforge generate points",
                          options.extraBytes ? generatedExtraBytes() : PointExtras{});
    if (!las) return las.status();
    sink.las.emplace(std::move(*las));
    return sink;
  }
  PlyLayout layout;
  layout.vertexCount = options.points;
  layout.normals = true;
  layout.colors = true;
  layout.comments = {command};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();
  sink.ply.emplace(std::move(*writer));
  return sink;
}

}  // namespace

PointExtras generatedExtraBytes() {
  PointExtras extras;
  const auto add = [&](std::string name, std::string description, ExtraType type, double scale,
                       std::optional<double> noData) {
    extras.fields.push_back(
        {std::move(name), std::move(description), type, extras.stride, scale, 0, noData});
    extras.stride += static_cast<std::uint32_t>(extraTypeSize(type));
  };
  add("height_above_ground", "metres above the ground", ExtraType::kUint16, 0.01, 65535);
  add("echo_width", "pulse width, 0.1 ns", ExtraType::kUint8, 1, std::nullopt);
  add("range", "metres from the scanner", ExtraType::kFloat64, 1, std::nullopt);
  add("amplitude", "dB", ExtraType::kFloat32, 1, std::nullopt);
  return extras;
}

Result<GenerateStats> generatePoints(const PointsOptions& options, const std::string& path) {
  if (options.points == 0)
    return Error{ErrorKind::kUsage, "a point cloud needs at least one point"};
  const std::string ext = fileExtension(path);
  if (ext != "ply" && ext != "las")
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: the points generator writes .ply or .las", path)};
  if (options.extraBytes && ext != "las")
    return Error{ErrorKind::kUsage, fmt::format("{}: --extra-bytes needs a .las output", path)};
  const double depth = options.width * 2.0 / 3.0;
  const double spacing = std::sqrt(options.width * depth / static_cast<double>(options.points));
  const Terrain terrain(options.seed, options.width, depth, spacing);
  Result<PointSink> sink = openSink(options, path);
  if (!sink) return sink.status();
  const bool lidar = sink->las.has_value();

  const std::uint64_t batches = (options.points + kBatch - 1) / kBatch;
  std::vector<PointBatch> round(kBatchesPerRound);
  Progress progress("points", options.points);
  for (std::uint64_t first = 0; first < batches; first += kBatchesPerRound) {
    LODFORGE_TRY(checkCancelled());
    const std::uint64_t count = std::min(kBatchesPerRound, batches - first);
    tbb::parallel_for(std::uint64_t{0}, count, [&](std::uint64_t i) {
      const std::uint64_t batch = first + i;
      const std::uint64_t points = std::min(kBatch, options.points - batch * kBatch);
      sampleBatch(terrain, options, batch, points, lidar, round[i]);
    });
    for (std::uint64_t i = 0; i < count; ++i) {
      LODFORGE_TRY(sink->write(round[i]));
      progress.advance(round[i].positions.size());
    }
  }
  progress.finish();
  const std::uint64_t bytes = sink->fileBytes();
  LODFORGE_TRY(sink->finish());
  return GenerateStats{1, options.points, 0, bytes};
}

}  // namespace lodforge
