# SPDX-License-Identifier: Apache-2.0
# Contact that settles under a held probe (issue 17, items 1 and 7):
# stab_settle checks the implicit tool coupling; stab_settle_<scene> holds a
# tool on every organ of one shipped scene (one test per scene file, found
# when configuring).
viscera_stability_test(NAME stab_settle SOURCES ${CMAKE_CURRENT_LIST_DIR}/stab_settle.c)
if(TARGET stab_settle)
  file(GLOB VISCERA_SHIPPED_SCENES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/assets/scenes/*.yaml)
  foreach(scene ${VISCERA_SHIPPED_SCENES})
    get_filename_component(file ${scene} NAME)
    get_filename_component(stem ${scene} NAME_WE)
    add_test(NAME stab_settle_${stem} COMMAND stab_settle ${file})
    set_tests_properties(stab_settle_${stem} PROPERTIES LABELS stability TIMEOUT 120
      ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  endforeach()
endif()
