# SPDX-License-Identifier: Apache-2.0
# Numerics cases of docs/numerics.md §5 on tetrahedral meshes: 2 (stiffness ratio
# 1e6 inside one mesh) and 11 (360 and 720 degree twist, release).
viscera_stability_test(NAME stab_stiff_band SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_stiff_band.c)
viscera_stability_test(NAME stab_twist SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_twist.c)
