#include "lodforge/generate/cad.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include <memory>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/random.h"
#include "lodforge/generate/shapes.h"
#include "lodforge/io/cad/cad_writer.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/ply_writer.h"

namespace lodforge {

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kFuselageLength = 64.0;  // metres, about a 777-200
constexpr double kFuselageRadius = 3.1;
constexpr double kWingSpan = 30.0;  // half span
constexpr int kBoltCatalogue = 24;  // standard bolt sizes, instanced in GLB output

enum class Kind : std::uint8_t { kBolt, kTube, kBox, kBracket, kPlate, kBeam, kRod };
constexpr const char* kKindNames[] = {"bolt", "tube", "box", "bracket", "plate", "beam", "rod"};
// The CAD layer each kind is drawn on in STEP output.
constexpr const char* kKindLayers[] = {"fasteners",   "tubing",    "housings", "brackets",
                                       "sheet metal", "structure", "rods"};
// Parts per sub-assembly in STEP output: real assemblies are trees, and OCCT's STEP reader is
// quadratic in the children of one product (STEPConstruct_Assembly::CheckSRRReversesNAUO).
constexpr std::uint64_t kStepGroupSize = 100;

struct Finish {
  const char* name;
  std::array<float, 4> color;  // linear RGBA
};
constexpr Finish kFinishes[] = {
    {"aluminium", {0.75f, 0.76f, 0.78f, 1}},  {"steel", {0.42f, 0.43f, 0.45f, 1}},
    {"primer", {0.42f, 0.58f, 0.32f, 1}},     {"composite", {0.72f, 0.62f, 0.45f, 1}},
    {"titanium", {0.55f, 0.55f, 0.60f, 1}},   {"wire", {0.70f, 0.14f, 0.10f, 1}},
    {"insulation", {0.86f, 0.74f, 0.25f, 1}}, {"duct", {0.30f, 0.45f, 0.70f, 1}},
    {"rubber", {0.08f, 0.08f, 0.08f, 1}},     {"panel", {0.90f, 0.90f, 0.88f, 1}},
    {"copper", {0.72f, 0.45f, 0.20f, 1}},     {"safety", {0.90f, 0.45f, 0.10f, 1}}};
constexpr int kFinishCount = static_cast<int>(std::size(kFinishes));

// Everything about one part, decided from the seed and its index alone.
struct PartPlan {
  Kind kind = Kind::kBox;
  int finish = 0;
  int bolt = -1;  // catalogue entry for bolts
  std::uint64_t shapeSeed = 0;
  Mat4d transform;  // part to assembly
};

int pick(Random& random, std::initializer_list<int> choices) {
  return *(choices.begin() + static_cast<std::ptrdiff_t>(random.below(choices.size())));
}

int segmentsFor(Random& random, double radius, double detail, int lo, int hi) {
  // Bigger parts get more segments, as a chordal tolerance would give them, with scatter.
  const double wanted = detail * random.uniform(0.6, 1.6) * (8.0 + 60.0 * std::sqrt(radius / 0.3));
  return std::clamp(static_cast<int>(wanted), lo, hi);
}

// Rotation taking local z to `axis` (unit), spun by `spin` around it.
Mat4d alignZ(Vec3d axis, double spin) {
  const Vec3d helper = std::abs(axis.z) < 0.9 ? Vec3d{0, 0, 1} : Vec3d{1, 0, 0};
  const Vec3d x0 = normalizeOr(cross(helper, axis), Vec3d{1, 0, 0});
  const Vec3d y0 = cross(axis, x0);
  const Vec3d x = x0 * std::cos(spin) + y0 * std::sin(spin);
  const Vec3d y = cross(axis, x);
  Mat4d m;
  for (int r = 0; r < 3; ++r) {
    m.at(r, 0) = x[r];
    m.at(r, 1) = y[r];
    m.at(r, 2) = axis[r];
  }
  return m;
}

Mat4d randomRotation(Random& random) {
  // Uniform random unit quaternion (Shoemake).
  const double u1 = random.uniform(), u2 = random.uniform() * 2 * kPi,
               u3 = random.uniform() * 2 * kPi;
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return Mat4d::rotation(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3));
}

