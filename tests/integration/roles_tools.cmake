# SPDX-License-Identifier: Apache-2.0
# Tool roles on the server (issue 7): assignment, take-over and guiding hand
# with real processes (two haptic stations, viscera-control). Domain 151.
add_executable(roles_watch ${CMAKE_CURRENT_LIST_DIR}/roles_watch.c)
target_link_libraries(roles_watch PRIVATE viscera_dds)
viscera_integration_test(tool_roles 151 roles_tools_test.sh)
