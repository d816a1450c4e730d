# Per-element stiffness factors (mass-spring springs, XPBD edges) and edge-only
# PBD meshes: refusals, force/energy/Jacobian consistency, rigid vs compliant.
viscera_unit_test(NAME test_element_scale SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_element_scale.c LIBS viscera_sim)
