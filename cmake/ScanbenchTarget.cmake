# One place for the compile settings of every scanbench target: C++20, strict
# warnings as errors, and the sanitizers when SCANBENCH_SANITIZE is on.
function(scanbench_target_settings target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
  # GCC 12 reports -Wrestrict false positives inside libstdc++'s std::string
  # concatenation at -O2/-O3 (GCC bug 105329); the warning stays, as a warning.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-error=restrict)
  endif()
  # The branch-free kernels (acquisition/geometry/branch_free.hpp, mixed_pixels.cpp)
  # combine booleans with & and | on purpose: no short-circuit branches.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    target_compile_options(${target} PRIVATE -Wno-bitwise-instead-of-logical)
  endif()
  if(SCANBENCH_SANITIZE)
    # -UNDEBUG: the sanitizer pass also checks every programmer-error assert,
    # at optimised speed (RelWithDebInfo would otherwise define NDEBUG).
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined -UNDEBUG)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    if(SCANBENCH_UBSAN_SKIP)
      target_compile_options(${target} PRIVATE -fno-sanitize=${SCANBENCH_UBSAN_SKIP})
    endif()
    # Eigen switches to its own aligned allocator under AddressSanitizer; the
    # prebuilt Ceres (and the benches' PCL) libraries use malloc. Objects
    # crossing that line (Eigen matrices inside their objects) would be freed
    # by the other allocator. glibc's and ASan's malloc both align to 16 bytes, which
    # is all Eigen needs here, so keep malloc everywhere.
    target_compile_definitions(${target} PRIVATE EIGEN_MALLOC_ALREADY_ALIGNED=1)
    # No AVX2 clones (acquisition/geometry/branch_free.hpp): their ifunc resolvers run
    # during relocation, before the sanitizer runtime is initialised.
    target_compile_definitions(${target} PRIVATE SCANBENCH_VECTOR_CLONES=)
  endif()
  if(SCANBENCH_FUZZ)
    # Coverage for libFuzzer in every library it drives (fuzz/CMakeLists.txt
    # links the fuzzer's own main into the targets).
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()

# A module library: sources beside headers, includes rooted at the repository
# so that every include names its module ("acquisition/scan.hpp").
# PRECOMPILE: headers most of its sources include (Eigen, JSON), parsed once
# per library instead of once per source file.
function(scanbench_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PRECOMPILE" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  scanbench_target_settings(${name})
  if(ARG_PRECOMPILE)
    target_precompile_headers(${name} PRIVATE ${ARG_PRECOMPILE})
  endif()
endfunction()

# The standard and Eigen headers nearly every source of our libraries includes.
set(SCANBENCH_COMMON_HEADERS <algorithm> <cmath> <cstdint> <filesystem> <optional> <span>
    <string> <vector> <Eigen/Core> <Eigen/Geometry>)
