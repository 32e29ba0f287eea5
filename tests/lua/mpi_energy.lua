-- Energies under the MPI decomposition (issue 16; test lua_mpi_energy
-- through mpi_same.sh, and mpi_stops.sh): serially and under mpirun -np
-- 1 ... 4 each scene prints the same lines, to the bit.
--   track D   energy tracking on a bonded specimen (D = 2: 480 disks, one
--             chunk of pairs over every rank; 3: 576 spheres, two chunks)
--             with local damping, contact dashpots and friction, crushed
--             (3D: sheared) by a moving platen until bonds break, balls
--             pushed by applied forces and moments, a loose stack of grains
--             collapsing beside it (friction: slip in every rank's slab),
--             and clumps falling: every energy term in hexadecimal (%a)
--             every 400 steps, and the state hash.
--   guard D   an unforced bed (balls settled in a fixed box, no load) given
--             a timestep far above the critical one: the energy guard stops
--             the cycle; its message (mpi_stops.sh compares it) must name
--             the same gain, scale, fastest ball and critical estimate
--             under every rank count. Before it trips, the guard's checks
--             every 64 steps must pass alike (a bed settling with a stable
--             timestep first).
local scene = arg and arg[1] or "track"
local dim = tonumber(arg and arg[2]) or 2
local terms = {"kinetic", "gravitational", "strain", "bond_strain", "slip", "local_damping", "viscous", "boundary_work",
               "bond_released"}

local function report(m, tag)
  local e, out = m:energy(), {}
  for _, k in ipairs(terms) do out[#out + 1] = k .. " " .. string.format("%a", e[k]) end
  print(string.format("%s step %d bonds %d cracks %d hash %s", tag, m:step(), m:bond_count(), m:crack_count(),
                      m:hash()))
  print("  " .. table.concat(out, " "))
end

local function along(v) -- a vector along the last axis
  return dim == 3 and {0, 0, v} or {0, v}
end

if scene == "track" then
  local m = seixo.model{dim = dim, gravity = along(-9.81)}
  m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5,
                      viscous_normal = 0.1, viscous_shear = 0.05,
                      bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                              tensile_strength = 2e5, tensile_strength_sd = 4e4, cohesion = 4e5, cohesion_sd = 8e4,
                              normal_strength = 1000, normal_strength_sd = 200, shear_strength = 1000,
                              shear_strength_sd = 200}})
  m:material("grain", {density = 2500, friction = 0.4, damping = 0.2, modulus = 1e8, stiffness_ratio = 2.5,
                       viscous_normal = 0.2})
  local r = 1e-3
  local height, balls = 0, {}
  if dim == 2 then -- a hexagonal packing, 20 x 24
    for j = 0, 23 do
      for i = 0, 19 do
        balls[#balls + 1] = m:ball{pos = {(2 * i + (j % 2) + 1) * r, (1 + j * math.sqrt(3)) * r}, radius = r,
                                   material = "rock"}
      end
    end
    height = (2 + 23 * math.sqrt(3)) * r
    m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = 2e9, ks = 2e9, friction = 0.3}
    m:clump_template("pair", {{-0.8 * r, 0, r}, {0.8 * r, 0, 0.8 * r}})
  else -- a simple cubic block, 6 x 6 x 16
    for k = 0, 15 do
      for j = 0, 5 do
        for i = 0, 5 do
          balls[#balls + 1] = m:ball{pos = {(2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r}, radius = r,
                                     material = "rock"}
        end
      end
    end
    height = 32 * r
    m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 2e9, ks = 2e9, friction = 0.3}
    m:clump_template("pair", {{-0.8 * r, 0, 0, r}, {0.8 * r, 0, 0, 0.8 * r}})
  end
  local n = m:bond{kind = "parallel", gap = 1e-6, seed = 42, materials = "rock"}
  local nc = m:bond{kind = "contact", gap = 1e-6, seed = 43, materials = "rock"}
  print(string.format("%d balls, %d parallel bonds, %d contact bonds", m:ball_count(), n, nc))
  -- a square stack of grains beside it, as tall as the specimen, pressed
  -- a little together, its layers thrown sideways in turn: they slide on
  -- each other (friction) in every rank's slab
  local layers = dim == 3 and 14 or 19 -- below the platen
  for j = 0, layers - 1 do
    for i = 0, 2 do
      local x, y, u = (44 + 1.99 * i) * r, (1 + 1.99 * j) * r, j % 2 == 0 and 0.3 or -0.3
      m:ball{pos = dim == 3 and {x, 6 * r, y} or {x, y}, radius = r, material = "grain",
             vel = dim == 3 and {u, 0.1 * u, 0} or {u, 0}}
    end
  end
  -- clumps falling on the floor beside them (its pebbles on the ranks of the low slabs)
  for k = 0, 5 do
    local x = (56 + 5 * k) * r
    m:clump{template = "pair", pos = dim == 3 and {x, 6 * r, 2 * r + k * r} or {x, 2 * r + k * r}, material = "grain",
            vel = along(-0.5)}
  end
  -- applied loads on a few balls: their work is boundary work
  for k = 1, #balls, 37 do
    balls[k].applied_force = dim == 3 and {0.02, -0.01, 0.03} or {0.02, -0.01}
    balls[k].applied_moment = dim == 3 and {1e-5, 0, -1e-5} or 1e-5
  end
  local down = dim == 3 and {0.1, 0, -0.1} or {0.01, -0.04}
  m:wall{kind = dim == 3 and "plane" or "line", point = along(height), normal = along(-1), kn = 2e9, ks = 2e9,
         friction = 0.3, vel = down}
  m:track_energy(true)
  for _ = 1, 6 do
    m:cycle(400)
    report(m, "at")
  end
  if m:crack_count() == 0 then error("no bond broke: the released energy is not exercised") end
  local e = m:energy()
  for _, k in ipairs{"slip", "local_damping", "viscous", "boundary_work", "bond_released"} do
    if e[k] == 0 then error("the " .. k .. " term is zero: not exercised") end
  end
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "guard" then
  local dir = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
  local m = dofile(dir .. "mpi_stack.lua")(dim, dim == 3 and 8 or 30, dim == 3 and 8 or 20, 10)
  m:cycle(640) -- settling with the automatic timestep: the guard checks and passes ten times
  report(m, "settled")
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  io.stderr:flush()
  m:set_timestep(tonumber(arg[3]) * m:timestep())
  m:cycle(6400) -- the guard stops it
  error("the guard did not trip")
else
  error("mpi_energy.lua: scene track or guard expected, got " .. tostring(scene))
end
