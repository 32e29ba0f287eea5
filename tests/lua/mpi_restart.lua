-- A 2D pour saved halfway and continued, for the MPI decomposition test
-- (tests/lua/mpi_pour.sh): `save FILE` pours, saves at step 1500 and runs
-- on to step 3000; `load FILE` loads the file and runs on to step 3000. Each
-- prints the final state hash: a file saved with N ranks, loaded with M ranks
-- (or serially), continues bit-for-bit.
local mode, file = arg[1], arg[2]
assert(mode == "save" or mode == "load", "usage: mpi_restart.lua save|load FILE")
local m
if mode == "save" then
  m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3})
  m:wall{kind = "box", min = {0, 0}, max = {0.5, 0.4}}
  m:generate{count = 600, radius = {3e-3, 5e-3}, region = {box = {{0, 0}, {0.5, 0.2}}}, seed = 7}
  m:cycle(1500)
  m:save(file)
else
  m = seixo.load(file)
  assert(m:step() == 1500, "the file holds step 1500")
end
m:cycle(3000 - m:step())
print(string.format("step %d contacts %d hash %s", m:step(), m:contact_count(), m:hash()))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
