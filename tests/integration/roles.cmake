# SPDX-License-Identifier: Apache-2.0
# The instructor's side of a lab (issue 7): the dashboard over several seats.
# Domains 147 (dashboard), 149 (SessionControl commands).
viscera_integration_test(dashboard 147 dashboard_test.sh)
viscera_integration_test(session_control 149 control_test.sh)
