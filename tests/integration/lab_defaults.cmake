# Issue 18: one set of defaults (the README's classroom block run verbatim),
# "nothing seen" explained, a clean exit shown as left. Domains 211-215.
viscera_integration_test(readme_classroom 211 readme_classroom_test.sh)
viscera_integration_test(nothing_seen 212 nothing_seen_test.sh)
viscera_integration_test(client_left 213 client_left_test.sh)
