# The deployment kit (issue 7): deploy/lab.sh, the LAN configuration and the
# service units, run as users run them. Domains 161-165.
viscera_integration_test(lab_launcher 161 lab_launcher_test.sh)
viscera_integration_test(lab_launcher_secure 162 lab_launcher_secure_test.sh)
viscera_integration_test(lan_config 163 lan_config_test.sh)
