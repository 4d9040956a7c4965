# The sanitizer tree (scripts/build.sh asan): the unit tests, the command and the fuzzers, all
# under ASan + UBSan, with clang. LODFORGE_FUZZ builds the fuzz targets against a second copy of
# the library instrumented for libFuzzer's coverage (src/CMakeLists.txt): the tests and the
# command run the uninstrumented one, twice as fast.
if(LODFORGE_SANITIZE OR LODFORGE_FUZZ)
  # Asserts stay on: they catch caller bugs that the sanitizers would only see later.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -UNDEBUG)
  add_link_options(-fsanitize=address,undefined)
endif()
if(LODFORGE_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "LODFORGE_FUZZ needs clang (CXX=clang++)")
  endif()
endif()
