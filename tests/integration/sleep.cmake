# SPDX-License-Identifier: Apache-2.0
# Organ sleeping over DDS (issue 7, load): a classroom seat sleeps while the
# trainee is away and wakes for the press. Domain 184.
viscera_integration_test(organ_sleep 184 sleep_test.sh)
