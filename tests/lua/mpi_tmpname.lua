-- os.tmpname under mpirun (issue 16; test lua_mpi_tmpname through
-- mpi_same.sh): every rank runs the script, and m:save writes from rank 0
-- alone, so a path made by os.tmpname must be the same on every rank: rank
-- 0's. A model saved there loads on every rank and continues as the one
-- saved; a CSV written there through seixo.lab reads back on every rank.
-- After seixo.decompose(false) (a rank on its own, as in lab.calibrate)
-- each rank makes its own names and saves and loads its own model.
local lab = require "seixo.lab"
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
local base = os.tmpname()
m:save(base .. ".h5")
local loaded = seixo.load(base .. ".h5")
print("loaded", loaded:step(), loaded:hash() == m:hash())
m:cycle(100)
loaded:cycle(100)
print("continued", loaded:hash() == m:hash(), loaded:hash())
lab.write_csv(base, {"step", "balls"}, {{m:step(), m:ball_count()}})
local csv = require("seixo.util").read_csv(base)
print("csv", csv.columns.step[1], csv.columns.balls[1])
m:cycle(1) -- every rank has read the files
if seixo.rank() == 0 then os.remove(base .. ".h5"); os.remove(base) end
seixo.decompose(false)
local own = seixo.model{dim = 2}
own:material("g", {density = 2500, kn = 1e6, ks = 1e6})
own:ball{pos = {0, 0}, radius = 1e-3}
local path = os.tmpname()
own:save(path)
print("own model", own:ranks(), seixo.load(path):hash() == own:hash())
os.remove(path)
