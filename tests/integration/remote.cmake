# SPDX-License-Identifier: Apache-2.0
# Remote sessions (issue 14, client side): short blips while the hand is
# inside the organ, the server stalled and then the client stalled. Domain 223.
viscera_integration_test(haptic_blip 223 blip_test.sh)
# It judges loss detection and ramps of 1 kHz processes: alone under the sanitizers.
if(VISCERA_SANITIZE)
  set_tests_properties(haptic_blip PROPERTIES RUN_SERIAL TRUE)
endif()
