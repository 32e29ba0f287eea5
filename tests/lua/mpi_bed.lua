-- A small 2D bed of 100 balls in a box, cycled `steps` steps (the model
-- returned), for the MPI tests of the Lua layer (mpi_exit, mpi_fail,
-- mpi_stdout, mpi_tmpname): it says on stderr over how many ranks its
-- model ran ("ranks N", what mpi_same.sh and mpi_stops.sh look for).
--   local m = dofile(dir .. "mpi_bed.lua")(steps)
return function(steps)
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
  m:generate{count = 100, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.03}}}, seed = 2}
  m:wall{kind = "box", min = {0, 0}, max = {0.04, 0.05}}
  m:cycle(steps)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  return m
end