bool isLong(Kind kind) {
  return kind == Kind::kBeam || kind == Kind::kRod || kind == Kind::kTube;
}

PartPlan planPart(std::uint64_t seed, std::uint64_t index) {
  Random random = Random::forItem(seed, index);
  PartPlan plan;
  const double k = random.uniform();
  plan.kind = k < 0.30   ? Kind::kBolt
              : k < 0.42 ? Kind::kTube
              : k < 0.54 ? Kind::kBox
              : k < 0.68 ? Kind::kBracket
              : k < 0.80 ? Kind::kPlate
              : k < 0.90 ? Kind::kBeam
                         : Kind::kRod;
  switch (plan.kind) {
    case Kind::kBolt:
      plan.finish = pick(random, {1, 4});
      break;
    case Kind::kTube:
      plan.finish = pick(random, {7, 0, 10});
      break;
    case Kind::kBox:
      plan.finish = pick(random, {1, 9, 8, 11, 0});
      break;
    case Kind::kBracket:
      plan.finish = pick(random, {2, 0});
      break;
    case Kind::kPlate:
      plan.finish = pick(random, {0, 3, 9});
      break;
    case Kind::kBeam:
      plan.finish = pick(random, {0, 2});
      break;
    case Kind::kRod:
      plan.finish = pick(random, {5, 6, 8});
      break;
  }
  if (plan.kind == Kind::kBolt) plan.bolt = static_cast<int>(random.below(kBoltCatalogue));
  plan.shapeSeed = random.next();

  // Placement: skin frames and stringers, floor, cabin volume, wings.
  const double zone = random.uniform();
  Mat4d rotation;
  Vec3d position;
  if (zone < 0.45) {
    double x = random.uniform(0, kFuselageLength);
    if (random.uniform() < 0.5) x = std::round(x / 0.5) * 0.5;  // frames every half metre
    const double angle = random.uniform(0, 2 * kPi);
    const double radius = kFuselageRadius - random.uniform(0, 0.25);
    const Vec3d radial{0, std::cos(angle), std::sin(angle)};
    const Vec3d tangent{0, -std::sin(angle), std::cos(angle)};
    position = Vec3d{x, 0, 0} + radial * radius;
    if (isLong(plan.kind))
      rotation =
          alignZ(random.uniform() < 0.5 ? Vec3d{1, 0, 0} : tangent, random.uniform(0, 2 * kPi));
    else
      rotation = alignZ(radial, random.uniform(0, 2 * kPi));
  } else if (zone < 0.60) {
    position = {random.uniform(2, kFuselageLength - 2), random.uniform(-2.8, 2.8),
                -0.9 + random.uniform(0, 0.1)};
    const double quarterTurns = static_cast<double>(random.below(4));  // floor parts sit square
    rotation = isLong(plan.kind)
                   ? alignZ(random.uniform() < 0.5 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, 0)
                   : Mat4d::rotation(0, 0, std::sin(kPi / 4 * quarterTurns),
                                     std::cos(kPi / 4 * quarterTurns));
  } else if (zone < 0.85) {
    const double r = kFuselageRadius * 0.93 * std::sqrt(random.uniform()),
                 a = random.uniform(0, 2 * kPi);
    position = {random.uniform(0, kFuselageLength), r * std::cos(a), r * std::sin(a)};
    rotation = randomRotation(random);
  } else {
    const double span =
        random.uniform(kFuselageRadius, kWingSpan) * (random.uniform() < 0.5 ? -1 : 1);
    const double chord = 10.0 * (1.0 - 0.7 * std::abs(span) / kWingSpan);
    position = {26.0 + 0.3 * std::abs(span) + random.uniform(0, chord), span,
                -1.6 + 0.08 * std::abs(span) + random.uniform(-0.3, 0.3) * chord / 10.0};
    rotation = isLong(plan.kind)
                   ? alignZ(Vec3d{0, span > 0 ? 1.0 : -1.0, 0}, random.uniform(0, 2 * kPi))
                   : alignZ(Vec3d{0, 0, 1}, random.uniform(0, 2 * kPi));
  }
  plan.transform = Mat4d::translation(position) * rotation;
  return plan;
}

