# SPDX-License-Identifier: Apache-2.0
# Cutting (docs/numerics.md §5 case 15): 100 random scalpel cuts on the spleen-size PBD model.
viscera_stability_test(NAME stab_cut SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_cut.c)
