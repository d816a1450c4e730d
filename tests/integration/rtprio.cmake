# SPDX-License-Identifier: Apache-2.0
# Real-time loop threads: viscera-server and viscera-haptic --rt-priority
# (common/vrt.c): one FIFO thread each, the refusal path. Domain 180.
viscera_integration_test(rt_priority 180 rt_priority_test.sh)
