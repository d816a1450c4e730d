-- found by fuzz_recording (seed 2 round 16, seed 3 round 167): a recorded deadline of 0 ns made the replayed writer spin for ever
UPDATE topics SET deadline_ns = 0 WHERE name = 'viscera_ToolCommand'
