# A precompiled header for the GoogleTest programs: GoogleTest, Eigen and the standard library are parsed once per
# build instead of once per test file. It cut a clean build's compile time of the sim test files by about a fifth;
# the same header on the libraries saved about what building it cost, so they do without.
#
# PALPATE_PCH is OFF by default: with it, GCC 12 at -O2 reports a false -Warray-bounds inside std::string's copy in
# tests/haptics/force/proxy_settle_test.cpp, which fails a -Werror build (CI's). With a compiler launcher (ccache) it
# would be of no use anyway: ccache caches a PCH build only with CCACHE_SLOPPINESS=pch_defines,time_macros and
# -fpch-preprocess, and a warm cache beats a PCH. The header is force-included into every test file, so a test file
# missing an #include still compiles with it; a PCH OFF build shows it.
#
# One owner target builds the header; every test program reuses it (same flags). No source file needs to change:
# palpate_apply_pch() walks the targets after they are all defined.

option(PALPATE_PCH "Precompile the headers of the test programs (OFF by default: see cmake/precompiled_headers.cmake)"
       OFF)

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
      endif()
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(subdir IN LISTS subdirs)
    palpate_apply_pch(${subdir})
  endforeach()
endfunction()
