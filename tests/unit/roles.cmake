# Tool roles (issue 7): who drives each tool, the guide's mix, ASSIGN_TOOL /
# GUIDE validation, the writer-station cache and the scene `station:` key.
viscera_unit_test(NAME test_tool_roles SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tool_roles.c LIBS viscera_session)
