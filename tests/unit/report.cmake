# Trainee measures (common/training/measures.c) on synthetic samples:
# hysteresis-consistent time above thresholds, contact and timing measures,
# gaps, path length, task pairing.
viscera_unit_test(NAME test_report_measures SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_report_measures.c
                  LIBS viscera_training)
