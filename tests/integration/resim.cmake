# SPDX-License-Identifier: Apache-2.0
# Deterministic re-simulation (issue 6 part 3): record a real session, then
# viscera-resim reproduces its meshes; a stiffer material must fail. Domain 110.
if(TARGET viscera-resim)
  viscera_integration_test(resim 110 resim_test.sh)
endif()
