# SPDX-License-Identifier: Apache-2.0
viscera_stability_test(NAME stab_haptic SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_haptic.c LIBS viscera_haptic)
