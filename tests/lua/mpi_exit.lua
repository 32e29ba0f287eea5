-- os.exit under mpirun (issue 16; test lua_mpi_exit through mpi_same.sh):
-- a script ending with os.exit(0) (or os.exit(true), closing the state or
-- not) succeeds serially, and so must the job under mpirun: every rank
-- ends through os.exit alike, and none may leave without finalizing MPI.
--   mpi_exit.lua CODE [close]     CODE: 0 or true
local code = arg[1] == "true" or tonumber(arg[1])
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
m:generate{count = 100, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.03}}}, seed = 2}
m:wall{kind = "box", min = {0, 0}, max = {0.04, 0.05}}
m:cycle(100)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print("exiting", tostring(code), m:hash())
os.exit(code, arg[2] == "close")
