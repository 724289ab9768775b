# Compiler settings for project targets: warnings as errors, no floating-point
# contraction (results must not depend on whether the compiler fuses a*b+c),
# optional sanitizers.
add_library(crowdrecon_options INTERFACE)
target_compile_options(crowdrecon_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:
  -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
  -Wnon-virtual-dtor -Woverloaded-virtual -Wdouble-promotion
  -Werror
  -ffp-contract=off>
  # CUDA sources (the optional force computation on a GPU): no contraction
  # on the device nor in their host code, as above; warnings as errors.
  # GCC 12 at -O3 reports false positives inside libstdc++ for these two
  # (GCC bugs 105329 and 105562 family); they are not errors in our code.
  $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<CXX_COMPILER_ID:GNU>>:-Wno-restrict -Wno-null-dereference>
  $<$<COMPILE_LANGUAGE:CUDA>:--fmad=false -Xcompiler=-ffp-contract=off --expt-relaxed-constexpr>)
if(CROWDRECON_SANITIZE)
  # (C++ sources only: nvcc takes no such flags; the CUDA file's host code,
  # a few copies and launches, goes unsanitised.)
  target_compile_options(crowdrecon_options INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined>
    # GCC 12's flow analysis under the sanitizers' instrumentation reports
    # uninitialised members inside libstdc++'s std::regex and std::function
    # (false positives, as the release build shows); not errors in our code.
    $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<CXX_COMPILER_ID:GNU>>:-Wno-maybe-uninitialized>)
  target_link_options(crowdrecon_options INTERFACE -fsanitize=address,undefined)
  # Eigen's allocations the way Debian's Ceres makes them. Under ASan Eigen
  # stops assuming malloc's 16-byte alignment (it checks __SANITIZE_ADDRESS__)
  # and allocates with an offset of its own, while libceres, built without
  # ASan, frees with plain free(): an Eigen matrix whose resize() the linker
  # took from one of our translation units and whose memory Ceres freed was
  # a bad free (Ceres' covariance, Surrogate.CovarianceIsTheInverseOfJtJ...).
  # ASan's malloc is 16-byte aligned on x86-64 (measured: 0 of 4,999 sizes
  # misaligned), so the assumption holds here too and both sides agree.
  target_compile_definitions(crowdrecon_options INTERFACE EIGEN_MALLOC_ALREADY_ALIGNED=1)
  # Programs linked as position-dependent executables: as PIE (Debian's
  # default), the instrumented crowdrecon carried 50 MB of dynamic
  # relocations (2 million, ASan's and UBSan's metadata) that the loader
  # applied at every start: 389 ms of CPU for `crowdrecon --help`, 151 ms
  # without. The command-line tests start it ~1,000 times and ctest starts a
  # test program for every unit test. (Libraries keep their code model.)
  target_link_options(crowdrecon_options INTERFACE $<$<STREQUAL:$<TARGET_PROPERTY:TYPE>,EXECUTABLE>:-no-pie>)
endif()
if(CROWDRECON_FUZZ)
  # Every project library instrumented for libFuzzer's coverage and checked by
  # ASan and UBSan (any undefined behaviour aborts: a crash to the fuzzer);
  # the harnesses add -fsanitize=fuzzer (libFuzzer's main) when linked.
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "CROWDRECON_FUZZ needs clang (libFuzzer): use the `fuzz` preset (docs/fuzzing.md)")
  endif()
  target_compile_options(crowdrecon_options INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
    -fno-omit-frame-pointer -Wno-unknown-warning-option>)
  target_link_options(crowdrecon_options INTERFACE -fsanitize=address,undefined)
endif()