// A catalogue bolt's dimensions, drawn from its entry: what both its mesh and its B-rep are made
// of. A hexagonal head on a round shaft.
struct BoltDims {
  float shaft = 0, length = 0, headHeight = 0;
  std::array<Vec2f, 6> hexagon;
  int segments = 6;
};

BoltDims drawBolt(int entry, std::uint64_t seed, double detail) {
  Random random = Random::forItem(seed ^ 0xB017ull, static_cast<std::uint64_t>(entry));
  BoltDims d;
  d.shaft = static_cast<float>(random.logUniform(0.002, 0.012));
  d.length = d.shaft * static_cast<float>(random.uniform(4, 14));
  const float head = d.shaft * 1.7f;
  d.headHeight = d.shaft * 1.4f;
  d.segments = std::clamp(static_cast<int>(detail * random.uniform(8, 20)), 6, 64);
  for (int k = 0; k < 6; ++k) {
    const double a = kPi / 3 * k;
    d.hexagon[static_cast<std::size_t>(k)] = {head * static_cast<float>(std::cos(a)),
                                              head * static_cast<float>(std::sin(a))};
  }
  return d;
}

void buildBolt(int entry, std::uint64_t seed, double detail, PartMesh& mesh) {
  const BoltDims d = drawBolt(entry, seed, detail);
  addExtrusion(mesh, d.hexagon, d.headHeight, 1);  // flat-shaded
  addCylinderSide(mesh, d.shaft, -d.length, 0, d.segments, 1, true);
  addDisk(mesh, d.shaft, -d.length, d.segments, false);
}

// A part's dimensions, drawn from its shape seed: what both its mesh and its B-rep are made of.
struct PartDims {
  Kind kind = Kind::kBox;
  float radius = 0, inner = 0, length = 0;  // tube, rod
  Vec3f size;                               // box
  std::vector<Vec2f> profile;               // bracket, beam: a counter-clockwise polygon
  int columns = 0, rows = 0;                // plate
  float cell = 0, hole = 0;                 // plate: cell side, hole radius over the cell
  int segments = 1, rings = 1;              // tessellation
};

PartDims drawPart(const PartPlan& plan, double detail) {
  Random random(plan.shapeSeed);
  PartDims d;
  d.kind = plan.kind;
  switch (plan.kind) {
    case Kind::kBolt:
      break;  // from the catalogue
    case Kind::kTube: {
      const double radius = random.logUniform(0.01, 0.3);
      d.radius = static_cast<float>(radius);
      d.inner = d.radius * static_cast<float>(random.uniform(0.75, 0.95));
      d.length = static_cast<float>(random.logUniform(0.1, 5.0));
      d.segments = segmentsFor(random, radius, detail, 8, 128);
      d.rings = std::clamp(static_cast<int>(detail * d.length / random.uniform(0.2, 2.0)), 1, 64);
      break;
    }
    case Kind::kBox:
      d.size = {static_cast<float>(random.logUniform(0.02, 2.0)),
                static_cast<float>(random.logUniform(0.02, 2.0)),
                static_cast<float>(random.logUniform(0.02, 1.0))};
      d.segments = std::clamp(static_cast<int>(detail * random.uniform(1, 7)), 1, 32);
      break;
    case Kind::kBracket: {
      const float a = static_cast<float>(random.logUniform(0.03, 0.4)),
                  b = a * static_cast<float>(random.uniform(0.5, 1.5));
      const float t = std::min(a, b) * static_cast<float>(random.uniform(0.08, 0.25));
      d.profile = {{0, 0}, {a, 0}, {a, t}, {t, t}, {t, b}, {0, b}};
      d.length = static_cast<float>(random.logUniform(0.02, 0.5));
      d.segments = std::clamp(static_cast<int>(detail * random.uniform(1, 8)), 1, 64);
      break;
    }
    case Kind::kPlate:
      d.columns = static_cast<int>(1 + random.below(8));
      d.rows = static_cast<int>(1 + random.below(6));
      d.segments =
          std::clamp(8 * static_cast<int>(std::lround(detail * random.uniform(1, 4))), 8, 64);
      // In this order: the plates GCC's right-to-left argument order drew before (same seed,
      // same file).
      d.hole = static_cast<float>(random.uniform(0.15, 0.4));
      d.cell = static_cast<float>(random.logUniform(0.02, 0.3));
      break;
    case Kind::kBeam: {
      // An I-section stringer: long, thin, finely sliced along its length.
      const float w = static_cast<float>(random.logUniform(0.01, 0.05)),
                  h = w * static_cast<float>(random.uniform(1.0, 2.0));
      const float t = w * 0.15f, web = w * 0.1f;
      d.profile = {{-w, -h}, {w, -h}, {w, -h + t}, {web, -h + t}, {web, h - t},   {w, h - t},
                   {w, h},   {-w, h}, {-w, h - t}, {-web, h - t}, {-web, -h + t}, {-w, -h + t}};
      d.length = static_cast<float>(random.uniform(2.0, 15.0));
      d.segments =
          std::clamp(static_cast<int>(detail * d.length / random.uniform(0.05, 1.0)), 1, 400);
      break;
    }
    case Kind::kRod: {
      const double radius = random.logUniform(0.003, 0.02);
      d.radius = static_cast<float>(radius);
      d.length = static_cast<float>(random.uniform(1.0, 10.0));
      d.segments = segmentsFor(random, radius, detail, 6, 24);
      d.rings = std::clamp(static_cast<int>(detail * d.length / random.uniform(0.1, 2.0)), 1, 100);
      break;
    }
  }
  return d;
}

