# SPDX-License-Identifier: Apache-2.0
# Off loopback, secure by default (issue 14 item 5): every DDS program
# refuses a non-loopback configuration without DDS Security unless told
# --insecure (or VISCERA_INSECURE=1). Domain 227.
viscera_integration_test(insecure_start 227 insecure_start_test.sh)
