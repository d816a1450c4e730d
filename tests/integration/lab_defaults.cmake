# SPDX-License-Identifier: Apache-2.0
# Issue 18: one set of defaults (the README's classroom block run verbatim),
# "nothing seen" explained, a clean exit shown as left. Domains 211-215.
viscera_integration_test(readme_classroom 211 readme_classroom_test.sh)
viscera_integration_test(nothing_seen 212 nothing_seen_test.sh)
viscera_integration_test(client_left 213 client_left_test.sh)
# The .deb: built by cpack from this build, checked, unpacked and run. Not in
# the sanitizer pass (a package of instrumented binaries proves nothing more).
if(NOT VISCERA_SANITIZE)
  viscera_integration_test(package_deb 214 package_test.sh)
  set_tests_properties(package_deb PROPERTIES SKIP_RETURN_CODE 77)
endif()
# Like the lab launcher tests: a whole sanitized lab (3 servers, viewers and
# trainees) fills the 2 cores by itself.
if(VISCERA_SANITIZE)
  set_tests_properties(readme_classroom PROPERTIES RUN_SERIAL TRUE)
endif()
