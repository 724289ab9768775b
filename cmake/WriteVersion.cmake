# Writes OUT, a header defining CROWDRECON_GIT_VERSION as `git describe
# --always --dirty` of SOURCE_DIR ("unknown" without git), and rewrites it only
# when the text changes, so that only its users recompile. Run at every build
# (see sweep/CMakeLists.txt): the version stored with results is that of the
# build, not of the last configure.
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
set(text "// Generated at build time by cmake/WriteVersion.cmake; do not edit.\n#pragma once\n#define CROWDRECON_GIT_VERSION \"${version}\"\n")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
