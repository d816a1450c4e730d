# SPDX-License-Identifier: Apache-2.0
# viscera-report per task and per seat, and the recording exports
# (issue 16 items 3, 4, 6). Domains 201-205.
if(TARGET viscera-report AND TARGET viscera-viewer)
  viscera_integration_test(report_tasks 201 report_tasks_test.sh)
endif()
if(TARGET viscera-report AND TARGET viscera-haptic)
  viscera_integration_test(report_lab 202 report_lab_test.sh)
endif()
if(TARGET viscera-recinfo AND TARGET viscera-viewer)
  viscera_integration_test(recinfo_mcap 203 recinfo_mcap_test.sh)
  set_tests_properties(recinfo_mcap PROPERTIES SKIP_RETURN_CODE 77)
endif()
if(TARGET viscera-recinfo AND TARGET viscera-viewer)
  viscera_integration_test(recinfo_export 204 recinfo_export_test.sh)
endif()
