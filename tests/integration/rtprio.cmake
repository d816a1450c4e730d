# SPDX-License-Identifier: Apache-2.0
# Real-time loop threads: viscera-server and viscera-haptic --rt-priority
# (common/vrt.c): one FIFO thread each, the refusal path. Domain 180.
viscera_integration_test(rt_priority 180 rt_priority_test.sh)

# PM QoS wake-up bound of the same two loops (common/cpu_wake.c): the request
# held while they run (the kernel's idle counters), the refusal path. Domain 175.
viscera_integration_test(cpu_wake 175 cpu_wake_test.sh)
