# SPDX-License-Identifier: Apache-2.0
# Issue 16 item 2: certificate subjects in recordings under DDS Security
# (rec_subject_test.sh). Domain 206.
viscera_integration_test(rec_subject 206 rec_subject_test.sh)
