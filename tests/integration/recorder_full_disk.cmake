# SPDX-License-Identifier: Apache-2.0
# Full disk while recording (issue 6 part 5): a recorder under a 512 KB
# file-size limit (ulimit -f) records a real session (server + scripted
# haptic client) beside a second recorder that is killed with SIGKILL
# mid-session; both files must read, and both must still give a report.
# Domain 101.
if(TARGET viscera-report AND TARGET viscera-recinfo)
  viscera_integration_test(recorder_full_disk 101 recorder_full_disk_test.sh)
endif()
