# Organ sleeping over DDS (issue 7, load): a classroom seat sleeps while the
# trainee is away and wakes for the press. Domain 184.
viscera_integration_test(organ_sleep 184 sleep_test.sh)
# --rt-priority: exactly the loop thread is SCHED_FIFO (server, haptic); the
# refusal without CAP_SYS_NICE warns and runs on. Domain 185.
viscera_integration_test(rt_priority 185 rt_priority_test.sh)
