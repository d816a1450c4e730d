# SPDX-License-Identifier: Apache-2.0
# deploy/deb_check.sh (issue 18 item 3): apt install of the .deb on a clean
# Debian 12 and a session from the installed files, in a network namespace
# of its own (default domain). Label
# package-full: it needs root and downloads from the Debian mirror, so it is
# skipped (77) unless VISCERA_DEB_CHECK=1; deploy/README.md "Install and package".
if(NOT VISCERA_SANITIZE)
  add_test(NAME deb_check COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/deb_check_test.sh ${PROJECT_BINARY_DIR}
                                  ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/deb_check.out)
  set_tests_properties(deb_check PROPERTIES LABELS package-full TIMEOUT 1500 SKIP_RETURN_CODE 77
                                            RUN_SERIAL TRUE)
endif()