void buildPart(const PartPlan& plan, double detail, PartMesh& mesh) {
  const PartDims d = drawPart(plan, detail);
  switch (d.kind) {
    case Kind::kBolt:
      return;  // from the catalogue
    case Kind::kTube:
      addCylinderSide(mesh, d.radius, 0, d.length, d.segments, d.rings, true);
      addCylinderSide(mesh, d.inner, 0, d.length, d.segments, d.rings, false);
      addAnnulus(mesh, d.inner, d.radius, 0, d.segments, false);
      addAnnulus(mesh, d.inner, d.radius, d.length, d.segments, true);
      return;
    case Kind::kBox:
      addBox(mesh, d.size, d.segments);
      return;
    case Kind::kBracket:
    case Kind::kBeam:
      addExtrusion(mesh, d.profile, d.length, d.segments);
      return;
    case Kind::kPlate:
      addPerforatedPlate(mesh, d.columns, d.rows, d.cell, d.hole, d.segments);
      return;
    case Kind::kRod:
      addCylinderSide(mesh, d.radius, 0, d.length, d.segments, d.rings, true);
      addDisk(mesh, d.radius, 0, d.segments, false);
      addDisk(mesh, d.radius, d.length, d.segments, true);
      return;
  }
}

// --- STEP: the same parts as B-rep ---

cad::Loop circle(float radius, Vec2f centre = {}) {
  return {radius, {centre.x, centre.y}};
}

cad::Loop polygon(std::span<const Vec2f> points) {
  cad::Loop loop;
  for (const Vec2f& p : points) loop.points.insert(loop.points.end(), {p.x, p.y});
  return loop;
}

// The part's solids (sheets for plates) with the dimensions its mesh has.
std::vector<cad::Prism> prismsOf(const PartDims& d) {
  switch (d.kind) {
    case Kind::kBolt:
      return {};
    case Kind::kTube:
      return {{circle(d.radius), {circle(d.inner)}, 0, d.length}};
    case Kind::kBox: {
      const std::array<Vec2f, 4> square = {{{-d.size.x / 2, -d.size.y / 2},
                                            {d.size.x / 2, -d.size.y / 2},
                                            {d.size.x / 2, d.size.y / 2},
                                            {-d.size.x / 2, d.size.y / 2}}};
      return {{polygon(square), {}, -d.size.z / 2, d.size.z / 2}};
    }
    case Kind::kBracket:
    case Kind::kBeam:
      return {{polygon(d.profile), {}, 0, d.length}};
    case Kind::kPlate: {
      const float x0 = -0.5f * d.cell * static_cast<float>(d.columns),
                  y0 = -0.5f * d.cell * static_cast<float>(d.rows);
      const std::array<Vec2f, 4> sheet = {{{x0, y0}, {-x0, y0}, {-x0, -y0}, {x0, -y0}}};
      cad::Prism plate{polygon(sheet), {}, 0, 0};
      for (int row = 0; row < d.rows; ++row)
        for (int column = 0; column < d.columns; ++column)
          plate.holes.push_back(
              circle(d.hole * d.cell, {x0 + (static_cast<float>(column) + 0.5f) * d.cell,
                                       y0 + (static_cast<float>(row) + 0.5f) * d.cell}));
      return {plate};
    }
    case Kind::kRod:
      return {{circle(d.radius), {}, 0, d.length}};
  }
  return {};
}

