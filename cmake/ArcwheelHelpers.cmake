include(GNUInstallDirs)

# arcwheel_add_library(NAME n SRCS ... DEPS ...): target arcwheel_<n>, alias arcwheel::<n>.
#   Its sources are compiled as one unity batch (each heavy header parsed, and each template used
#   instantiated and optimised, once a library, not once a file: a clean build in 70 % of the time;
#   the four libraries that had two or three batches of 8 took 82 CPU-s in them, 67 in one); a
#   file-local name must therefore be unique in its library. COLD marks a library with no numeric
#   kernel (formatting, storage, orchestration): compiled at -O1 in optimised builds, as the tests
#   are (see ARCWHEEL_TEST_OPTIMIZATION).
#   COLD_SRCS are such sources of a library that has kernels too (its file formats, job files,
#   logging): one unity batch of their own at -O1, the SRCS another at the build type's flags. A
#   batch costs a parse of the heavy headers, so a library's cold sources are worth separating only
#   when they are many. A library may group its sources further (fitting/CMakeLists.txt), so that
#   an edit recompiles less than the whole library.
# arcwheel_install_library(NAME n HEADERS ...): installs arcwheel_<n> as arcwheel::<n> of the
#   arcwheel CMake package (cmake/ArcwheelPackage.cmake), and its public headers, the ones listed,
#   under include/arcwheel/<n>/, where `#include "<n>/x.h"` finds them as in the source tree.
# arcwheel_add_test(NAME n SRCS ... DEPS ... [SHARDS k] [COST s]): the GoogleTest file SRCS[0] (with
#   its helper sources) in the folder's test binary <folder>_tests, which compiles the folder's test
#   files in unity batches of 8 (GoogleTest, Eigen and nlohmann-json parsed once a batch: a
#   file-local name must be unique in the folder's tests). Registered with CTest as <folder>/<n>,
#   running the tests that file defines (core/testing/main.cc), or with SHARDS as <folder>/<n>/<i>
#   for i < k, each running every k-th of them (GoogleTest's sharding), so that CTest runs a long
#   file on both cores. COST (about the seconds it takes under the sanitizers) makes CTest start the
#   long tests first on a clean checkout, which has no timings of earlier runs: started last, they
#   ran one after the other.
# arcwheel_add_benchmark(NAME n SRCS ... DEPS ...): a Google Benchmark binary.
# arcwheel_embed_text(OUT var SYMBOL s FILE f): writes a source file defining
#   `extern const char s[]` = the text of f (a data file the binary needs at run time, such as a
#   robot's URDF) and sets var to its path, for the SRCS of a library. Rewritten when f changes.

# Test code itself is built with -O1 in optimised builds: it is compiled on every CI run and runs for
# seconds, and -O1 compiles it in about 60 % of -O3's time. The code under test, the libraries,
# keeps the build type's flags. (Precompiled headers saved another 10 % of a test file's time, but
# GCC 12 then reports false -Warray-bounds and -Wmaybe-uninitialized inside libstdc++, which
# -Werror turns into failures.)
# GCC's -Wmaybe-uninitialized depends on the optimiser's data flow, and at -O1 it flags Eigen's
# fixed-size temporaries in test files (it does not at -O3); the libraries keep it.
set(ARCWHEEL_TEST_OPTIMIZATION $<$<CONFIG:Release,RelWithDebInfo,MinSizeRel>:-O1>
    $<$<AND:$<CONFIG:Release,RelWithDebInfo,MinSizeRel>,$<CXX_COMPILER_ID:GNU>>:-Wno-maybe-uninitialized>)
