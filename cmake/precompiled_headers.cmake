# A precompiled header for the GoogleTest programs: GoogleTest, Eigen and the standard library are parsed once per
# build instead of once per test file. It cut a clean build's compile time of the sim test files by about a fifth;
# the same header on the libraries saved about what building it cost, so they do without.
#
# PALPATE_PCH is on by default, except with a compiler launcher (ccache): ccache caches a PCH build only with
# CCACHE_SLOPPINESS=pch_defines,time_macros and -fpch-preprocess, and a warm cache beats a PCH. The header is
# force-included into every test file, so a test file missing an #include still compiles with it; a PCH OFF build
# shows it.
#
# One owner target builds the header; every test program reuses it (same flags). No source file needs to change:
# palpate_apply_pch() walks the targets after they are all defined.

if(CMAKE_CXX_COMPILER_LAUNCHER)
  set(palpate_pch_default OFF)
else()
  set(palpate_pch_default ON)
endif()
option(PALPATE_PCH "Precompile the headers of the test programs (see cmake/precompiled_headers.cmake)"
       ${palpate_pch_default})

# palpate_test_flags(TARGET): how the test programs (and their header) compile.
# - At -O1 in an optimised build: the code under test is the libraries', built as the build type says; the test
#   files only drive it, and -O1 compiles them about a sixth faster than -O3 (CI builds them on every run).
# - GCC 12 reports false warnings in test files under it: -Warray-bounds and -Wstringop-overflow inside std::string's
#   copy with the header (GCC bug 105329: the libstdc++ string's inlined _M_construct), and -Wmaybe-uninitialized in
#   a std::optional of an Eigen vector at -O1 (GCC bug 80635); the test programs leave those out
function(palpate_test_flags target)
  target_compile_options(${target} PRIVATE $<$<CONFIG:Release,RelWithDebInfo>:-O1>)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-array-bounds -Wno-stringop-overflow -Wno-maybe-uninitialized)
  endif()
endfunction()

# palpate_apply_pch(DIR): every program under DIR that links GoogleTest reuses the one precompiled header
function(palpate_apply_pch dir)
  if(NOT PALPATE_PCH OR NOT PALPATE_BUILD_TESTS)
    return()
  endif()
  if(NOT TARGET palpate_pch_test)
    set(owner_source ${CMAKE_BINARY_DIR}/palpate_pch_owner.cpp)
    file(CONFIGURE OUTPUT ${owner_source} CONTENT "// compiles the precompiled header (cmake/precompiled_headers.cmake)\n")
    add_library(palpate_pch_test OBJECT ${owner_source})
    target_link_libraries(palpate_pch_test PRIVATE Eigen3::Eigen GTest::gtest palpate_warnings)
    palpate_test_flags(palpate_pch_test)
    # (the header's -fpic/-fpie must be its users': the Python module's build compiles the libraries -fPIC, which an
    # object library would take and a program would not; neither needs either, the compiler's default serves both)
    set_target_properties(palpate_pch_test PROPERTIES POSITION_INDEPENDENT_CODE OFF)
    target_precompile_headers(palpate_pch_test PRIVATE
      <algorithm> <array> <atomic> <chrono> <cmath> <cstdint> <cstdio> <cstdlib> <cstring> <filesystem> <fstream>
      <functional> <map> <memory> <optional> <sstream> <string> <string_view> <thread> <utility> <vector>
      <Eigen/Core> <Eigen/Geometry> <gtest/gtest.h>)
  endif()
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    if(type STREQUAL "EXECUTABLE")
      get_target_property(libs ${target} LINK_LIBRARIES)
      if("GTest::gtest" IN_LIST libs)
        target_precompile_headers(${target} REUSE_FROM palpate_pch_test)
        set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE OFF)
      endif()
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(subdir IN LISTS subdirs)
    palpate_apply_pch(${subdir})
  endforeach()
endfunction()
