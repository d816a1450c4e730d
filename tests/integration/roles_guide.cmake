# SPDX-License-Identifier: Apache-2.0
# Guiding hand, client side (issue 7): two coupled haptic stations, guide 0.5,
# take-over with a press into the kidney, release. Domain 154. (Named to sort
# after lead.cmake, which defines viscera_integration_test.)
viscera_integration_test(guiding_hand 154 guide_test.sh)
