-- issue 15: a NULL type information
UPDATE topics SET typeinfo = NULL WHERE name = 'viscera_ToolCommand'
