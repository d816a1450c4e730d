# SPDX-License-Identifier: Apache-2.0
# Tool coupling out of the stability bound: adaptive_mass_spring, pbd, xpbd (issue 17.1).
viscera_stability_test(NAME stab_coupling_adaptive SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_coupling_adaptive.c)
viscera_stability_test(NAME stab_coupling_pbd SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_coupling_pbd.c)
