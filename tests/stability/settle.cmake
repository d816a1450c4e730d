# Contact that settles under a held probe, every shipped scene; the tool
# spring out of the organ's stability bound (issue 17, items 1 and 7).
viscera_stability_test(NAME stab_settle SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_settle.c)
