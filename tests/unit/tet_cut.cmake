# Progressive tetrahedral cutting: every split case on one tetrahedron, cuts
# through a box grid (also through nodes and along faces), the seed's
# rest-length rules, and the PBD model cut in two under gravity.
viscera_unit_test(NAME test_tet_cut SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tet_cut.c LIBS viscera_sim)
