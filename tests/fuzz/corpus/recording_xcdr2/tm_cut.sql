-- issue 15: a cut type mapping
UPDATE topics SET typemap = substr(typemap, 1, 300) WHERE name = 'viscera_ToolCommand'
