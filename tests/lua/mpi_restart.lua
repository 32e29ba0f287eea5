-- A 2D pour saved halfway and continued, for the MPI decomposition test
-- (tests/lua/mpi_pour.sh): `save FILE` pours, saves at step 1500 and runs
-- on to step 3000; `load FILE` loads the file and runs on to step 3000. Each
-- prints the final state hash: a file saved with N ranks, loaded with M ranks
-- (or serially), continues bit-for-bit. `save FILE bonded`: a bonded 2D
-- specimen crushed by a platen instead, breaking bonds before and after the
-- save (the hash covers the bonds and the crack log). `save FILE periodic`:
-- a 2D cell periodic on both axes, compressed by its servo, bonded and
-- sheared at a rate, breaking bonds before and after the save.
local mode, file, kind = arg[1], arg[2], arg[3]
assert(mode == "save" or mode == "load", "usage: mpi_restart.lua save|load FILE [bonded|periodic]")
local m
if mode == "save" and kind == "bonded" then
  m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5,
                      bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 2e5,
                              tensile_strength_sd = 4e4, cohesion = 4e5, cohesion_sd = 8e4, normal_strength = 1000,
                              normal_strength_sd = 200, shear_strength = 1000, shear_strength_sd = 200}})
  local r = 1e-3
  for j = 0, 15 do
    for i = 0, 19 do m:ball{pos = {(2 * i + (j % 2) + 1) * r, (1 + j * math.sqrt(3)) * r}, radius = r} end
  end
  m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = 2e9, ks = 2e9}
  m:wall{kind = "line", point = {0, (2 + 15 * math.sqrt(3)) * r}, normal = {0, -1}, kn = 2e9, ks = 2e9, vel = {0, -0.06}}
  m:bond{kind = "parallel", gap = 1e-6, seed = 42}
  m:bond{kind = "contact", gap = 1e-6, seed = 43}
  m:cycle(1500)
  m:save(file)
elseif mode == "save" and kind == "periodic" then
  m = seixo.model{dim = 2}
  m:material("rock", {density = 2000, kn = 1e7, ks = 5e6, friction = 0.5, damping = 0.7,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2, tensile_strength = 3e5,
                              tensile_strength_sd = 5e4, cohesion = 6e5, cohesion_sd = 1e5}})
  m:periodic{min = {0, 0}, max = {0.2, 0.2}}
  m:generate{count = 900, radius = {2.2e-3, 3.3e-3}, region = {box = {{0, 0}, {0.2, 0.2}}}, seed = 7}
  local servo = {xx = {stress = 4e3}, yy = {stress = 4e3}, max_rate = 30}
  m:cell_control(servo)
  m:cycle(1100)
  m:bond{gap = 1e-4}
  servo.xy = {rate = 4}
  m:cell_control(servo)
  m:cycle(400)
  m:save(file)
elseif mode == "save" then
  m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3})
  m:wall{kind = "box", min = {0, 0}, max = {0.5, 0.4}}
  m:generate{count = 600, radius = {3e-3, 5e-3}, region = {box = {{0, 0}, {0.5, 0.2}}}, seed = 7}
  m:cycle(1500)
  m:save(file)
else
  m = seixo.load(file)
  assert(m:step() == 1500, "the file holds step 1500")
end
m:cycle(3000 - m:step())
print(string.format("step %d contacts %d bonds %d cracks %d hash %s", m:step(), m:contact_count(), m:bond_count(),
                    m:crack_count(), m:hash()))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
