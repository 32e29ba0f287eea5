-- os.exit under mpirun (issue 16; test lua_mpi_exit through mpi_same.sh):
-- a script ending with os.exit(0) (or os.exit(true), closing the state or
-- not) succeeds serially, and so must the job under mpirun: every rank
-- ends through os.exit alike, and none may leave without finalizing MPI.
--   mpi_exit.lua CODE [close]     CODE: 0 or true
local code = arg[1] == "true" or tonumber(arg[1])
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
print("exiting", tostring(code), m:hash())
os.exit(code, arg[2] == "close")