std::vector<cad::Prism> boltPrisms(int entry, std::uint64_t seed) {
  const BoltDims d = drawBolt(entry, seed, 1);
  return {{polygon(d.hexagon), {}, 0, d.headHeight}, {circle(d.shaft), {}, -d.length, 0}};
}

std::string partName(const PartPlan& plan, std::uint64_t index) {
  return fmt::format("{}_{:07}", kKindNames[static_cast<int>(plan.kind)], index);
}

Rgba8 finishColor(int finish) {
  const auto& c = kFinishes[finish].color;
  auto channel = [](float x) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f));
  };
  return {channel(c[0]), channel(c[1]), channel(c[2]), channel(c[3])};
}

// A few consecutive parts travelling through the pipeline together.
struct PartGroup {
  std::uint64_t first = 0;
  std::vector<PartPlan> plans;
  std::vector<PartMesh> meshes;
};

// Plans and builds every part in parallel and hands them to `consume(index, plan, mesh)` in
// index order. A bounded pipeline: at most kTokens groups of kGroupSize parts exist at once, so
// memory does not depend on the number of parts. Bolts stay empty when `instanceBolts`. Stops at
// the first error from `consume` or at Ctrl-C.
template <class Consume>
Status forEachPart(const CadOptions& options, bool instanceBolts, Progress& progress,
                   Consume&& consume) {
  constexpr std::uint64_t kGroupSize = 16;
  const std::size_t tokens = 4 * static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  std::uint64_t next = 0;
  Status status;
  tbb::parallel_pipeline(
      tokens, tbb::make_filter<void, PartGroup*>(
                  tbb::filter_mode::serial_in_order,
                  [&](tbb::flow_control& control) -> PartGroup* {
                    if (next >= options.objects || !status.ok() || cancelRequested()) {
                      control.stop();
                      return nullptr;
                    }
                    auto* group = new PartGroup;
                    group->first = next;
                    next = std::min(options.objects, next + kGroupSize);
                    return group;
                  }) &
                  tbb::make_filter<PartGroup*, PartGroup*>(
                      tbb::filter_mode::parallel,
                      [&](PartGroup* group) {
                        const std::uint64_t count =
                            std::min(kGroupSize, options.objects - group->first);
                        group->plans.resize(count);
                        group->meshes.resize(count);
                        for (std::uint64_t i = 0; i < count; ++i) {
                          PartPlan& plan = group->plans[i];
                          plan = planPart(options.seed, group->first + i);
                          if (plan.kind != Kind::kBolt)
                            buildPart(plan, options.detail, group->meshes[i]);
                          else if (!instanceBolts)
                            buildBolt(plan.bolt, options.seed, options.detail, group->meshes[i]);
                        }
                        return group;
                      }) &
                  tbb::make_filter<PartGroup*, void>(
                      tbb::filter_mode::serial_in_order, [&](PartGroup* group) {
                        const std::unique_ptr<PartGroup> owned(group);
                        for (std::size_t i = 0; i < group->plans.size() && status.ok(); ++i) {
                          status = consume(group->first + i, group->plans[i], group->meshes[i]);
                        }
                        progress.advance(group->plans.size());
                      }));
  LODFORGE_TRY(status);
  return checkCancelled();
}

