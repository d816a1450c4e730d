# Collision queries: AABB tree over triangles, node grid, cylinder tool.
viscera_unit_test(NAME test_aabb_tree SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_aabb_tree.c LIBS viscera_sim)
viscera_unit_test(NAME test_node_grid SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_node_grid.c LIBS viscera_sim)
viscera_unit_test(NAME test_cylinder SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cylinder.c LIBS viscera_sim)
