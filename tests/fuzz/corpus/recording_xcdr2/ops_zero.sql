-- a zeroed type program
UPDATE topics SET ops = zeroblob(length(ops)) WHERE name = 'viscera_ToolCommand'
