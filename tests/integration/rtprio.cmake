# SPDX-License-Identifier: Apache-2.0
# Real-time loop threads: viscera-server and viscera-haptic --rt-priority
# (common/vrt.c): one FIFO thread each, the refusal path. Domain 180.
viscera_integration_test(rt_priority 180 rt_priority_test.sh)

# Where the loops run: the PM QoS wake-up bound of the same two loops
# (common/cpu_wake.c; the request held while they run, by the kernel's idle
# counters; the refusal path) and the server's --physics-cpus
# (common/cpu_pin.c). Domain 175.
viscera_integration_test(loop_cpus 175 loop_cpus_test.sh)
