-- Bonds under the MPI decomposition (issue 16; test lua_mpi_bonds through
-- mpi_same.sh): serially and under mpirun -np 1 ... 4 each scene prints
-- the same lines, to the bit.
--   crush D   a bonded specimen (D = 2: 480 disks; 3: 576 spheres), every
--             touching pair with a parallel and a contact bond, crushed by
--             a platen (3D: sheared too) until bonds break: the state hash
--             at mid-run and at the end, the bond and crack counts and the
--             whole crack log, entry by entry, in its order.
--   cross     a bonded triplet of disks (three parallel bonds, three contact
--             bonds) dropped down a channel beside a column of 600 fixed
--             disks, so that its balls pass through the slab of every rank
--             (the ranks cut the balls by count along y): its bonds and
--             contacts must survive the migrations, and the state is the
--             serial one.
--   flat D    a flat-jointed specimen (D = 2 or 3), a fifth of its
--             elements unbonded, crushed (3D: sheared) until elements and
--             whole joints break: the state hash (which covers every
--             element's state and forces), the platen's force, the elements
--             by state and the crack log at several points.
--   smooth D  a bonded column (D = 2 or 3) cut by a bonded smooth joint at
--             60 degrees through every rank's slab, its upper part pushed down the
--             joint: the joint's bonds break, the part slides by more than
--             a ball, making new contacts across the joint; the hash, the
--             joint contacts and the crack log.
--   flat D energy, smooth D energy: the same with energy tracking on, every
--             energy term printed (%a) with each report.
local scene = arg and arg[1] or "crush"
local dim = tonumber(arg and arg[2]) or 2
local energy = arg and arg[3] == "energy"

local function log_cracks(m)
  for i, c in ipairs(m:cracks()) do
    print(string.format("crack %d step %d %s %s balls %d %d fn %.17g fs %.17g mn %.17g ms %.17g at %.17g %.17g", i,
                        c.step, c.kind, c.mode, c.a, c.b, c.fn, c.fs, c.mn, c.ms, c.pos[1], c.pos[2]))
  end
end

local function report(m, tag)
  print(string.format("%s step %d bonds %d cracks %d (tension %d) contacts %d hash %s", tag, m:step(), m:bond_count(),
                      m:crack_count(), m:crack_count("tension"), m:contact_count(), m:hash()))
  if not energy then return end
  local e, terms = m:energy(), {}
  for k in pairs(e) do terms[#terms + 1] = k end
  table.sort(terms)
  for i, k in ipairs(terms) do terms[i] = k .. " " .. string.format("%a", e[k]) end
  print("  energy " .. table.concat(terms, " "))
end

-- The ball-ball contacts keep(c) holds in each quarter of the balls by
-- height (the ranks' slabs cut the balls by count along the last axis:
-- with 4 ranks, about these quarters), as "a b c d"; an error unless each
-- has some, so that they meet the slab of every rank.
local function quarters(m, keep)
  local z = {}
  for b in m:balls() do z[#z + 1] = b.pos[dim] end
  table.sort(z)
  local cut = {z[#z // 4], z[#z // 2], z[3 * #z // 4]}
  local count = {0, 0, 0, 0}
  for c in m:contacts{kind = "ball-ball"} do
    if keep(c) then
      local q = 1
      while q <= 3 and c.a.pos[dim] > cut[q] do q = q + 1 end
      count[q] = count[q] + 1
    end
  end
  for q = 1, 4 do
    if count[q] == 0 then error(string.format("no contact in quarter %d of the balls", q)) end
  end
  return table.concat(count, " ")
end

local function material(m)
  m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5,
                      bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                              tensile_strength = 2e5, tensile_strength_sd = 4e4, cohesion = 4e5, cohesion_sd = 8e4,
                              normal_strength = 1000, normal_strength_sd = 200, shear_strength = 1000,
                              shear_strength_sd = 200}})
end

if scene == "crush" then
  local g = dim == 3 and {0, 0, -9.81} or {0, -9.81}
  local m = seixo.model{dim = dim, gravity = g}
  material(m)
  local r = 1e-3
  local height
  if dim == 2 then -- a hexagonal packing, 20 x 24
    for j = 0, 23 do
      for i = 0, 19 do m:ball{pos = {(2 * i + (j % 2) + 1) * r, (1 + j * math.sqrt(3)) * r}, radius = r} end
    end
    height = (2 + 23 * math.sqrt(3)) * r
    m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = 2e9, ks = 2e9}
  else -- a simple cubic block, 6 x 6 x 16
    for k = 0, 15 do
      for j = 0, 5 do
        for i = 0, 5 do m:ball{pos = {(2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r}, radius = r} end
      end
    end
    height = 32 * r
    m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 2e9, ks = 2e9}
  end
  local n = m:bond{kind = "parallel", gap = 1e-6, seed = 42}
  local nc = m:bond{kind = "contact", gap = 1e-6, seed = 43}
  print(string.format("%d balls, %d parallel bonds, %d contact bonds", m:ball_count(), n, nc))
  local function along(v) -- a vector along the last axis
    return dim == 3 and {0, 0, v} or {0, v}
  end
  local down, up, top = along(-0.04), along(-1), along(height)
  if dim == 3 then down = {0.1, 0, -0.1} end -- (a simple cubic block is crushed without tension: shear it)
  m:wall{kind = dim == 3 and "plane" or "line", point = top, normal = up, kn = 2e9, ks = 2e9, vel = down}
  m:cycle(1500)
  report(m, "mid")
  m:cycle(1500)
  report(m, "end")
  log_cracks(m)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "cross" then
  -- soft disks and a fixed timestep, so that the fall takes few steps
  local m = seixo.model{dim = 2, gravity = {0, -9.81}, timestep = 4e-6}
  m:material("soft", {density = 2650, friction = 0.5, modulus = 1e7, stiffness_ratio = 2.5,
                      bond = {radius_multiplier = 1, modulus = 1e7, stiffness_ratio = 2.5, tensile_strength = 1e12,
                              cohesion = 1e12, normal_strength = 1e9, shear_strength = 1e9}})
  m:material("column", {density = 2650, modulus = 1e7})
  local r = 1e-3
  -- a column of fixed disks, 6 wide and 100 tall, on the right; the channel on the left
  for j = 0, 99 do
    for i = 0, 5 do
      m:ball{pos = {0.02 + (2 * i + 1) * r, (2 * j + 1) * r}, radius = r, material = "column"}.fix = "all"
    end
  end
  m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = 2e7, ks = 2e7}
  local x0, y0 = 0.008, 0.19
  local tri = {}
  for k, p in ipairs{{x0, y0}, {x0 + 2 * r, y0}, {x0 + r, y0 + math.sqrt(3) * r}} do
    tri[k] = m:ball{pos = p, radius = r, material = "soft", vel = {0, -4}, spin = 30}
  end
  local n = m:bond{kind = "parallel", gap = 1e-6, seed = 42, materials = "soft"}
  local nc = m:bond{kind = "contact", gap = 1e-6, seed = 43, materials = "soft"}
  print(string.format("triplet: %d parallel and %d contact bonds", n, nc))
  for _ = 1, 10 do
    m:cycle(1200)
    -- the triplet's contacts among its balls, with their forces, and its bonds
    local own, fn, seen = 0, {}, {}
    local mine = {[tri[1].id] = true, [tri[2].id] = true, [tri[3].id] = true}
    for k = 1, 3 do
      for c in m:contacts{ball = tri[k], kind = "ball-ball"} do
        local key = math.min(c.a.id, c.b.id) .. "-" .. math.max(c.a.id, c.b.id)
        if mine[c.a.id] and mine[c.b.id] and not seen[key] then
          seen[key] = true
          own = own + 1
          fn[#fn + 1] = string.format("%.17g", c.fn)
        end
      end
    end
    print(string.format("step %d y %.17g %.17g %.17g bonds %d triplet contacts %d (fn %s) hash %s", m:step(),
                        tri[1].pos[2], tri[2].pos[2], tri[3].pos[2], m:bond_count(), own, table.concat(fn, " "),
                        m:hash()))
    if m:bond_count() ~= 3 or own ~= 3 then error("the triplet lost a bond or a contact") end
  end
  if tri[1].pos[2] > 0.02 then error("the triplet did not fall through the column") end
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "flat" then
  -- a flat-jointed specimen (D = 2: 16 x 20 disks, 4 elements a joint; 3:
  -- 4 x 4 x 12 spheres, 2 rings of 3 sectors), a fifth of the elements
  -- unbonded, crushed (3D: sheared) by a platen until elements break and
  -- whole joints go: the elements' state travels with the joints
  local g = dim == 3 and {0, 0, -9.81} or {0, -9.81}
  local m = seixo.model{dim = dim, gravity = g}
  m:track_energy(energy)
  m:material("rock", {density = 2650, friction = 0.5, damping = 0.7, modulus = 1e9, stiffness_ratio = 2.5,
                      bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 4e5,
                              tensile_strength_sd = 8e4, cohesion = 8e5, cohesion_sd = 1.6e5, friction_angle = 30,
                              friction = 0.6, elements = dim == 3 and 2 or 4, sectors = 3,
                              unbonded_fraction = 0.2, initial_gap = 1e-6}})
  local r = 1e-3
  local height
  if dim == 2 then -- a hexagonal packing, 16 x 20
    for j = 0, 19 do
      for i = 0, 15 do m:ball{pos = {(2 * i + (j % 2) + 1) * r, (1 + j * math.sqrt(3)) * r}, radius = r} end
    end
    height = (2 + 19 * math.sqrt(3)) * r
  else -- a simple cubic block, 4 x 4 x 12
    for k = 0, 11 do
      for j = 0, 3 do
        for i = 0, 3 do m:ball{pos = {(2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r}, radius = r} end
      end
    end
    height = 24 * r
  end
  local up = dim == 3 and {0, 0, 1} or {0, 1}
  m:wall{kind = dim == 3 and "plane" or "line", point = dim == 3 and {0, 0, 0} or {0, 0}, normal = up, kn = 2e9,
         ks = 2e9}
  local n = m:bond{kind = "flatjoint", gap = 1e-6, seed = 42}
  print(string.format("%d balls, %d flat joints", m:ball_count(), n))
  local down = dim == 3 and {0.1, 0, -0.1} or {0, -0.05}
  local platen = m:wall{kind = dim == 3 and "plane" or "line", point = dim == 3 and {0, 0, height} or {0, height},
                        normal = dim == 3 and {0, 0, -1} or {0, -1}, kn = 2e9, ks = 2e9, vel = down}
  -- the elements of every joint still listed, by state (m:flatjoint of each bonded pair)
  local function elements()
    local count = {}
    for c in m:contacts{kind = "ball-ball"} do
      for _, e in ipairs(m:flatjoint(c.a.id, c.b.id) or {}) do count[e.state] = (count[e.state] or 0) + 1 end
    end
    return string.format("bonded %d unbonded %d tension %d shear %d", count.bonded or 0, count.unbonded or 0,
                         count.tension or 0, count.shear or 0)
  end
  for k = 1, 4 do
    m:cycle(dim == 3 and 500 or 800)
    report(m, "at " .. k)
    print(string.format("  platen %.17g %.17g %s", platen.force[1], platen.force[dim], elements()))
  end
  if m:crack_count() == 0 or m:bond_count() == n then error("no element or joint broke") end
  log_cracks(m)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "smooth" then
  -- a bonded column of soft balls (D = 2: 12 x 30 disks; 3: 8 x 3 x 20
  -- spheres) cut by a bonded smooth joint at 60 degrees across the whole
  -- column (through every rank's slab), its upper part pressed onto the
  -- joint and pushed down it, the lower part fixed: the joint's bonds
  -- break and the part slides along the joint by more than a ball, its
  -- balls meeting new balls across it (contacts that take the joint's law
  -- as they form)
  local function v(x, z) -- x along the dip, z up (the slabs' axis)
    return dim == 3 and {x, 0, z} or {x, z}
  end
  local m = seixo.model{dim = dim, gravity = v(0, -9.81), timestep = 4e-6}
  m:track_energy(energy)
  m:material("soft", {density = 2650, friction = 0.5, modulus = 1e7, stiffness_ratio = 2.5,
                      bond = {radius_multiplier = 1, modulus = 1e7, stiffness_ratio = 2.5, tensile_strength = 1e12,
                              cohesion = 1e12}})
  local r = 1e-3
  local nx, ny, nz = 12, 1, 30
  if dim == 3 then nx, ny, nz = 8, 3, 20 end
  local dip = math.rad(60)
  local px, pz = nx * r, nz * r
  -- a ball's weight times 600 (2D: 5 N a disk of unit thickness): the load pressing the joint
  local P = 600 * 2650 * (dim == 3 and 4 / 3 * math.pi * r ^ 3 or math.pi * r ^ 2)
  local upper = {}
  for k = 0, nz - 1 do
    for j = 0, ny - 1 do
      for i = 0, nx - 1 do
        local x, z = (2 * i + 1) * r, (2 * k + 1) * r
        local pos = v(x, z)
        if dim == 3 then pos[2] = (2 * j + 1) * r end
        local b = m:ball{pos = pos, radius = r}
        -- above the joint (its normal (-sin, cos) in x, z): pressed onto it
        -- by P, and pushed down it by P / 2 (more than its friction)
        if -math.sin(dip) * (x - px) + math.cos(dip) * (z - pz) > 0 then
          b.applied_force = v(P * math.sin(dip) - P / 2 * math.cos(dip), -P * math.cos(dip) - P / 2 * math.sin(dip))
          upper[#upper + 1] = b
        else -- the lower part: a fixed base
          b.fix = "all"
        end
      end
    end
  end
  local n = m:bond{kind = "parallel", gap = 1e-6, seed = 42}
  local _, cut, took = m:joint{point = v(px, pz), normal = v(-math.sin(dip), math.cos(dip)), kn = 1e10, ks = 1e10,
                               friction = 0.3, dilation = 5, tension = 5e3, cohesion = 5e3, friction_angle = 20}
  print(string.format("%d balls (%d above the joint), %d parallel bonds, the joint took %d bonds and %d contacts",
                      m:ball_count(), #upper, n, cut, took))
  local x0 = upper[1].pos[1]
  for k = 1, 4 do
    m:cycle(800)
    local joint, broke = 0, 0
    for c in m:contacts{kind = "ball-ball"} do
      if c.joint then joint = joint + 1 end
    end
    for _, c in ipairs(m:cracks()) do
      if c.kind == "smoothjoint" then broke = broke + 1 end
    end
    report(m, "at " .. k)
    print(string.format("  joint contacts %d joint bonds broken %d slid %.17g", joint, broke, upper[1].pos[1] - x0))
    if k == 1 then print("  joint contacts by quarter of height " .. quarters(m, function(c) return c.joint end)) end
  end
  if upper[1].pos[1] - x0 > -2 * r then error("the upper part did not slide by a ball along the joint") end
  log_cracks(m)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
else
  error("mpi_bonds.lua: scene 'crush', 'cross', 'flat' or 'smooth' expected, got " .. tostring(scene))
end
