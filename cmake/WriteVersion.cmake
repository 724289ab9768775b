# Writes OUT, a header defining
# - CROWDRECON_GIT_VERSION as `git describe --always --dirty` of SOURCE_DIR
#   ("unknown" without git): what the build is called, for people;
# - CROWDRECON_SOURCE_FINGERPRINT: the first 16 hex digits of a SHA-256 over
#   the content of every source file of the tools (the folders in
#   SOURCE_FOLDERS, comma-separated, with the top CMakeLists.txt and
#   CMakePresets.json, less the files in SOURCE_EXCLUDE), the compiler and the
#   flags (BUILD_INFO): what a run's results depend on. Only files that write
#   pages from results already judged are left out (the validation report's
#   writer), so that a better page is drawn from the runs there are; the
#   presentation modules stay in, as computations use them too (the chest
#   load is in reports, synthetic footage is drawn by viz and read by media).
#   Two
#   builds with the same fingerprint give the same runs, whatever their
#   commits (a commit of documents, results or tests changes the version,
#   not the fingerprint), and a build with uncommitted edits has its own.
#   Sweeps, calibrations and validations reuse runs by it (docs/sweeps.md).
# It rewrites OUT only when the text changes, so that only its users
# recompile. Run at every build (see sweep/CMakeLists.txt): the version stored
# with results is that of the build, not of the last configure.
set(version "unknown")
if(GIT)
  execute_process(COMMAND "${GIT}" describe --always --dirty
                  WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE described OUTPUT_STRIP_TRAILING_WHITESPACE
                  ERROR_QUIET RESULT_VARIABLE result)
  if(result EQUAL 0 AND described)
    set(version "${described}")
  endif()
endif()

set(files "${SOURCE_DIR}/CMakeLists.txt" "${SOURCE_DIR}/CMakePresets.json")
string(REPLACE "," ";" folders "${SOURCE_FOLDERS}")
foreach(folder IN LISTS folders)
  file(GLOB_RECURSE found LIST_DIRECTORIES false
       "${SOURCE_DIR}/${folder}/*.cpp" "${SOURCE_DIR}/${folder}/*.hpp" "${SOURCE_DIR}/${folder}/*.h"
       "${SOURCE_DIR}/${folder}/*.c" "${SOURCE_DIR}/${folder}/*.cmake" "${SOURCE_DIR}/${folder}/CMakeLists.txt")
  list(APPEND files ${found})
endforeach()
string(REPLACE "," ";" excluded "${SOURCE_EXCLUDE}")
foreach(x IN LISTS excluded)
  list(REMOVE_ITEM files "${SOURCE_DIR}/${x}")
endforeach()
list(SORT files)
set(manifest "${BUILD_INFO}\n")
foreach(f IN LISTS files)
  if(EXISTS "${f}")
    file(SHA256 "${f}" digest)
    file(RELATIVE_PATH rel "${SOURCE_DIR}" "${f}")
    string(APPEND manifest "${rel} ${digest}\n")
  endif()
endforeach()
string(SHA256 fingerprint "${manifest}")
string(SUBSTRING "${fingerprint}" 0 16 fingerprint)

set(text "// Generated at build time by cmake/WriteVersion.cmake; do not edit.\n#pragma once\n#define CROWDRECON_GIT_VERSION \"${version}\"\n#define CROWDRECON_SOURCE_FINGERPRINT \"${fingerprint}\"\n")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
