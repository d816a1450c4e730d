# Topology changes end to end (adaptive refinement/simplification, cutting):
# the runtime re-attaches contacts and rebuilds the collision tree, the
# publisher sends a new keyframe per topology version, the viewer's organ
# state follows versions.
viscera_unit_test(NAME test_topology_runtime SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_topology_runtime.c
                  LIBS viscera_sim)
viscera_unit_test(NAME test_publisher_retopo SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_publisher_retopo.c
                  LIBS viscera_session)
