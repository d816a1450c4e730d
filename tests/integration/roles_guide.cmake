# SPDX-License-Identifier: Apache-2.0
# Guiding hand, client side (issue 7): two coupled haptic stations, guide 0.5,
# take-over with a press into the kidney, release. Domain 154. (Named to sort
# after lead.cmake, which defines viscera_integration_test.)
viscera_integration_test(guiding_hand 154 guide_test.sh)
# Each phase waits for 400 coupled ticks of each client: under heavy load
# (two busy loops beside it, load 6 on 2 cores) coupling blips made a run
# take 90-128 s; 300 s leaves room (the waits stop a hang at 60 s each).
set_tests_properties(guiding_hand PROPERTIES TIMEOUT 300)
