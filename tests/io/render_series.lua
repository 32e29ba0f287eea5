-- Writes the series tests/io/render.sh renders: two bonded rows of balls
-- pulled apart (bonded_rows.lua), so that the series carries a crack map;
-- prints "snapshots balls cracks".
--   seixo render_series.lua OUT.h5
local out = assert(arg[1], "usage: seixo render_series.lua OUT.h5")
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "bonded_rows.lua")()
local o = m:output{path = out, every = 100, fields = {"all"}}
m:cycle(1000)
print(o:count(), m:ball_count(), m:crack_count())
o:close()
