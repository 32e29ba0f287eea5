-- Periodic space under the MPI decomposition (issue 16; test lua_mpi_periodic
-- through mpi_same.sh): run serially and under mpirun -np 1 ... 4, each
-- scene prints the same hashes, cell and crack log, to the bit. The slabs
-- are cut across the last axis (z in 3D, y in 2D), the cell is periodic
-- along it too: the first and the last rank meet through the boundary,
-- where a ghost's force is folded onto its owner on another rank.
--   cell D    a granular gas in a cell periodic on every axis, compressed
--             by the cell's servo (the stress summed over the ranks in
--             pair order) with the automatic timestep, then bonded (bonds
--             through the boundary included) and sheared at a rate with
--             the lateral stress held by the servo until bonds break
--   drift D   a bonded triplet thrown along the last axis beside a column
--             of fixed balls, in a cell periodic along that axis only: it
--             goes round the cell (through every rank's slab and the
--             boundary) keeping its bonds and contacts
--   flat D    a flat bed, long along x and periodic along x (and y), its
--             cells ordered with x the slowest (the grid's longest axis),
--             so the slabs cut it across x and the first and last rank meet
--             through that boundary; balls thrown along x over a rough
--             floor of fixed balls (a dashpot between a free and a fixed
--             ball: infinite mass), dashpots, energy tracking (every term)
-- Arguments: scene (cell), dim (3).
local scene = arg and arg[1] or "cell"
local dim = tonumber(arg and arg[2]) or 3

local function report(m, tag)
  local c = m:periodic()
  print(string.format("%s step %d balls %d bonds %d cracks %d contacts %d dt %.17g tilt %.17g size %.17g %.17g hash %s",
                      tag, m:step(), m:ball_count(), m:bond_count(), m:crack_count(), m:contact_count(), m:timestep(),
                      c.tilt.xy, c.size[1], c.size[dim], m:hash()))
end

if scene == "cell" then
  local m = seixo.model{dim = dim}
  m:material("rock", {density = 2000, kn = 1e7, ks = 5e6, friction = 0.5, damping = 0.7,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2, tensile_strength = 3e5,
                              tensile_strength_sd = 5e4, cohesion = 6e5, cohesion_sd = 1e5}})
  local L = dim == 3 and 0.06 or 0.2
  local zero = dim == 3 and {0, 0, 0} or {0, 0}
  local size = dim == 3 and {L, L, L} or {L, L}
  m:periodic{min = zero, max = size}
  m:generate{count = dim == 3 and 700 or 900, radius = {2.2e-3, 3.3e-3}, region = {box = {zero, size}}, seed = 7}
  local target = dim == 3 and 2e5 or 4e3
  local servo = {xx = {stress = target}, yy = {stress = target}, max_rate = dim == 3 and 80 or 30}
  if dim == 3 then servo.zz = {stress = target} end
  m:cell_control(servo)
  m:cycle(2000)
  report(m, "compressed")
  m:bond{gap = 1e-4}
  -- simple shear at a rate, the normal stresses held by the servo
  servo.xy = {rate = 4}
  m:cell_control(servo)
  m:profile{print = false, reset = true}
  m:cycle(dim == 3 and 1000 or 1500)
  -- decomposed, a build takes the positions and moves what changes rank:
  -- no gather of the whole state (the cycle's end leaves it scattered)
  local p = m:profile{print = false}
  if m:ranks() > 1 and (p.broad_phase.calls < 2 or p.gathers > 0) then
    error(string.format("mpi_periodic.lua cell: %d builds made %d gathers", p.broad_phase.calls, p.gathers))
  end
  -- the cell and its stress (the ranks' own pairs' terms chained) without a gather
  local c, s = m:periodic(), m:cell_stress()
  if m:ranks() > 1 and m:profile{print = false}.gathers ~= p.gathers then
    error("mpi_periodic.lua cell: m:periodic() or m:cell_stress() gathered")
  end
  print(string.format("stress xx %.17g yy %.17g xy %.17g size %.17g", s[1][1], s[2][2], s[1][2], c.size[1]))
  report(m, "sheared")
  for i, c in ipairs(m:cracks()) do
    print(string.format("crack %d step %d %s balls %d %d", i, c.step, c.kind, c.a, c.b))
  end
  if m:crack_count() == 0 or m:bond_count() == 0 then error("mpi_periodic.lua cell: no crack or no bond left") end
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "drift" then
  local m = seixo.model{dim = dim, timestep = 2e-5, skin = 4e-3}
  m:material("soft", {density = 2000, kn = 1e6, ks = 1e6, friction = 0.3,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2, tensile_strength = 1e12,
                              cohesion = 1e12}})
  m:material("column", {density = 2000, kn = 1e6, ks = 1e6, friction = 0.3})
  local r, H = 0.01, 0.8
  local function at(x, y, z) return dim == 3 and {x, y, z} or {x, z} end
  m:periodic{min = at(-0.1, -0.1, 0), max = at(0.1, 0.1, H), axes = dim == 3 and "z" or "y"}
  -- the column: fixed balls along the last axis, so that every rank has balls
  for k = 0, 38 do m:ball{pos = at(0, 0, (k + 0.5) * H / 39), radius = r, material = "column"}.fix = "all" end
  -- the triplet (sides s) straddles the boundary, grazing the column
  local s, x0, v = 1.99 * r, 1.99 * r, at(0.1, 0, 30)
  local tri = {}
  for k, p in ipairs{at(x0, 0, H - 0.25 * s), at(x0, 0, 0.75 * s), at(x0 + math.sqrt(3) / 2 * s, 0, 0.25 * s)} do
    tri[k] = m:ball{pos = p, radius = r, material = "soft", vel = v}
  end
  print(string.format("triplet: %d bonds", m:bond{gap = 1e-4, materials = "soft"}))
  local mine = {[tri[1].id] = true, [tri[2].id] = true, [tri[3].id] = true}
  for step = 1, 4 do
    m:cycle(400)
    local own = 0
    for c in m:contacts{kind = "ball-ball"} do
      if mine[c.a.id] and mine[c.b.id] then own = own + 1 end
    end
    report(m, "drift " .. step)
    print(string.format("triplet contacts %d at %.17g %.17g %.17g", own, tri[1].pos[dim], tri[2].pos[dim],
                        tri[3].pos[dim]))
    if m:bond_count() ~= 3 or own ~= 3 then error("mpi_periodic.lua drift: the triplet lost a bond or a contact") end
  end
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "flat" then
  local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}}
  m:material("g", {density = 2500, kn = 1e5, ks = 1e5, friction = 0.5, viscous_normal = 0.3, viscous_shear = 0.1})
  local L, W = 0.4, 0.06
  local function at(x, y, z) return dim == 3 and {x, y, z} or {x, z} end
  m:periodic{min = at(0, 0, -0.5), max = at(L, W, 0.5), axes = dim == 3 and "xy" or "x"}
  m:wall{kind = dim == 3 and "plane" or "line", point = at(0, 0, 0), normal = at(0, 0, 1)}
  -- the rough floor: fixed balls in a row along x
  local floor = {}
  for k = 0, 79 do
    local f = m:ball{pos = at((k + 0.5) * L / 80, W / 2, 0.002), radius = 0.002}
    f.fix = "all"
    floor[f.id] = true
  end
  m:generate{count = dim == 3 and 1500 or 150, radius = {0.002, 0.003},
             region = {box = {at(0, 0, 0.006), at(L, W, 0.03)}}, seed = 3}
  for b in m:balls() do
    if not floor[b.id] then b.vel = at(1 + 0.5 * math.sin(b.id), 0.2, 0) end
  end
  m:track_energy(true)
  for step = 1, 3 do
    m:cycle(dim == 3 and 2500 or 3000)
    report(m, "flat " .. step)
    local e = m:energy()
    print(string.format("energy kinetic %a strain %a slip %a viscous %a damping %a boundary %a", e.kinetic, e.strain,
                        e.slip, e.viscous, e.local_damping, e.boundary_work))
  end
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
else
  error("mpi_periodic.lua: scene cell, drift or flat expected")
end
