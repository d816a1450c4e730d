# Tetrahedral meshes: the box grid, building from surfaces and the embedding.
viscera_unit_test(NAME test_tet_mesh SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tet_mesh.c)
# The same source on the third-party organs of ../shared (skips with 77 without them).
viscera_unit_test(NAME test_tet_mesh_shared SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tet_mesh.c)
target_compile_definitions(test_tet_mesh_shared PRIVATE TET_TEST_SHARED=1)

# The asset tool is a client program (absent with VISCERA_SIM_ONLY).
if(TARGET viscera-asset)
# viscera-asset tet: the report for an organ, a clear failure (exit 1) on the open
# tissue patch, and bad usage (exit 2) for a bad --size.
add_test(NAME asset_tool_tet COMMAND viscera-asset tet ${PROJECT_SOURCE_DIR}/assets/meshes/spleen.obj --size 0.005)
set_tests_properties(asset_tool_tet PROPERTIES LABELS unit
  PASS_REGULAR_EXPRESSION "nodes +[0-9]+\n +tetrahedra +[0-9]+\n +build time .*quality +min 0\\.[2-9].*ratio (0\\.9[5-9]|1\\.0[0-4]).*outside +[0-9]+ of 600")
add_test(NAME asset_tool_tet_fails
  COMMAND sh -c "\"$1\" tet \"$2/tissue_block.obj\" 2>\"$3/tet_patch.err\"; rc=$?; cat \"$3/tet_patch.err\"; \
test $rc -eq 1 && grep -q 'tissue_block.obj: .*nothing is inside' \"$3/tet_patch.err\" && \
{ \"$1\" tet \"$2/spleen.obj\" --size 0; test $? -eq 2; } && { \"$1\" tet \"$2/spleen.obj\" --size 0.0001; test $? -eq 1; } && \
{ \"$1\" tet; test $? -eq 2; }"
  sh $<TARGET_FILE:viscera-asset> ${PROJECT_SOURCE_DIR}/assets/meshes ${CMAKE_CURRENT_BINARY_DIR})
set_tests_properties(asset_tool_tet_fails PROPERTIES LABELS unit)
endif()
