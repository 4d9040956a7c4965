// Running the real `lodforge` binary from a test: exit code, stdout and stderr.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "test_support.h"

namespace lodforge::test {

struct Outcome {
  int code = -1;
  std::string out, err;
};

// Runs `lodforge ARGS` through the shell, capturing stdout and stderr; `wrapper` goes in front
// of the binary (an environment change, a virtual display).
inline Outcome lodforge(const std::string& args, const test::TempDir& dir,
                        const std::string& wrapper = "") {
  const std::string out = dir.file(".stdout"), err = dir.file(".stderr");
  const std::string command =
      wrapper + std::string(LODFORGE_BINARY) + " " + args + " >" + out + " 2>" + err;
  const int status = std::system(command.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = test::readFile(out);
  o.err = test::readFile(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return o;
}

// Under ASan, LeakSanitizer's exit-time tracer crashes reading the main thread's TLS in a render
// subprocess started from this test (Mesa's driver loaded; since PROJ joined the link), though
// the same command passes on its own. Leaks of the render code stay checked in-process by
// tests/render/*; the subprocess keeps ASan and UBSan, without the leak pass.
inline std::string glSubprocess() {
#ifdef LODFORGE_SANITIZED
  const char* options = std::getenv("ASAN_OPTIONS");
  return std::string("ASAN_OPTIONS=") + (options ? options : "") + ":detect_leaks=0 ";
#else
  return "";
#endif
}

}  // namespace lodforge::test
