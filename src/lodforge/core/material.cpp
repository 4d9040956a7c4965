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

int wrapModeCode(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kMirror:
      return 33648;
    case TextureWrap::kClamp:
      return 33071;
    case TextureWrap::kRepeat:
      break;
  }
  return 10497;
}

TextureWrap wrapModeOf(int code) {
  if (code == 33648) return TextureWrap::kMirror;
  if (code == 33071) return TextureWrap::kClamp;
  return TextureWrap::kRepeat;
}

}  // namespace lodforge
