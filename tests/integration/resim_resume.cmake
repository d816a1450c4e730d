# SPDX-License-Identifier: Apache-2.0
# Issue 16: a session resumed from a checkpoint re-simulates bit for bit from
# its recording alone (resim_resume_test.sh). Domain 207.
if(TARGET viscera-resim)
  viscera_integration_test(resim_resume 207 resim_resume_test.sh)
endif()
# A server killed and resumed while the recorder ran: each run of the server re-simulates
# on its own (resim_restart_test.sh, viscera-resim --run). Domain 169.
if(TARGET viscera-resim)
  viscera_integration_test(resim_restart 169 resim_restart_test.sh)
endif()
