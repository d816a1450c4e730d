-- issue 15: INT64_MIN without a session row
DELETE FROM session;
UPDATE samples SET source_ts_ns = -9223372036854775808 WHERE id = (SELECT id FROM samples WHERE kind = 0 ORDER BY id LIMIT 1 OFFSET 20)
