# SPDX-License-Identifier: Apache-2.0
# Several seats in one server process (viscera-server --seats, issue 17
# item 6): each seat its own session on its own partition. Domain 167.
viscera_integration_test(server_seats 167 seats_test.sh)
