-- MPI and threads together (issue 16; test lua_mpi_threads through
-- mpi_same.sh): every rank steps its slab on 2 threads (seixo.threads, as
-- `seixo --threads 2` sets it), the way a cluster runs one rank per node or
-- socket and a thread per core. Another test scene (mpi_bonds.lua crush 3,
-- ...) run so must print what the serial run prints, to the bit.
--   mpi_threads.lua SCRIPT ARGS...
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
seixo.threads = 2
-- every model the scene makes or loads runs on them
for _, make in ipairs{"model", "load"} do
  local made = seixo[make]
  seixo[make] = function(...)
    local m = made(...)
    local t = m:profile{print = false}.threads
    if t ~= 2 then error(string.format("seixo.%s made a model of %d threads, not 2", make, t)) end
    return m
  end
end
arg = {[0] = here .. arg[1], table.unpack(arg, 2)}
dofile(arg[0])
