# SPDX-License-Identifier: Apache-2.0
# The large-step integrator implicit_pcg on stiff and extreme cases (issue 17.3).
viscera_stability_test(NAME stab_implicit_pcg SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_implicit_pcg.c)
# Tool coupling out of the stability bound beyond mass-spring (issue 17.1).
viscera_stability_test(NAME stab_coupling_models SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_coupling_models.c)
