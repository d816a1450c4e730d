# PBD / XPBD on tetrahedral meshes: gradients, constraint forces, recovery from
# inverted, flat, collapsed, scrambled and stretched starts, effective stiffness
# against iterations, a 1:1000 mass-ratio chain, rollback and the model wrapper.
viscera_unit_test(NAME test_pbd SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_pbd.c LIBS viscera_sim)