Result<GenerateStats> writePly(const CadOptions& options, const std::string& path) {
  // Pass 1: counts (the PLY header needs them before any data).
  GenerateStats stats;
  stats.objects = options.objects;
  {
    Progress progress("cad: counting", options.objects);
    LODFORGE_TRY(forEachPart(options, false, progress,
                             [&](std::uint64_t, const PartPlan&, const PartMesh& mesh) {
                               stats.vertices += mesh.positions.size();
                               stats.triangles += mesh.indices.size() / 3;
                               return Status();
                             }));
  }
  if (stats.vertices > 0xFFFFFFFFull) {
    return Error{ErrorKind::kLimit,
                 fmt::format("{} vertices exceed PLY's 32-bit indices; generate fewer objects",
                             stats.vertices)};
  }
  PlyLayout layout;
  layout.vertexCount = stats.vertices;
  layout.faceCount = stats.triangles;
  layout.normals = true;
  layout.colors = true;
  layout.objectIds = true;
  layout.comments = {fmt::format("lodforge generate cad --objects {} --seed {} --detail {}",
                                 options.objects, options.seed, options.detail)};
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();

  // Pass 2: the same parts again, placed in assembly coordinates.
  std::uint64_t vertexBase = 0;
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> indices, ids;
  Progress progress("cad: writing", options.objects);
  LODFORGE_TRY(forEachPart(
      options, false, progress,
      [&](std::uint64_t index, const PartPlan& plan, const PartMesh& mesh) {
        const Mat4d normalMatrix = plan.transform.normalMatrix();
        positions.resize(mesh.positions.size());
        normals.resize(mesh.positions.size());
        for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
          positions[v] = toFloat(plan.transform.transformPoint(toDouble(mesh.positions[v])));
          normals[v] = toFloat(
              normalizeOr(normalMatrix.transformVector(toDouble(mesh.normals[v])), Vec3d{0, 0, 1}));
        }
        colors.assign(mesh.positions.size(), finishColor(plan.finish));
        indices.resize(mesh.indices.size());
        for (std::size_t k = 0; k < mesh.indices.size(); ++k)
          indices[k] = static_cast<std::uint32_t>(mesh.indices[k] + vertexBase);
        ids.assign(mesh.indices.size() / 3, static_cast<std::uint32_t>(index));
        vertexBase += mesh.positions.size();
        LODFORGE_TRY(writer->writeVertices(positions, normals, colors));
        return writer->writeTriangles(indices, ids);
      }));
  progress.finish();
  stats.bytes = writer->fileBytes();
  LODFORGE_TRY(writer->finish());
  return stats;
}

Result<GenerateStats> writeGlb(const CadOptions& options, const std::string& path) {
  Result<GlbWriter> writer = GlbWriter::create(path);
  if (!writer) return writer.status();
  std::array<std::uint32_t, kFinishCount> materials{};
  for (int f = 0; f < kFinishCount; ++f)
    materials[static_cast<std::size_t>(f)] =
        writer->addMaterial(kFinishes[f].color, kFinishes[f].name);
  std::array<std::optional<std::uint32_t>, kBoltCatalogue> boltMeshes;
  std::array<std::uint64_t, kBoltCatalogue> boltVertices{}, boltTriangles{};

  GenerateStats stats;
  stats.objects = options.objects;
  PartMesh bolt;
  Progress progress("cad", options.objects);
  LODFORGE_TRY(forEachPart(
      options, true, progress,
      [&](std::uint64_t index, const PartPlan& plan, const PartMesh& mesh) -> Status {
        std::uint32_t meshIndex = 0;
        const auto material = materials[static_cast<std::size_t>(plan.finish)];
        if (plan.kind == Kind::kBolt) {
          // Standard parts are instanced: the catalogue mesh is written once, at first use.
          const auto entry = static_cast<std::size_t>(plan.bolt);
          if (!boltMeshes[entry]) {
            bolt.clear();
            buildBolt(plan.bolt, options.seed, options.detail, bolt);
            Result<std::uint32_t> added =
                writer->addMesh({bolt.positions, bolt.normals, {}, bolt.indices},
                                fmt::format("bolt M{}", entry), material);
            if (!added) return added.status();
            boltMeshes[entry] = *added;
            boltVertices[entry] = bolt.positions.size();
            boltTriangles[entry] = bolt.indices.size() / 3;
          }
          meshIndex = *boltMeshes[entry];
          stats.vertices += boltVertices[entry];
          stats.triangles += boltTriangles[entry];
        } else {
          Result<std::uint32_t> added =
              writer->addMesh({mesh.positions, mesh.normals, {}, mesh.indices}, {}, material);
          if (!added) return added.status();
          meshIndex = *added;
          stats.vertices += mesh.positions.size();
          stats.triangles += mesh.indices.size() / 3;
        }
        writer->addNode(partName(plan, index), meshIndex, &plan.transform);
        if (writer->binaryBytes() >
            (std::uint64_t{15} << 28)) {  // 3.75 GiB: stop before GLB's 4 GiB
          return Error{
              ErrorKind::kLimit,
              fmt::format("{}: {} objects do not fit in one GLB (4 GiB); write a .ply instead",
                          path, options.objects)};
        }
        return Status();
      }));
  progress.finish();
  LODFORGE_TRY(writer->finish());
  Result<std::uint64_t> size = fileSize(path);
  if (!size) return size.status();
  stats.bytes = *size;
  return stats;
}

