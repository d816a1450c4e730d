# SPDX-License-Identifier: Apache-2.0
# Real-time loop threads: viscera-server and viscera-haptic --rt-priority
# (common/vrt.c): one FIFO thread each, the refusal path. Domain 180.
viscera_integration_test(rt_priority 180 rt_priority_test.sh)

# Where the loops run: the PM QoS wake-up bound of the same two loops
# (common/cpu_wake.c; the request held while they run, by the kernel's idle
# counters; the refusal path) and the server's --physics-cpus
# (common/cpu_pin.c). Domain 175.
viscera_integration_test(loop_cpus 175 loop_cpus_test.sh)

# The deploy scripts pass those options on: lab.sh --cpu-wake-latency,
# load_bench.sh --cpu-wake-latency / --server-cpus / --client-cpus /
# --physics-cpus (needs the benchmarks' delta_sub; skipped without). Domain 176.
viscera_integration_test(script_cpus 176 script_cpus_test.sh)
set_tests_properties(script_cpus PROPERTIES SKIP_RETURN_CODE 77)
