// The boundary between lodforge and its OpenCASCADE module (liblodforge_cad.so). Linking OCCT's
// thirty libraries into every command would cost each run ~30 MiB of memory at start, so
// cad_reader.cpp loads the module (dlopen) only when a CAD file is read. Plain standard types
// only, no lodforge code on the module's side: it and the command are built by one compiler.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lodforge::cad {

inline constexpr int kModuleVersion = 8;  // bumped when these structs change
inline constexpr const char* kReadSymbol = "lodforge_cad_read";
inline constexpr const char* kWriteSymbol = "lodforge_cad_write";

struct Request {
  std::string path;
  double deflection = 0.001;
  bool absoluteDeflection = false;  // metres, else a fraction of each shape's diagonal
  double angleDegrees = 20;
  std::string codePage;  // OCCT's read.step.codepage; empty: UTF-8
  bool hidden = false;   // keep the parts the file hides (else they are left out)
  // Asked between shapes and inside OCCT's mesher (its user break): true stops the read.
  bool (*cancelled)() = nullptr;
  // Told the number of distinct shapes once, then each shape meshed (from any thread).
  void (*shapes)(void* context, std::uint64_t total) = nullptr;
  void (*meshed)(void* context) = nullptr;
  void* context = nullptr;
};

// A part's material (glTF's model): OCCT's visual material where the file has one, else made
// from its colours when a face is translucent.
struct Material {
  std::string name;
  float baseColor[4] = {1, 1, 1, 1};  // linear
  float metallic = 0, roughness = 0.5f;
  int alphaMode = 0;  // 0 opaque, 1 mask, 2 blend
  float alphaCutoff = 0.5f;
  bool doubleSided = false;
  float emissive[3] = {0, 0, 0};  // linear

  bool operator==(const Material&) const = default;
};

struct Instance {
  std::string name;
  std::string path;   // product names from the root down to this instance, "/"-separated
  std::string layer;  // the CAD layers of the instance and its part, "; "-separated; often empty
  std::uint64_t firstVertex = 0, vertexCount = 0;
  std::uint64_t firstTriangle = 0, triangleCount = 0;
  std::uint64_t shape = 0;       // which distinct shape
  std::uint32_t material = ~0u;  // into Result::materials; ~0u: none
};

struct Result {
  // 0 ok; otherwise 1: bad input, 2: a bad option (usage), 3: cancelled; `error` says what
  // (without the path)
  int status = 0;
  std::string error;
  std::vector<std::string> warnings;  // without the path
  // The entities OCCT failed to read or to transfer ("#123: its reason"), in the file's order:
  // what a damaged file lost.
  std::vector<std::string> lost;
  std::vector<double> positions;     // xyz per vertex, metres (STEP, IGES) or the file's unit
  std::vector<float> normals;        // xyz per vertex
  std::vector<std::uint8_t> colors;  // rgba per vertex (sRGB), when `coloured`
  bool coloured = false;
  std::vector<std::uint32_t> indices;  // 3 per triangle, local to the instance
  std::vector<Instance> instances;
  std::vector<Material> materials;
  std::uint64_t shapes = 0;
  std::uint32_t depth = 0;
  std::uint64_t hidden = 0;  // placed parts left out because the file hides them
};

// The module's reading entry point; `version` must equal kModuleVersion.
using ReadFunction = void (*)(int version, const Request& request, Result& result);

// --- writing (`lodforge generate cad -o X.step`) ---

// A closed planar loop: a circle (radius > 0, centred at points[0], points[1]) or a polygon
// (x, y pairs, counter-clockwise).
struct Loop {
  double radius = 0;
  std::vector<double> points;
};

// The region inside `outer` and outside `holes`, swept along z from z0 to z1: a solid prism, or
// a planar sheet where z0 == z1.
struct Prism {
  Loop outer;
  std::vector<Loop> holes;
  double z0 = 0, z1 = 0;
};

// A part's B-rep, in its own frame: one or more prisms (a compound when several).
struct ShapeSpec {
  std::string name;
  std::vector<Prism> prisms;
  float color[4] = {0.8f, 0.8f, 0.8f, 1};  // linear RGBA
  std::string layer;                       // empty: on no layer
};

// One placed instance of a shape, under the assembly's root or one of its sub-assemblies.
struct Placement {
  std::string name;
  std::uint64_t shape = 0;
  std::uint32_t group = ~0u;  // into WriteRequest::groups; ~0u: directly under the root
  double matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // rigid, column-major
};

struct WriteRequest {
  std::string path;      // written as given (the caller names a temporary and renames it)
  std::string assembly;  // the root product's name
  // Sub-assemblies placed under the root (identity transform), by name. Real assemblies are
  // trees, and OCCT's STEP reader is quadratic in the children of one product.
  std::vector<std::string> groups;
  std::vector<ShapeSpec> shapes;
  std::vector<Placement> placements;
  bool (*cancelled)() = nullptr;  // asked between shapes
};

struct WriteResult {
  int status = 0;  // 0 ok, 1 failed, 3 cancelled
  std::string error;
};

// Writes the assembly as STEP (AP214, names, colours and layers); `version` must equal
// kModuleVersion.
using WriteFunction = void (*)(int version, const WriteRequest& request, WriteResult& result);

}  // namespace lodforge::cad
