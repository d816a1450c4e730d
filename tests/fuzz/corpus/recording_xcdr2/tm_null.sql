-- issue 15: a NULL type mapping (dds_create_topic crashed)
UPDATE topics SET typemap = NULL WHERE name = 'viscera_ToolCommand'