# Libraries that format, store and orchestrate (COLD below, and the command-line front end) spend
# milliseconds of a run in their own code but a third of the build's compilation at -O3; -O1 halves
# their code generation. IEEE arithmetic is the same at every level (no -ffast-math, no FMA
# contraction in ISO C++ mode), so the numbers they write do not change.
set(ARCWHEEL_COLD_OPTIMIZATION $<$<CONFIG:Release,RelWithDebInfo,MinSizeRel>:-O1>)
set(ARCWHEEL_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
if(ARCWHEEL_WERROR)
  list(APPEND ARCWHEEL_WARNINGS -Werror)
endif()
if(ARCWHEEL_SANITIZE)
  string(REPLACE ";" "," _arcwheel_sanitizers "${ARCWHEEL_SANITIZE}")
  add_compile_options(-fsanitize=${_arcwheel_sanitizers} -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=${_arcwheel_sanitizers})
endif()
# The sanitizer suite (preset asan) keeps UndefinedBehaviorSanitizer's arithmetic checks (signed
# overflow, shifts, division by zero, a NaN or too large a double converted to an integer, array
# bounds, bool and enum values, a missing return) and leaves its pointer checks to
# AddressSanitizer, which reports the access a null, misaligned or overflowed pointer leads to.
# They instrumented every pointer step of Eigen's and GoogleTest's templates: the frames library
# compiled in 31-36 CPU-s with them, 21.5 without; its test binary 40, 29 (2026-12-07). The fuzz
# preset, for long runs, keeps them all.
if(ARCWHEEL_SANITIZE_EXCLUDE)
  string(REPLACE ";" "," _arcwheel_excluded "${ARCWHEEL_SANITIZE_EXCLUDE}")
  add_compile_options(-fno-sanitize=${_arcwheel_excluded})
endif()

function(arcwheel_add_library)
  cmake_parse_arguments(ARG "COLD" "NAME" "SRCS;COLD_SRCS;DEPS" ${ARGN})
  add_library(arcwheel_${ARG_NAME} STATIC ${ARG_SRCS} ${ARG_COLD_SRCS})
  add_library(arcwheel::${ARG_NAME} ALIAS arcwheel_${ARG_NAME})
  target_include_directories(arcwheel_${ARG_NAME} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                             $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>
                             $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/arcwheel>)
  target_link_libraries(arcwheel_${ARG_NAME} PUBLIC ${ARG_DEPS})
  target_compile_options(arcwheel_${ARG_NAME} PRIVATE ${ARCWHEEL_WARNINGS})
  set_target_properties(arcwheel_${ARG_NAME} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 0)
  # GCC takes a source included into a unity batch for a header, and a header's type that holds a
  # file-local one for a linkage hazard; in a source file it is none.
  target_compile_options(arcwheel_${ARG_NAME} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  if(ARG_COLD)
    target_compile_options(arcwheel_${ARG_NAME} PRIVATE ${ARCWHEEL_COLD_OPTIMIZATION})
  endif()
  if(ARG_COLD_SRCS)
    # Two named unity groups, hot (the SRCS) and cold, whose generated source (CMake names it
    # unity_<group>_cxx.cxx) carries the -O1; set on the sources themselves, the option would take
    # them out of the unity build.
    set_target_properties(arcwheel_${ARG_NAME} PROPERTIES UNITY_BUILD_MODE GROUP)
    set_source_files_properties(${ARG_SRCS} PROPERTIES UNITY_GROUP hot)
    set_source_files_properties(${ARG_COLD_SRCS} PROPERTIES UNITY_GROUP cold)
    set_source_files_properties(
      ${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/arcwheel_${ARG_NAME}.dir/Unity/unity_cold_cxx.cxx
      PROPERTIES COMPILE_OPTIONS "${ARCWHEEL_COLD_OPTIMIZATION}")
  endif()
endfunction()

function(arcwheel_install_library)
  cmake_parse_arguments(ARG "" "NAME" "HEADERS" ${ARGN})
  set_target_properties(arcwheel_${ARG_NAME} PROPERTIES EXPORT_NAME ${ARG_NAME})
  install(TARGETS arcwheel_${ARG_NAME} EXPORT arcwheelTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(FILES ${ARG_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/arcwheel/${ARG_NAME})
  set_property(GLOBAL APPEND PROPERTY ARCWHEEL_INSTALLED_LIBRARIES ${ARG_NAME})
endfunction()

function(arcwheel_add_test)
  if(NOT ARCWHEEL_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME;SHARDS;COST" "SRCS;DEPS" ${ARGN})
  if(NOT ARG_COST)
    set(ARG_COST 1)
  endif()
  get_filename_component(_folder ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(_target ${_folder}_tests)
  if(NOT TARGET ${_target})
    add_executable(${_target})
    target_link_libraries(${_target} PRIVATE arcwheel::testing GTest::gtest GTest::gmock)
    target_compile_options(${_target} PRIVATE ${ARCWHEEL_WARNINGS} ${ARCWHEEL_TEST_OPTIMIZATION}
                           $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
    set_target_properties(${_target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  # A helper source shared by several test files (reports/report_fixture.cc) is compiled once.
  get_target_property(_sources ${_target} SOURCES)
  foreach(_source IN LISTS ARG_SRCS)
    if(NOT _source IN_LIST _sources)
      target_sources(${_target} PRIVATE ${_source})
    endif()
  endforeach()
  target_link_libraries(${_target} PRIVATE ${ARG_DEPS})
  list(GET ARG_SRCS 0 _test_source)
  set(_environment "ARCWHEEL_SOURCE_DIR=${PROJECT_SOURCE_DIR};ARCWHEEL_BINARY=$<TARGET_FILE:arcwheel>"
                   "ARCWHEEL_TEST_SOURCE=${_folder}/${_test_source}")
  if(NOT ARG_SHARDS)
    add_test(NAME ${_folder}/${ARG_NAME} COMMAND ${_target} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(${_folder}/${ARG_NAME} PROPERTIES ENVIRONMENT "${_environment}" COST ${ARG_COST})
    return()
  endif()
  math(EXPR _last "${ARG_SHARDS} - 1")
  foreach(_shard RANGE ${_last})
    add_test(NAME ${_folder}/${ARG_NAME}/${_shard} COMMAND ${_target} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(${_folder}/${ARG_NAME}/${_shard} PROPERTIES ENVIRONMENT
                         "${_environment};GTEST_TOTAL_SHARDS=${ARG_SHARDS};GTEST_SHARD_INDEX=${_shard}"
                         COST ${ARG_COST})
  endforeach()
endfunction()

function(arcwheel_add_benchmark)
  if(NOT ARCWHEEL_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} benchmark::benchmark)
  target_compile_options(${ARG_NAME} PRIVATE ${ARCWHEEL_WARNINGS})
endfunction()

function(arcwheel_embed_text)
  cmake_parse_arguments(ARG "" "OUT;SYMBOL;FILE" "" ${ARGN})
  set(_file ${CMAKE_CURRENT_SOURCE_DIR}/${ARG_FILE})
  file(READ ${_file} _text)
  if(_text MATCHES "\\)embedded\"")
    message(FATAL_ERROR "${_file} holds the raw string's end marker )embedded\"")
  endif()
  set(_out ${PROJECT_BINARY_DIR}/generated/embedded/${ARG_SYMBOL}.cc)
  file(CONFIGURE OUTPUT ${_out} CONTENT
       "// Generated by arcwheel_embed_text from ${ARG_FILE}: do not edit.\nextern const char ${ARG_SYMBOL}[];\nconst char ${ARG_SYMBOL}[] = R\"embedded(@_text@)embedded\";\n" @ONLY)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_file})
  set(${ARG_OUT} ${_out} PARENT_SCOPE)
endfunction()