// The assembly as STEP through OpenCASCADE: one shape per part (bolts: one per catalogue entry
// and finish, placed many times, and on the layer of their kind), placed with the part's
// transform in sub-assemblies of kStepGroupSize consecutive parts under the root.
Result<GenerateStats> writeStep(const CadOptions& options, const std::string& path) {
  cad::WriteRequest request;
  request.path = path;
  request.assembly = fmt::format("lodforge cad assembly (seed {})", options.seed);
  std::map<std::pair<int, int>, std::uint64_t> bolts;  // (entry, finish) -> shape
  Progress progress("cad (B-rep)", options.objects);
  for (std::uint64_t index = 0; index < options.objects; ++index) {
    if (index % 1024 == 0) LODFORGE_TRY(checkCancelled());
    const PartPlan plan = planPart(options.seed, index);
    const auto& color = kFinishes[plan.finish].color;
    const std::string name = partName(plan, index);
    const std::string layer = kKindLayers[static_cast<int>(plan.kind)];
    std::uint64_t shape = request.shapes.size();
    if (plan.kind == Kind::kBolt) {
      const auto [at, added] = bolts.try_emplace({plan.bolt, plan.finish}, shape);
      shape = at->second;
      if (added)
        request.shapes.push_back(
            {fmt::format("bolt M{} {}", plan.bolt, kFinishes[plan.finish].name),
             boltPrisms(plan.bolt, options.seed),
             {color[0], color[1], color[2], color[3]},
             layer});
    } else {
      request.shapes.push_back({name,
                                prismsOf(drawPart(plan, options.detail)),
                                {color[0], color[1], color[2], color[3]},
                                layer});
    }
    const auto group = static_cast<std::uint32_t>(index / kStepGroupSize);
    if (group == request.groups.size()) request.groups.push_back(fmt::format("group {:05}", group));
    cad::Placement placement{name, shape, group, {}};
    std::copy(plan.transform.m.begin(), plan.transform.m.end(), placement.matrix);
    request.placements.push_back(std::move(placement));
    progress.advance(1);
  }
  LODFORGE_TRY(writeStepAssembly(std::move(request)));
  progress.finish();
  GenerateStats stats;
  stats.objects = options.objects;
  Result<std::uint64_t> size = fileSize(path);
  if (!size) return size.status();
  stats.bytes = *size;
  return stats;
}

}  // namespace

Result<GenerateStats> generateCad(const CadOptions& options, const std::string& path) {
  if (options.objects == 0)
    return Error{ErrorKind::kUsage, "an assembly needs at least one object"};
  if (!(options.detail > 0)) return Error{ErrorKind::kUsage, "--detail must be positive"};
  const std::string ext = fileExtension(path);
  if (ext == "glb") return writeGlb(options, path);
  if (ext == "ply") return writePly(options, path);
  if (ext == "step" || ext == "stp") return writeStep(options, path);
  return Error{ErrorKind::kUsage,
               fmt::format("{}: the cad generator writes .glb, .ply or .step", path)};
}

}  // namespace lodforge
