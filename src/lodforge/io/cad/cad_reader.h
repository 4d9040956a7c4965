// CAD B-rep files through OpenCASCADE's XDE: STEP (AP203/214/242), IGES and OCCT's native BREP.
// The assembly tree is walked to its leaves; every placed instance becomes an object named by
// its product, with the colours of its faces (or its part) as vertex colours. A shape placed many
// times is tessellated once (BRepMesh_IncrementalMesh, in parallel across shapes) and its
// triangles transformed per instance. STEP and IGES lengths come out in metres (glTF's unit);
// BREP has no unit and is taken as it is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

struct CadReadOptions {
  // The chord error: a fraction of each shape's bounding-box diagonal, or (absoluteDeflection)
  // a length in the model's unit (metres for STEP and IGES).
  double deflection = 0.001;
  bool absoluteDeflection = false;
  double angleDegrees = 20;  // the largest angle between neighbouring triangles on a curve
  // Legacy 8-bit names (not UTF-8, not STEP's \X2\ escapes) read in this code page; OCCT's names,
  // e.g. "CP1251", "SJIS", "GB", "CP1252". Empty: UTF-8.
  std::string codePage;
  // Keep the parts the file hides: a product or instance marked invisible (STEP's INVISIBILITY)
  // or on a hidden layer. Without it they are left out, as the CAD system shows the model.
  bool hidden = false;
  // What a damaged file lost (the entities OCCT failed to read or transfer): one warning per
  // entity with OCCT's reason (-v), else one warning with the count and the first few.
  bool listLost = false;
  // A STEP file cut short (no END-ISO-10303-21;) is read with a warning instead of refused.
  bool salvageTruncated = false;
};

struct CadReadStats {
  std::uint64_t shapes = 0;     // distinct shapes tessellated
  std::uint64_t instances = 0;  // placed instances (objects)
  std::uint32_t depth = 0;      // the assembly tree's depth
  std::uint64_t hidden = 0;     // placed parts the file hides, left out (0 with `hidden`)
};

bool isCadPath(const std::string& path);

// An entry point of the OpenCASCADE module (cad_module.h), loaded on first use.
Status cadModuleSymbol(const char* symbol, void*& entry);

// Warnings name each part OCCT could not mesh (wholly or some faces); its other parts are kept.
// No part left, no shape in the file, or a file OCCT cannot read: ErrorKind::kBadInput.
Result<Model> readCad(const std::string& path, const CadReadOptions& options = {},
                      std::vector<std::string>* warnings = nullptr, CadReadStats* stats = nullptr);

}  // namespace lodforge
