# SPDX-License-Identifier: Apache-2.0
# Network hardening (issue 15.1, 15.2, 14.2 tool streams): floods and
# impostors against a seat. Domains 186-190.
add_executable(flood_commands ${CMAKE_CURRENT_LIST_DIR}/flood_commands.c)
target_link_libraries(flood_commands PRIVATE viscera_dds)
viscera_integration_test(flood_commands 186 flood_commands_test.sh)
add_executable(impostor ${CMAKE_CURRENT_LIST_DIR}/impostor.c)
target_link_libraries(impostor PRIVATE viscera_dds)
viscera_integration_test(impostor 187 impostor_test.sh)
viscera_integration_test(command_order 189 command_order_test.sh)
# The force-log checker of failover and fault_tolerance (issue 15.6).
add_executable(force_check ${CMAKE_CURRENT_LIST_DIR}/force_check.c)
target_link_libraries(force_check PRIVATE m)
