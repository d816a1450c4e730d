# Tasks started by the instructor (issue 7 "starts tasks"): scene
# `start: instructor`, viscera-control start-task. Domain 157.
if(TARGET viscera-recorder)
  viscera_integration_test(start_task 157 start_task_test.sh)
endif()
