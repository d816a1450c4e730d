# SPDX-License-Identifier: Apache-2.0
# install(): what `cmake --install` and the .deb put where (GNUInstallDirs
# under CMAKE_INSTALL_PREFIX, /usr/local by default, /usr in the .deb):
#   bin/                      every viscera binary this build has
#   share/viscera/assets/     scenes, meshes, trajectories (the binaries find
#                             them from any directory: common/data_path.h)
#   share/viscera/deploy/     the Cyclone DDS configurations and pki.sh (the
#                             binaries' default loopback configuration)
#   share/man/man1/           the man pages (cmake/manpages.cmake)
#   share/bash-completion/completions/<binary>
#   lib/systemd/system/       the service units, ExecStart pointing at bin/
#   lib/sysusers.d/viscera.conf   the units' user
#   share/doc/viscera/copyright   the LICENSE
set(VISCERA_BINARIES viscera-server viscera-resim viscera-haptic viscera-viewer viscera-dashboard viscera-control
                     viscera-recorder viscera-recinfo viscera-replay viscera-report viscera-asset viscera-organ-gen)
set(VISCERA_INSTALLED_BINARIES "")
foreach(bin ${VISCERA_BINARIES})
  if(TARGET ${bin})
    install(TARGETS ${bin} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    list(APPEND VISCERA_INSTALLED_BINARIES ${bin})
    install(FILES ${PROJECT_SOURCE_DIR}/deploy/completion/viscera.bash
            DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME ${bin})
  endif()
endforeach()

set(VISCERA_DATA_DEST ${CMAKE_INSTALL_DATADIR}/viscera)
foreach(dir scenes meshes trajectories)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/assets/${dir} DESTINATION ${VISCERA_DATA_DEST}/assets
          PATTERN "*.md" EXCLUDE)
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/assets/scenes/README.md DESTINATION ${VISCERA_DATA_DEST}/assets/scenes)
file(GLOB VISCERA_DDS_CONFIGS ${PROJECT_SOURCE_DIR}/deploy/*.xml)
install(FILES ${VISCERA_DDS_CONFIGS} DESTINATION ${VISCERA_DATA_DEST}/deploy)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/deploy/pki.sh DESTINATION ${VISCERA_DATA_DEST}/deploy)

# The units name /usr/local/bin/ (cmake --install's default); installed, they
# name the bin/ of the prefix actually installed to (/usr/bin in the .deb),
# rewritten at install time so `cpack` (prefix /usr) gets it right too.
file(GLOB VISCERA_UNITS ${PROJECT_SOURCE_DIR}/deploy/systemd/*.service)
foreach(unit ${VISCERA_UNITS})
  get_filename_component(name ${unit} NAME)
  install(CODE "
    file(READ \"${unit}\" _u)
    string(REPLACE \"/usr/local/bin/\" \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}/\" _u \"\${_u}\")
    file(WRITE \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/lib/systemd/system/${name}\" \"\${_u}\")
    message(STATUS \"Installing: \$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/lib/systemd/system/${name}\")")
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/deploy/systemd/viscera.sysusers DESTINATION lib/sysusers.d RENAME viscera.conf)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR} RENAME copyright)
