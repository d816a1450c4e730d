# SPDX-License-Identifier: Apache-2.0
# CPack: `cpack -G DEB` in the build directory makes viscera_VERSION_ARCH.deb
# from the install() rules (cmake/install.cmake) with the prefix /usr. Its
# Depends are computed by dpkg-shlibdeps from the binaries' shared libraries
# (Cyclone DDS, assimp, yaml, sqlite3, png, cairo, OSMesa, SDL2: whatever this
# build links). postinst creates the units' user (sysusers.d).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME viscera)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "viscera")
set(CPACK_PACKAGE_CONTACT "viscera maintainers <viscera@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "networked soft-tissue surgery training platform (Cyclone DDS)")
set(CPACK_PACKAGE_DESCRIPTION "Simulation server, haptic clients, viewers, recorder, dashboard, report and \
re-simulation of the viscera training platform; every process talks over Eclipse Cyclone DDS.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# pki.sh (DDS Security identities) needs openssl; the units need systemd.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "openssl")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "systemd")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${PROJECT_SOURCE_DIR}/deploy/debian/postinst)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_STRIP_FILES ON)
include(CPack)
