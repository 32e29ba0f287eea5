-- Writes the series tests/io/render.sh renders: two bonded rows of balls
-- pulled apart, so that every bond between the rows breaks in tension and
-- the series carries a crack map; prints "snapshots balls cracks".
--   seixo render_series.lua OUT.h5
local out = assert(arg[1], "usage: seixo render_series.lua OUT.h5")
local m = seixo.model{dim = 3}
m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, density = 2600})
for i = 0, 9 do
  for j = 0, 1 do m:ball{pos = {0.002 * i, 0.002 * j, 0}, radius = 0.001} end
end
m:bond{kind = "parallel", gap = 1e-4, radius_multiplier = 0.5, modulus = 1e7, stiffness_ratio = 2,
       tensile_strength = 1e4, cohesion = 1e4}
for b in m:balls() do b.vel = {0, b.pos[2] > 0.001 and 0.5 or -0.5, 0} end
local o = m:output{path = out, every = 100, fields = {"all"}}
m:cycle(1000)
print(o:count(), m:ball_count(), m:crack_count())
o:close()
