# SPDX-License-Identifier: Apache-2.0
# Fault tolerance of a seat (issue 7): clients killed or stalled, the server
# killed and resumed from its checkpoint, a damaged checkpoint. Domain 145.
viscera_integration_test(fault_tolerance 145 fault_tolerance_test.sh)
