-- issue 15: a source time of INT64_MAX (replay waited for ever)
UPDATE samples SET source_ts_ns = 9223372036854775807 WHERE id = (SELECT id FROM samples WHERE kind = 0 ORDER BY id LIMIT 1 OFFSET 20)
