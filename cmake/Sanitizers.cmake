# The sanitizer tree (scripts/build.sh asan): the unit tests, the command and the fuzzers, all
# under ASan + UBSan and compiled once, with clang. LODFORGE_FUZZ adds libFuzzer's coverage
# instrumentation to everything and builds the fuzz targets (only they link libFuzzer's main).
if(LODFORGE_SANITIZE OR LODFORGE_FUZZ)
  # Asserts stay on: they catch caller bugs that the sanitizers would only see later.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -UNDEBUG)
  add_link_options(-fsanitize=address,undefined)
endif()
if(LODFORGE_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "LODFORGE_FUZZ needs clang (CXX=clang++)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
