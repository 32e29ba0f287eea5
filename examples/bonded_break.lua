-- A bonded specimen (rock as bonded particles) crushed between two walls (2D).
--   scripts/run examples/bonded_break.lua
-- A hexagonal packing of disks with parallel bonds (Potyondy & Cundall's
-- bonded-particle model, seed 4.4) is loaded by a platen moving down until
-- bonds break; the crack log and the energy balance are printed.
local m = seixo.model{dim = 2}
m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5,
                    bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                            tensile_strength = 2e5, tensile_strength_sd = 4e4,
                            cohesion = 4e5, cohesion_sd = 8e4}})
local r, cols, rows = 1e-3, 20, 24
for j = 0, rows - 1 do
  for i = 0, cols - 1 do
    m:ball{pos = {(2 * i + (j % 2) + 1) * r, (1 + j * math.sqrt(3)) * r}, radius = r}
  end
end
local height = (2 + (rows - 1) * math.sqrt(3)) * r
print(string.format("bonded_break: %d disks, %d parallel bonds", m:ball_count(), m:bond{gap = 1e-6, seed = 42}))

m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = 2e9, ks = 2e9}
local platen = m:wall{kind = "line", point = {0, height}, normal = {0, -1}, kn = 2e9, ks = 2e9, vel = {0, -0.02}}
m:track_energy(true)

local width = 2 * cols * r
local peak = 0
for k = 1, 40 do
  m:cycle(1000)
  local stress = platen.force[2] / width     -- N per m of thickness over m: Pa
  peak = math.max(peak, stress)
  print(string.format("strain %.4f  stress %8.3f MPa  cracks %4d (tension %d, shear %d)",
                      (height - platen.point[2]) / height, stress / 1e6, m:crack_count(),
                      m:crack_count("tension"), m:crack_count("shear")))
end
local e = m:energy()
local stored = e.kinetic + e.strain + e.bond_strain
local dissipated = e.slip + e.local_damping + e.viscous + e.bond_released
print(string.format("peak stress %.3f MPa, %d intact bonds, %d cracks", peak / 1e6, m:bond_count(), m:crack_count()))
print(string.format("energy: boundary work %.4g J = stored %.4g J + dissipated %.4g J (residual %.2g %%)",
                    e.boundary_work, stored, dissipated, 100 * (e.boundary_work - stored - dissipated) / e.boundary_work))
