# Scene file parser: schema, defaults and every error class with its line.
viscera_unit_test(NAME test_scene SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_scene.c)
