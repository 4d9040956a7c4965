#include "lodforge/core/material.h"

namespace lodforge {

const char* alphaModeName(AlphaMode mode) {
  switch (mode) {
    case AlphaMode::kMask:
      return "MASK";
    case AlphaMode::kBlend:
      return "BLEND";
    case AlphaMode::kOpaque:
      break;
  }
  return "OPAQUE";
}

}  // namespace lodforge
