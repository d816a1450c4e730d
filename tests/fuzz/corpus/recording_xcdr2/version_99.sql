-- issue 15: an unknown format version
UPDATE session SET format_version = 99;
PRAGMA user_version = 99
