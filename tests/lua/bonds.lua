-- Lua-level checks of bonds, cracks and energies (m:bond, m:cracks, m:energy).
local passed, failed = 0, 0
local function check(name, ok, msg)
  if ok then passed = passed + 1 else failed = failed + 1; print("FAIL " .. name .. ": " .. tostring(msg)) end
end

-- two disks joined by a parallel bond, pulled apart by an applied force
local function pair(force)
  local m = seixo.model{dim = 2}
  m:material("r", {density = 1000, damping = 0.7, kn = 1e9, ks = 1e9,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                           tensile_strength = 1e7, cohesion = 1e7}})
  local a = m:ball{pos = {0, 0}, radius = 1}
  local b = m:ball{pos = {2, 0}, radius = 1}
  a.fix = "all"
  local n = m:bond{gap = 1e-6}
  b.applied_force = {force, 0}
  m:track_energy(true)
  m:cycle(20000)
  return m, b, n
end

do
  -- closed form: axial stiffness kn_bar * A = Ec/(RA+RB) * 2R_bar = 1e9/2 * 2 = 1e9 N/m
  local m, b, n = pair(1e5)
  check("one bond installed", n == 1 and m:bond_count() == 1, n)
  local disp = b.pos[1] - 2
  check("axial stiffness", math.abs(disp - 1e-4) < 1e-4 * 1e-6, disp)
  check("no crack below strength", m:crack_count() == 0, m:crack_count())
  local e = m:energy()
  local balance = e.boundary_work - (e.kinetic + e.strain + e.bond_strain + e.slip + e.local_damping + e.viscous + e.bond_released)
  check("energy closes", math.abs(balance) < 1e-3 * e.boundary_work, balance)
end

do
  -- break load: sigma_max = -Fn/A >= sigma_c, i.e. F >= 1e7 * 2 = 2e7 N
  local m = pair(2.02e7)
  check("bond breaks in tension", m:crack_count() == 1 and m:crack_count("tension") == 1 and m:bond_count() == 0,
        m:crack_count())
  local c = m:cracks()[1]
  -- the contact point is the middle of the opened gap; the bond failed at or past its strength sigma_c A
  check("crack record", c and c.mode == "tension" and c.kind == "parallel" and c.a == 1 and c.b == 2
        and c.pos[1] > 1 and c.pos[1] < 1.05 and c.fn <= -2e7 and c.step > 0, c and c.pos[1])
end

do
  local m = seixo.model{dim = 3}
  m:material("h", {model = "hertz", shear_modulus = 1e9, poisson = 0.2})
  m:ball{pos = {0, 0, 0}, radius = 1}
  m:ball{pos = {2, 0, 0}, radius = 1}
  local ok, err = pcall(m.bond, m, {kind = "contact", gap = 1e-6, normal_strength = 1, shear_strength = 1})
  check("hertz refuses bonds", not ok and tostring(err):find("Hertz"), err)
  ok, err = pcall(m.bond, m, {gapp = 1})
  check("unknown key named", not ok and tostring(err):find("gapp"), err)
  ok, err = pcall(m.material, m, "x", {model = "plastic"})
  check("unknown model named", not ok and tostring(err):find("plastic"), err)
end

print(string.format("%d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
