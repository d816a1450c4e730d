# SPDX-License-Identifier: Apache-2.0
# The deployment kit (issue 7): deploy/lab.sh, the LAN configuration and the
# service units, run as users run them. Domains 161-165.
viscera_integration_test(lab_launcher 161 lab_launcher_test.sh)
viscera_integration_test(lab_launcher_secure 162 lab_launcher_secure_test.sh)
viscera_integration_test(lan_config 163 lan_config_test.sh)
viscera_integration_test(systemd_units 164 systemd_units_test.sh)
set_tests_properties(systemd_units PROPERTIES SKIP_RETURN_CODE 77)
# lab.sh --one-server: the seats in one server, on one physics thread (issue 17 item 6). Domain 173.
viscera_integration_test(lab_one_server 173 lab_one_server_test.sh)
# lab.sh --one-server --secure: one group identity for the process's seats. Domain 174.
viscera_integration_test(lab_one_server_secure 174 lab_one_server_secure_test.sh)
# lab.sh's printed commands pasted in another directory, PKI given by a
# relative path as in the README (--secure, one seat). Domain 229.
viscera_integration_test(lab_paste 229 lab_paste_test.sh)
# lab.sh --one-server with ten seats: each seat's split log holds its own
# figures only. Domain 230.
viscera_integration_test(lab_one_server_logs 230 lab_one_server_logs_test.sh)
# pki.sh rerun on a lab's PKI (adding a server group): identities already
# handed out stay valid. Domain 208.
viscera_integration_test(pki_rerun 208 pki_rerun_test.sh)
