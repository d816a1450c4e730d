# SPDX-License-Identifier: Apache-2.0
# The version every binary prints with --version (common/cli.c): the CMake
# project version, plus `git describe` of the source tree when it is a git
# checkout and git is installed (e.g. "0.1.0 (git a69fab4-dirty)"). Read at
# configure time: re-run cmake after a commit to refresh the git part.
set(VISCERA_VERSION_FULL "${PROJECT_VERSION}")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} describe --tags --always --dirty
                  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                  OUTPUT_VARIABLE _viscera_git_describe OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _viscera_git_rc ERROR_QUIET)
  if(_viscera_git_rc EQUAL 0 AND _viscera_git_describe MATCHES "^[A-Za-z0-9._+-]+$")
    set(VISCERA_VERSION_FULL "${PROJECT_VERSION} (git ${_viscera_git_describe})")
  endif()
endif()
message(STATUS "viscera version: ${VISCERA_VERSION_FULL}")
