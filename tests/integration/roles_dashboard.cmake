# SPDX-License-Identifier: Apache-2.0
# The instructor's dashboard beyond the grid (issue 7): the focus view of a
# seat written headless, and the live window under Xvfb driven by scripted
# keys and clicks. Domains 159 (window), 160 (focus).
if(TARGET viscera-dashboard)
  add_executable(png_region ${CMAKE_CURRENT_LIST_DIR}/png_region.c)
  target_link_libraries(png_region PRIVATE PkgConfig::PNG)
  viscera_integration_test(dashboard_focus 160 dashboard_focus_test.sh)
  find_program(VISCERA_XVFB_RUN xvfb-run)
  if(VISCERA_BUILD_WINDOW AND VISCERA_XVFB_RUN)
    viscera_integration_test(dashboard_window 159 dashboard_window_test.sh)
  elseif(VISCERA_BUILD_WINDOW)
    message(STATUS "dashboard_window test not registered: xvfb-run not found (package xvfb)")
  endif()
endif()
# A dashboard started after the seat's trainee pressed: past crossings are
# counted, not shown as a live alert. Domain 215.
if(TARGET viscera-dashboard)
  viscera_integration_test(dashboard_late 215 dashboard_late_test.sh)
endif()
