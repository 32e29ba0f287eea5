-- A live plot under mpirun (issue 16; tests/lua/mpi_pour.sh): every rank
-- runs the script, and rank 0 alone draws. On gnuplot's dumb terminal the
-- plot goes to standard output, where a plot drawn by every rank would
-- come once per rank; mpi_pour.sh compares the output with the serial
-- run's. The plot's callback cuts every rank's cycles at its steps alike.
local plot = require "seixo.plot"
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
m:generate{count = 100, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.03}}}, seed = 2}
m:wall{kind = "box", min = {0, 0}, max = {0.04, 0.05}}
m:history("ke", "kinetic", {every = 10})
local p = plot.live(m, {"ke"}, {every = 500, terminal = "dumb 60,12"})
m:cycle(1000)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
p:close()
print(tostring(p), m:hash())
