-- Writes the files tests/io/h5py_check.py reads with h5py alone: a snapshot
-- and a series of balls squeezed in a servo-controlled cylinder, with
-- histories and seeds.
--   seixo h5py_files.lua OUT_DIR
local out = assert(arg[1], "usage: seixo h5py_files.lua OUT_DIR")
local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("rock", {kn = 1e7, ks = 1e7, friction = 0.5, density = 2600, damping = 0.7})
local cyl = m:wall{kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}, radius = 0.02, height = 0.05}
m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
m:generate{count = 60, radius = {0.002, 0.003}, region = {cylinder = {p1 = {0, 0, 0}, p2 = {0, 0, 0.04}, radius = 0.02}},
           seed = 11}
cyl:servo{target = 1e3, area = 2 * math.pi * 0.02 * 0.04, max_speed = 0.05}
m:history("ke", "kinetic", {every = 10})
m:history("radius, of the cylinder", function() return (cyl:radius()) end, {every = 25})
m:history("fz", {wall = 2, field = "force", component = "z"}, {every = 10})
local o = m:output{path = out .. "/series.h5", every = 50}
m:cycle(300)
o:close()
m:save(out .. "/snapshot.h5")
