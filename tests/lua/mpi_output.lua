-- An output series of a decomposed model (tests/lua/mpi_pour.sh): a 2D pour
-- with a history writes a series every 500 steps; rank 0 writes the file
-- for all ranks, and every rank gets the same answers (o:count(), o:path())
-- and the same errors (a series or a save at a path that cannot be written
-- raises rank 0's error on every rank, which pcall catches everywhere).
-- mpi_pour.sh compares the series file (h5dump) with the serial run's.
--   mpi_output.lua FILE.h5
local file = arg[1]
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5})
m:generate{count = 400, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.06, 0.08}}}, seed = 5}
m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
m:wall{kind = "line", point = {0, 0}, normal = {1, 0}}
m:wall{kind = "line", point = {0.06, 0}, normal = {-1, 0}}
m:history("ke", function(mm) return mm:energy().kinetic end, {every = 50})
local nowhere = file .. ".missing/series.h5"
-- (print shows rank 0's answers; the asserts check every rank's)
local ok, err = pcall(m.output, m, {path = nowhere, every = 100})
assert(not ok and err:find("cannot create", 1, true), err)
print("bad series path raises", not ok, tostring(err):match("': (.*)$"))
ok, err = pcall(m.save, m, nowhere)
assert(not ok and err:find("cannot create", 1, true), err)
print("bad save path raises", not ok, tostring(err):match("': (.*)$"))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
local o = m:output{path = file, every = 500}
m:cycle(1200)
assert(o:count() == 3 and o:path() == file) -- steps 0, 500, 1000
print("count", o:count(), "path", o:path() == file)
m:cycle(800)
o:write()
-- the open series' file refuses other writers on every rank: only rank 0
-- opened it, so ranks above 0 had renamed a CSV over it
ok, err = pcall(m.history_csv, m, file)
assert(not ok and err:find("an output series open", 1, true), err)
ok, err = pcall(m.save, m, file)
assert(not ok and err:find("an output series open", 1, true), err)
print("the open series' file refused", not ok)
assert(o:count() == 6 and tostring(o):find("6 snapshots", 1, true)) -- and 1500, 2000, now
print("count", o:count(), tostring(o):match("%(.*%)"))
o:close()
assert(o:count() == 6) -- closed: what it wrote
print("closed", o:count(), pcall(o.write, o))
print("hash", m:hash())