# Mark a third-party target's include directories as system includes.
function(crowdrecon_system_includes target)
  get_target_property(aliased ${target} ALIASED_TARGET)
  if(aliased)
    set(target ${aliased})
  endif()
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  if(dirs)
    set_target_properties(${target} PROPERTIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${dirs}")
  endif()
endfunction()

# Optimisation levels by kind of code. The build type's flags apply to the
# libraries; CROWDRECON_HOT_FLAGS (after them) to the code where runs spend
# their time (engine, geometry, common's JSON parsing); CROWDRECON_GLUE_FLAGS
# to the thin code around it (the command line, the tests, the fuzz
# harnesses). Release: -O2, hot -O3, glue -O1. Sanitize: -O1, glue -O0 (it
# compiles 40 % faster and the tests spend their time in the libraries: with
# every library at -O0 too, the sanitizer tests took 733 s of CPU against 431).
# The results do not depend on it: no -ffast-math anywhere, no contraction.
set(CROWDRECON_HOT_FLAGS "" CACHE STRING "Compiler flags for the hot libraries (engine, geometry, common), after the build type's")
set(CROWDRECON_GLUE_FLAGS "" CACHE STRING "Compiler flags for the command line, tests and fuzz harnesses, after the build type's")
function(crowdrecon_hot_code target)
  if(CROWDRECON_HOT_FLAGS)
    separate_arguments(flags UNIX_COMMAND "${CROWDRECON_HOT_FLAGS}")
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${flags}>)
  endif()
endfunction()
# For every target defined after it in the calling directory. Glue code is
# also compiled as unity sources (CMake's UNITY_BUILD, 8 files to a unit):
# each of its files spends most of its compile time on the same header-only
# libraries (CLI11, nlohmann_json, GoogleTest's templates), which a unit
# then compiles once for eight. CROWDRECON_UNITY_GLUE=OFF compiles file by file.
option(CROWDRECON_UNITY_GLUE "Compile the command line and tests as unity sources" ON)
macro(crowdrecon_glue_code_directory)
  if(CROWDRECON_GLUE_FLAGS)
    separate_arguments(crowdrecon_glue_flags UNIX_COMMAND "${CROWDRECON_GLUE_FLAGS}")
    add_compile_options($<$<COMPILE_LANGUAGE:CXX>:${crowdrecon_glue_flags}>)
  endif()
  if(CROWDRECON_UNITY_GLUE)
    set(CMAKE_UNITY_BUILD ON)
    set(CMAKE_UNITY_BUILD_BATCH_SIZE 8)
  endif()
endmacro()

# Cold code: parsers, importers and writers that run once per input or per
# output (venue import and JSON, sweep files and tables, phase diagrams and
# run pictures, analysis output, output guards). CROWDRECON_COLD_FLAGS (after
# the build type's) go to these files only; the sanitizer build compiles them
# at -O0, which halves their compile time (venue_import_raster.cpp: 65 s at
# -O1, 34 s at -O0) and costs the tests little: the tests spend their time in
# the engine, the geometry of bodies and the run loop, which stay at -O1.
set(CROWDRECON_COLD_FLAGS "" CACHE STRING "Compiler flags for cold code (crowdrecon_cold_code), after the build type's")
function(crowdrecon_cold_code)
  if(CROWDRECON_COLD_FLAGS)
    separate_arguments(flags UNIX_COMMAND "${CROWDRECON_COLD_FLAGS}")
    set_source_files_properties(${ARGN} DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTIES COMPILE_OPTIONS "${flags}")
  endif()
endfunction()

# Sources that only call into a third-party library (CGAL templates, no logic
# of ours beyond a few lines) are left uninstrumented in the sanitizer build:
# instrumenting CGAL's inlined code triples their compile time (135 s against
# 48 s for outline_cgal.cpp) and checks no code of ours. The fuzzers still run
# them under clang's ASan and UBSan (docs/fuzzing.md). Nor are they hot code
# for the optimiser: the release build compiles them at -O2, not -O3
# (outline_cgal.cpp: 69 s at -O3, 56 s at -O2).
function(crowdrecon_third_party_only)
  if(CROWDRECON_SANITIZE)
    set_source_files_properties(${ARGN} DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}
      PROPERTIES COMPILE_OPTIONS "-fno-sanitize=all")
  elseif(CROWDRECON_HOT_FLAGS)
    set_source_files_properties(${ARGN} DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} PROPERTIES COMPILE_OPTIONS "-O2")
  endif()
endfunction()
