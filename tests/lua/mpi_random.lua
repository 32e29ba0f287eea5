-- A script using math.random without a seed of its own, under mpirun
-- (issue 16; test lua_mpi_random through mpi_same.sh): Lua seeds it at
-- random in each process, and every rank must build the same model, so the
-- ranks share rank 0's seed. Balls placed at random positions, cycled
-- (each decomposed cycle checks that the ranks' models agree), and a CSV
-- written through seixo.lab many times over (by rank 0; the other ranks
-- write their shadows, src/lua/rank_files.c). Prints what does
-- not depend on the draw: the same lines serially and on every rank count.
local lab = require "seixo.lab"
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
m:wall{kind = "box", min = {0, 0}, max = {0.1, 0.1}}
-- a lattice of cells, each ball placed at random inside its own cell: no overlap
for i = 0, 19 do
  for j = 0, 9 do
    m:ball{pos = {0.0025 + 0.005 * i + 0.001 * (math.random() - 0.5), 0.0025 + 0.005 * j + 0.001 * (math.random() - 0.5)},
           radius = 0.0015, material = "g"}
  end
end
m:cycle(200)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print("balls", m:ball_count(), "step", m:step())
local path = os.tmpname() -- one file for all the ranks: rank 0's name (mpi_tmpname.lua)
for k = 1, 200 do lab.write_csv(path, {"k", "x"}, {{k, m:ball(1).pos[1]}}) end
m:cycle(1) -- every rank has written its last
local rows = require("seixo.util").read_csv(path)
print("csv rows", rows.rows, "last k", rows.columns.k[1])
m:cycle(1) -- every rank has read it
if seixo.rank() == 0 then os.remove(path) end
