// The headless GL context the render tests share.
#pragma once

#include <memory>

#include <gtest/gtest.h>

#include "lodforge/render/context.h"

namespace lodforge::test {

// Created once and never torn down: unloading Mesa's driver at exit would leave its few
// process-lifetime allocations unattributable for LeakSanitizer; kept alive, they stay reachable.
inline GlContext& headlessContext() {
  static auto* created = new Result<std::unique_ptr<GlContext>>(GlContext::headless());
  EXPECT_TRUE(created->ok()) << created->error().message;
  return ***created;
}

}  // namespace lodforge::test
