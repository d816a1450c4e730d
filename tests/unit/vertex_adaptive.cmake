# Vertex-based local deformation (seed 002 ch. 4) and adaptive area-based
# refinement of a surface mass-spring (seed 002 ch. 5).
viscera_unit_test(NAME test_vertex_based SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_vertex_based.c LIBS viscera_sim)
viscera_unit_test(NAME test_adaptive SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_adaptive.c LIBS viscera_sim)
