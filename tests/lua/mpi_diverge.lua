-- Issue 16: ranks whose scripts did not make the same calls, for
-- mpi_pour.sh. The model is the same on every rank but for one ball's
-- velocity on the ranks above 0, by one unit in the last place (a branch
-- on seixo.rank(): what a script must not do); with the argument "wall",
-- but for the floor's place (a wall, which every rank holds whole after a
-- cycle, changed without a gather: the ranks above 0 would build, rank 0
-- not). The next cycle must stop every rank with the message that names
-- the cause, not run apart or wait for ever.
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
for i = 0, 19 do
  for j = 0, 9 do m:ball{pos = {0.0012 + i * 0.0021, j * 0.0021 + 0.001}, radius = 0.001, material = "g"} end
end
local floor = m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
m:cycle(100)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
if arg and arg[1] == "wall" then
  if seixo.rank() > 0 then floor.point = {0, -1e-6} end
  m:cycle(100)
  print("not stopped")
  return
end
local _ = m:contacts() -- every rank: a query of every contact gathers the state the cycle left on each
local b = m:ball(57)
local v = b.vel:copy()
if seixo.rank() > 0 then
  v[1] = v[1] ~= 0 and v[1] * (1 + 2 ^ -52) or 2 ^ -1074
  b.vel = v
end
m:cycle(100)
print("not stopped")
