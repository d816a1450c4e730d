# SPDX-License-Identifier: Apache-2.0
# Man pages, generated at build time by help2man (Debian package help2man,
# deploy/install_deps.sh) from each binary's --help and --version, and
# installed to share/man/man1. Without help2man the build goes on without
# them (a warning says so).
find_program(HELP2MAN help2man)
set(VISCERA_MAN_NAMES
    "viscera-server=simulation server of one seat (scene, physics, DDS)"
    "viscera-resim=re-simulate a recording and check it reproduces"
    "viscera-haptic=haptic client (scripted or real device) at 1 kHz"
    "viscera-viewer=offscreen PNG frames or a window of a seat"
    "viscera-dashboard=the instructor's grid of a lab's seats"
    "viscera-control=the instructor's commands to a seat"
    "viscera-recorder=record every topic of a partition into SQLite"
    "viscera-recinfo=read a viscera recording"
    "viscera-replay=republish a viscera recording"
    "viscera-report=trainee report from recordings"
    "viscera-asset=mesh import report, conversion and tetrahedral meshing"
    "viscera-organ-gen=regenerate the organ meshes")
if(NOT HELP2MAN)
  message(WARNING "help2man not found: no man pages (deploy/install_deps.sh installs it)")
  return()
endif()
set(VISCERA_MAN_PAGES "")
foreach(entry ${VISCERA_MAN_NAMES})
  string(FIND "${entry}" "=" eq)
  string(SUBSTRING "${entry}" 0 ${eq} bin)
  math(EXPR eq1 "${eq} + 1")
  string(SUBSTRING "${entry}" ${eq1} -1 what)
  if(NOT TARGET ${bin})
    continue()
  endif()
  set(page ${PROJECT_BINARY_DIR}/man/${bin}.1)
  add_custom_command(OUTPUT ${page}
                     COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
                     COMMAND ${CMAKE_COMMAND} -E env ASAN_OPTIONS=detect_leaks=0
                             ${HELP2MAN} --no-info --no-discard-stderr --section 1 --source viscera
                             --name "${what}" --output ${page} $<TARGET_FILE:${bin}>
                     DEPENDS ${bin}
                     COMMENT "help2man ${bin}"
                     VERBATIM)
  list(APPEND VISCERA_MAN_PAGES ${page})
  install(FILES ${page} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
endforeach()
add_custom_target(viscera_manpages ALL DEPENDS ${VISCERA_MAN_PAGES})
