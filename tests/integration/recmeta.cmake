# SPDX-License-Identifier: Apache-2.0
# Session metadata of issue 6: who took part (participants and roles from
# USER_DATA) and replay pause with the original timing kept.
# Domains 178 (participants), 179 + 180 (pause: recorded, replayed).
viscera_integration_test(recorder_participants 178 recorder_participants_test.sh)
viscera_integration_test(replay_pause 179 replay_pause_test.sh)
