# SPDX-License-Identifier: Apache-2.0
# The scalpel end to end (issue 5, parts 3 and 5): xpbd spleen and
# mass-spring sheet cut over DDS, early and late viewers on the server's
# cut mesh, recording with every topology version. Domain 150.
if(TARGET viscera-viewer)
  viscera_integration_test(scalpel_cut 150 scalpel_cut_test.sh)
endif()
