-- Writes the series that tests/io/paraview_check.py reads with ParaView:
-- a bonded block of balls of three radii falling onto a plane, a tilted
-- rectangle beside it, a tetrahedron of four triangles (a mesh wall) away
-- from them, turning; prints "snapshots balls rmin rmax".
--   seixo paraview_series.lua OUT.h5
local out = assert(arg[1], "usage: seixo paraview_series.lua OUT.h5")
local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, density = 2600, damping = 0.1})
m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
m:wall{kind = "rect", point = {-0.03, -0.03, 0.02}, edge1 = {0, 0.15, 0}, edge2 = {-0.01, 0, 0.05}}
m:wall{kind = "mesh", vertices = {{0.2, 0, 0.01}, {0.25, 0, 0.01}, {0.2, 0.05, 0.01}, {0.2, 0, 0.06}},
       triangles = {{1, 3, 2}, {1, 2, 4}, {2, 3, 4}, {3, 1, 4}}, point = {0.21, 0.01, 0.02}, spin = {0, 0, 3}}
local n, rmin, rmax = 0, math.huge, 0
for i = 0, 9 do
  for j = 0, 9 do
    for k = 0, 4 do
      local r = 0.0036 + 0.0002 * ((i + j + k) % 3)
      m:ball{pos = {0.009 * i, 0.009 * j, 0.0045 + 0.009 * k}, radius = r}
      n, rmin, rmax = n + 1, math.min(rmin, r), math.max(rmax, r)
    end
  end
end
m:bond{kind = "parallel", gap = 0.002, radius_multiplier = 0.5, modulus = 1e7, stiffness_ratio = 2,
       tensile_strength = 1e4, cohesion = 1e4}
local o = m:output{path = out, every = 50, fields = {"all"}}
m:cycle(200)
local count = o:count()
o:close()
print(count, n, string.format("%.17g", rmin), string.format("%.17g", rmax))
