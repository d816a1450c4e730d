# SPDX-License-Identifier: Apache-2.0
# The instructor's side of a lab (issue 7): the dashboard over several seats.
# Domains 147 (dashboard), 149 (SessionControl commands).
viscera_integration_test(dashboard 147 dashboard_test.sh)
viscera_integration_test(session_control 149 control_test.sh)
# Every instructor command of a secure seat reaches the lab's recording
# (viscera-control waits for the seat's other readers). Domain 205.
viscera_integration_test(control_recorded 205 control_recorded_test.sh)
