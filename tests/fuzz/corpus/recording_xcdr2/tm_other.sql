-- another topic's type mapping
UPDATE topics SET typemap = (SELECT typemap FROM topics WHERE name = 'viscera_Metrics') WHERE name = 'viscera_ToolCommand'
