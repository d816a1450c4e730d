# Tools, objects and tasks (issue 4): scene keys, grasping, stones, tasks.
viscera_unit_test(NAME test_scene_tools SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_scene_tools.c)
# Grasp, stone removal, tool-tool contact and tasks on the real runtime.
viscera_unit_test(NAME test_tool_actions SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tool_actions.c LIBS viscera_sim)
# Friction cone and force shading on the god-object proxy.
viscera_unit_test(NAME test_proxy_friction SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_proxy_friction.c LIBS viscera_sim)
# Tool shafts: the cylinder node test and segment-triangle crossings (tree vs scan).
viscera_unit_test(NAME test_shaft SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_shaft.c LIBS viscera_sim)
# Tasks started by the instructor (scene `start:`, SessionControl START_TASK).
viscera_unit_test(NAME test_task_start SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_task_start.c LIBS viscera_session)
