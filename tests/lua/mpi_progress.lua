-- Issue 16: the progress line of a cycle decomposed over MPI ranks, for
-- mpi_pour.sh: a 2D pour of 600 disks cycled in one call with log lines
-- every 0.2 s. Every rank must cut the call into the same chunks (rank 0's,
-- of at least a second each) and only rank 0 print; the bits must not
-- change (the hash is the serial run's). The call must outlast two chunks
-- on any machine: 30,000 steps take some 5 s with 3 ranks on a 2-core
-- host. (With 15,000, some 2.5 s, an idle host printed one line: the rate
-- measured over the first 16 steps was several times the run's, and the
-- second chunk took the rest; a chunk now grows at most eightfold.)
-- Prints the hash; the rank count on stderr.
seixo.progress("log", 0.2)
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
for i = 0, 29 do
  for j = 0, 19 do m:ball{pos = {0.0012 + i * 0.0021, j * 0.0021 + 0.001}, radius = 0.001, material = "g"} end
end
m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
m:wall{kind = "line", point = {0, 0}, normal = {1, 0}}
m:wall{kind = "line", point = {0.0645, 0}, normal = {-1, 0}}
m:cycle(30000)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print(m:hash())
