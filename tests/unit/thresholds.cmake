# Palpation threshold tracker (common/training/thresholds.c): crossings with hysteresis,
# time above, contact measures, path length.
viscera_unit_test(NAME test_thresholds SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_thresholds.c LIBS viscera_training)
