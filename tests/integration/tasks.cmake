# SPDX-License-Identifier: Apache-2.0
# Tasks started by the instructor (issue 7 "starts tasks"): scene
# `start: instructor`, viscera-control start-task. Domain 157.
if(TARGET viscera-recorder)
  viscera_integration_test(start_task 157 start_task_test.sh)
endif()
# Cut organs (xpbd spleen, mass-spring sheet) resumed from their
# checkpoint after kill -9 (checkpoint format 2). Domain 158.
if(TARGET viscera-recorder) # rec_topology: topology.cmake, same condition
  viscera_integration_test(checkpoint_cut 158 checkpoint_cut_test.sh)
endif()
