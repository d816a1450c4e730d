# Issue 18: one set of defaults (the README's classroom block run verbatim),
# "nothing seen" explained, a clean exit shown as left. Domains 211-215.
viscera_integration_test(readme_classroom 211 readme_classroom_test.sh)
