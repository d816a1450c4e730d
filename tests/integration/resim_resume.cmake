# SPDX-License-Identifier: Apache-2.0
# Issue 16: a session resumed from a checkpoint re-simulates bit for bit from
# its recording alone (resim_resume_test.sh). Domain 207.
if(TARGET viscera-resim)
  viscera_integration_test(resim_resume 207 resim_resume_test.sh)
endif()
