# The instructor's side of a lab (issue 7): the dashboard over several seats.
# Domain 147.
viscera_integration_test(dashboard 147 dashboard_test.sh)
