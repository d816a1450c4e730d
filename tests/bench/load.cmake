# SPDX-License-Identifier: Apache-2.0
# Classroom load benchmark (issue 7): deploy/load_bench.sh starts seats and
# light subscribers (delta_sub); the smoke test runs it for a few seconds.
add_executable(delta_sub ${CMAKE_CURRENT_LIST_DIR}/delta_sub.c)
target_link_libraries(delta_sub PRIVATE viscera_dds)
# The summary judges the seats against the seat alone, run before and after
# the lab: both runs' lines and a verdict against their spread.
add_test(NAME load_bench_smoke COMMAND bash -c
         "bash '${PROJECT_SOURCE_DIR}/deploy/load_bench.sh' --build '${PROJECT_BINARY_DIR}' --out '${CMAKE_CURRENT_BINARY_DIR}/load_smoke' --seats 2 --subscribers 4 --duration 12 --baseline 3 && grep -Eq '^  alone again after the lab: [0-9]{4,} steps, .*real-time ratio' '${CMAKE_CURRENT_BINARY_DIR}/load_smoke/summary.txt' && grep -Eq '^  step CPU median, seats against the seat alone: .*; alone again [0-9.]+ us [(][-+][0-9]+ %[)]: (unchanged within noise|slower than the seat alone beyond noise|no slower than the seat alone [(]faster beyond noise[)])$' '${CMAKE_CURRENT_BINARY_DIR}/load_smoke/summary.txt'")
set_tests_properties(load_bench_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=148")
# The same with the seats as threads of one server (--one-server, issue 17
# item 6): the process's log must come apart into one figures block per seat.
add_test(NAME load_bench_one_server_smoke COMMAND bash -c
         "bash '${PROJECT_SOURCE_DIR}/deploy/load_bench.sh' --build '${PROJECT_BINARY_DIR}' --out '${CMAKE_CURRENT_BINARY_DIR}/load_one' --seats 2 --subscribers 2 --duration 8 --baseline 2 --one-server --seat-threads 1 && grep -Eq '^  seat01: [0-9]{4,} steps, .*real-time ratio' '${CMAKE_CURRENT_BINARY_DIR}/load_one/summary.txt' && grep -Eq '^  seat02: [0-9]{4,} steps, .*real-time ratio' '${CMAKE_CURRENT_BINARY_DIR}/load_one/summary.txt' && grep -q 'in one server process (1 physics thread, each stepping its seats in turn)' '${CMAKE_CURRENT_BINARY_DIR}/load_one/summary.txt'")
set_tests_properties(load_bench_one_server_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=172")
# What sharing a core costs a busy seat's step, without DDS (issue 17 item 6).
add_executable(bench_seats ${CMAKE_CURRENT_LIST_DIR}/bench_seats.c)
target_link_libraries(bench_seats PRIVATE viscera_sim viscera_test_support)
add_test(NAME bench_seats_smoke COMMAND bench_seats --seats 1,2 --seconds 1.6)
set_tests_properties(bench_seats_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
add_test(NAME bench_seats_tick_smoke COMMAND bench_seats --seats 1,2 --seconds 1.6 --tick)
set_tests_properties(bench_seats_tick_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
# --rounds: the whole run twice and the verdict over the rounds (issue 17 item 6).
add_test(NAME load_bench_rounds_smoke COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/load_rounds_smoke.sh ${PROJECT_SOURCE_DIR}
         ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/load_rounds)
set_tests_properties(load_bench_rounds_smoke PROPERTIES LABELS bench TIMEOUT 180
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=177")
# --beside: the lab's last seat in a process of its own, set against the
# seat alone and against the one process's seats (issue 17 item 6).
add_test(NAME load_bench_beside_smoke COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/load_beside_smoke.sh ${PROJECT_SOURCE_DIR}
         ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/load_beside)
set_tests_properties(load_bench_beside_smoke PROPERTIES LABELS bench TIMEOUT 180
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=210")
# --neighbour: a second thread writes its own memory while the seats step;
# it must have run (passes counted) and the seats still be timed.
add_test(NAME bench_seats_neighbour_smoke COMMAND bench_seats --seats 1 --seconds 1.6 --neighbour 64)
set_tests_properties(bench_seats_neighbour_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
  PASS_REGULAR_EXPRESSION "1 +[0-9.]+ +[0-9.]+ +1.00x.*neighbour: [1-9][0-9]* passes over 64 kB")
# delta_sub counts a delta from before its join as history, not as a latency
# (a resting organ's last delta would otherwise read as seconds of latency).
add_test(NAME delta_sub_history COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/delta_sub_history.sh ${PROJECT_SOURCE_DIR}
         ${PROJECT_BINARY_DIR} ${CMAKE_CURRENT_BINARY_DIR}/delta_sub_history)
set_tests_properties(delta_sub_history PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=182")
# How the drive changes a busy seat's physics work (issue 17 item 6):
# deterministic, so the smoke run checks its figures' relation too: a
# probe held still on 5 % of the steps (then catching up) keeps more of
# the gallbladder awake than the even path.
add_executable(bench_drive ${CMAKE_CURRENT_LIST_DIR}/bench_drive.c)
target_link_libraries(bench_drive PRIVATE viscera_sim viscera_test_support)
add_test(NAME bench_drive_smoke COMMAND bash -c
         "e=$('$<TARGET_FILE:bench_drive>' --seconds 6 | sed -n 's/^bench_drive: mean \\([0-9.]*\\) .*/\\1/p') && h=$('$<TARGET_FILE:bench_drive>' --seconds 6 --holds 0.05 | sed -n 's/^bench_drive: mean \\([0-9.]*\\) .*/\\1/p') && echo \"even $e, 5 % holds $h\" && awk -v e=\"$e\" -v h=\"$h\" 'BEGIN { exit !(e > 100 && h > 1.1 * e) }'")
set_tests_properties(bench_drive_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
