-- found by fuzz_recording (seed 4 round 909: one overwritten byte): a finite deadline of 292 years hung the replayed writer's deletion
UPDATE topics SET deadline_ns = 9223372036485677055 WHERE name = 'viscera_ToolRole'
