// The headless GL context the render tests share.
#pragma once

#include <memory>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lodforge/render/context.h"

namespace lodforge::test {

// Created once and never torn down: unloading Mesa's driver at exit would leave its few
// process-lifetime allocations unattributable for LeakSanitizer; kept alive, they stay reachable.
// Without a context every render test fails with the reason (GoogleTest reports the exception as
// the test's failure): never a skip, never a dereferenced error.
inline GlContext& headlessContext() {
  static auto* created = new Result<std::unique_ptr<GlContext>>(GlContext::headless());
  if (!created->ok())
    throw std::runtime_error("no headless OpenGL context (EGL, Mesa llvmpipe): " +
                             created->error().message);
  return ***created;
}

}  // namespace lodforge::test
