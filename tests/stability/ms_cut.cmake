# SPDX-License-Identifier: Apache-2.0
# Three-stage mass-spring cutting: case 15 (100 random cuts).
viscera_stability_test(NAME stab_ms_cut SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_ms_cut.c)
