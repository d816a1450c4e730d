# SPDX-License-Identifier: Apache-2.0
# DDS Security (issue 7): PKI from deploy/pki.sh, access control per role and
# seat, unauthenticated participants shut out. Domain 141.
viscera_integration_test(security 141 security_test.sh)
