# SPDX-License-Identifier: Apache-2.0
# The physics core (mass-spring models and integrators): cases 1, 4, 5, 12, 14.
viscera_stability_test(NAME stab_step_limit SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_step_limit.c)
viscera_stability_test(NAME stab_large_steps SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_large_steps.c)
viscera_stability_test(NAME stab_degenerate SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_degenerate.c)
viscera_stability_test(NAME stab_energy SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_energy.c)
viscera_stability_test(NAME stab_nan SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_nan.c)
