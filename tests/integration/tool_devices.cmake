# SPDX-License-Identifier: Apache-2.0
# Devices and loss detection (issue 4). Domains 120-124.
# Liveliness: kill -9 of server and of haptic client, detected through the
# DDS liveliness of their tool writers.
viscera_integration_test(liveliness 120 liveliness_test.sh)
# Mouse/keyboard driving through the SDL2 window, under Xvfb.
find_program(VISCERA_XVFB_RUN xvfb-run)
if(VISCERA_BUILD_WINDOW AND VISCERA_XVFB_RUN)
  viscera_integration_test(window_drive 121 window_drive_test.sh)
elseif(VISCERA_BUILD_WINDOW)
  message(STATUS "window_drive test not registered: xvfb-run not found (package xvfb)")
endif()
# An SDK device that is not in this build: --device refuses it by name.
if(NOT VISCERA_DEVICE_FALCON)
  add_test(NAME haptic_device_absent COMMAND viscera-haptic --device falcon)
  set_tests_properties(haptic_device_absent PROPERTIES LABELS integration TIMEOUT 20
    PASS_REGULAR_EXPRESSION "device 'falcon' \\(Novint Falcon \\(libnifalcon\\)\\) is not in this build.*VISCERA_DEVICE_FALCON")
endif()
# --loop: only a scripted path plays over and over, and only one that ends
# where it begins (push_hold_kidney.traj ends 43 mm below its start).
add_test(NAME haptic_loop_refused COMMAND viscera-haptic --loop --device hd)
set_tests_properties(haptic_loop_refused PROPERTIES LABELS integration TIMEOUT 20
  PASS_REGULAR_EXPRESSION "--loop: only the scripted device plays a trajectory \\(--device is 'hd'\\)")
add_test(NAME haptic_loop_open_path COMMAND viscera-haptic --loop --wait-server 0.1
         --trajectory ${PROJECT_SOURCE_DIR}/assets/trajectories/push_hold_kidney.traj)
set_tests_properties(haptic_loop_open_path PROPERTIES LABELS integration TIMEOUT 20
  PASS_REGULAR_EXPRESSION "push_hold_kidney.traj: --loop needs the last sample back at the first: they are 43.0 mm apart")
# --start-on-answer: the scripted path from the server's first answer
# (nothing of it lost before the server matched the client), refused for a
# real device. Domain 196.
viscera_integration_test(start_on_answer 196 start_on_answer_test.sh)
add_test(NAME haptic_start_on_answer_refused COMMAND viscera-haptic --start-on-answer --device hd)
set_tests_properties(haptic_start_on_answer_refused PROPERTIES LABELS integration TIMEOUT 20
  PASS_REGULAR_EXPRESSION "--start-on-answer: only the scripted device plays a trajectory \\(--device is 'hd'\\)")
