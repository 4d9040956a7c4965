# One switch for the sanitizer build of the unit tests: ASan + UBSan, stop at the first report.
if(LODFORGE_SANITIZE)
  # Asserts stay on: they catch caller bugs that the sanitizers would only see later.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -g -UNDEBUG)
  add_link_options(-fsanitize=address,undefined)
endif()
if(LODFORGE_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "LODFORGE_FUZZ needs clang (CXX=clang++)")
  endif()
  # Everything is instrumented for coverage; only the fuzzer executables link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -g -UNDEBUG)
  add_link_options(-fsanitize=address,undefined)
endif()
