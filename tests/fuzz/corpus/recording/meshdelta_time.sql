-- issue 15: a MeshDelta header whose sim time has bit 44 set (+17,592 s; resim planned 17.6 million steps)
UPDATE samples SET cdr = substr(cdr, 1, 20) || x'00c09a2f00100000' || substr(cdr, 29) WHERE id = (SELECT s.id FROM samples s JOIN topics t ON t.id = s.topic_id WHERE t.name = 'viscera_MeshDelta' ORDER BY s.id LIMIT 1 OFFSET 5)
