# SPDX-License-Identifier: Apache-2.0
# Report tool end to end (issue 6 part 4): two real palpation sessions
# (expert and novice trajectories) recorded, reported, and the report's
# figures checked against the servers' own PALPATION lines; a truncated copy,
# a foreign SQLite file and random bytes. Domain 100.
if(TARGET viscera-report AND TARGET viscera-viewer)
  viscera_integration_test(report_e2e 100 report_test.sh)
endif()
# A scene without palpation thresholds: the report shows them as unset, not 0 N. Domain 192.
if(TARGET viscera-report AND TARGET viscera-viewer)
  viscera_integration_test(report_no_thresholds 192 report_no_thresholds_test.sh)
endif()
# A cutting session: the report gives the scalpel's cuts as the server ended them. Domain 170.
if(TARGET viscera-report AND TARGET viscera-viewer)
  viscera_integration_test(report_cuts 170 report_cuts_test.sh)
endif()
