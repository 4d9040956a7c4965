# Warnings as errors for our own targets; third-party headers come in as SYSTEM includes.
add_library(lodforge_warnings INTERFACE)
target_compile_options(lodforge_warnings INTERFACE
  -Wall -Wextra -Wshadow -Wconversion -Wsign-conversion -Wnon-virtual-dtor
  -Wold-style-cast -Woverloaded-virtual -Werror)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # GCC 12 reports false positives inside libstdc++ at -O3 (PR 105651, 106199)
  target_compile_options(lodforge_warnings INTERFACE -Wno-restrict -Wno-array-bounds -Wno-stringop-overflow)
endif()

# Tests and benchmarks: the same hygiene without the conversion warnings, which in test code
# flag literal arithmetic far more often than real mistakes.
add_library(lodforge_test_warnings INTERFACE)
target_compile_options(lodforge_test_warnings INTERFACE -Wall -Wextra -Wshadow -Wnon-virtual-dtor -Werror)
