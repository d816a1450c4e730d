-- issue 15: a sequence of structs whose element program is the member itself (the op counter recursed)
UPDATE topics SET ops = x'000A0701000000001000000000000400' || substr(ops, 17) WHERE name = 'viscera_ToolCommand'
