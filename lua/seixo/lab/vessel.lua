-- seixo.lab.vessel: the vessel of walls a specimen's genesis packs its
-- balls in (a box, or a cylinder closed by two planes), servo-controlled
-- to a stress, and the compaction of clumps by shrinking it (genesis.lua's
-- vessel interface: v.stress, v.volume, v.gaps, v.place).

local pi = math.pi

-- The point p moved towards c to f times its distance (an affine scaling about c).
local function scaled(p, f, c)
  local q = {}
  for k = 1, #c do q[k] = c[k] + f * (p[k] - c[k]) end
  return q
end

-- A vessel of walls around the box [lo, hi]: six planes (four lines), or
-- for a cylinder along axis `ax` a cylindrical wall closed by two planes.
-- vessel.areas() gives the current area (2D: length) each wall loads,
-- vessel.volume() the space it encloses, and vessel.scale(f, c) shrinks it
-- by the factor f about the point c.
local function make_vessel(m, lo, hi, kn, cyl_axis)
  local dim = m:dim()
  local v = {place = function(x) return x end} -- (a periodic cell's vessel wraps x: cell_vessel)
  function v.scale(f, c)
    for _, w in ipairs(v.walls) do
      w.point = scaled(w.point, f, c)
      if w.kind == "cylinder" then w:set_radius(f * w:radius()) end
    end
  end
  -- the distances from x to the walls, each {gap, unit normal into the vessel}
  function v.gaps(x)
    local w, list = v.walls, {}
    if not cyl_axis then
      for k = 1, dim do
        local e = {}
        for j = 1, dim do e[j] = j == k and 1 or 0 end
        list[#list + 1] = {x[k] - w[2 * k - 1].point[k], e}
        list[#list + 1] = {w[2 * k].point[k] - x[k], {-e[1], -e[2], e[3] and -e[3]}}
      end
      return list
    end
    local ax, c = cyl_axis, w[1].point
    local u, d2 = {}, 0
    for k = 1, 3 do u[k] = k == ax and 0 or c[k] - x[k]; d2 = d2 + u[k] * u[k] end
    local d = math.sqrt(d2)
    if d > 0 then for k = 1, 3 do u[k] = u[k] / d end end
    local e = {0, 0, 0}
    e[ax] = 1
    list[1] = {w[1]:radius() - d, u}
    list[2] = {x[ax] - w[2].point[ax], e}
    list[3] = {w[3].point[ax] - x[ax], {-e[1], -e[2], -e[3]}}
    return list
  end
  -- the mean direct stress on the walls (compression positive): for a
  -- box the mean over its walls, for a cylinder (2 sigma_r + sigma_z) / 3
  function v.stress()
    local areas, s, wsum = v.areas(), 0, 0
    for i, w in ipairs(v.walls) do
      local weight = cyl_axis and (i == 1 and 2 or 0.5) or 1
      s, wsum = s + weight * w:load() / areas[i], wsum + weight
    end
    return s / wsum
  end
  function v.volume()
    local a = v.areas()
    if cyl_axis then return a[2] * (v.walls[3].point[cyl_axis] - v.walls[2].point[cyl_axis]) end
    return a[1] * (v.walls[2].point[1] - v.walls[1].point[1])
  end
  if not cyl_axis then
    v.walls = m:wall{kind = "box", min = lo, max = hi, kn = kn, ks = 0, friction = 0}
    v.region = {box = {lo, hi}}
    function v.areas() -- -x, +x, -y, +y[, -z, +z]: the product of the other two sizes
      local w, areas = v.walls, {}
      for k = 1, dim do
        local a = 1
        for j = 1, dim do if j ~= k then a = a * (w[2 * j].point[j] - w[2 * j - 1].point[j]) end end
        areas[2 * k - 1], areas[2 * k] = a, a
      end
      return areas
    end
    return v
  end
  local ax = cyl_axis
  local other = {}
  for k = 1, 3 do if k ~= ax then other[#other + 1] = k end end
  local radius = 0.5 * (hi[other[1]] - lo[other[1]])
  local point, e, p1, p2 = {}, {}, {}, {}
  for k = 1, 3 do
    point[k] = k == ax and lo[k] or lo[k] + radius
    e[k] = k == ax and 1 or 0
    p1[k], p2[k] = point[k], k == ax and hi[k] or point[k]
  end
  local cyl = m:wall{kind = "cylinder", point = point, axis = e, radius = radius, height = 0, kn = kn, ks = 0,
                     friction = 0}
  local ne = {-e[1], -e[2], -e[3]}
  local b1 = m:wall{kind = "plane", point = p1, normal = e, kn = kn, ks = 0, friction = 0}
  local b2 = m:wall{kind = "plane", point = p2, normal = ne, kn = kn, ks = 0, friction = 0}
  v.walls = {cyl, b1, b2}
  v.region = {cylinder = {p1 = p1, p2 = p2, radius = radius}}
  function v.areas()
    local r, len = cyl:radius(), b2.point[ax] - b1.point[ax]
    return {2 * pi * r * len, pi * r * r, pi * r * r}
  end
  return v
end

-- Servo-controls the walls of a vessel to the stress `target` and cycles
-- until every wall is within `tol` of it and the unbalanced-force ratio is
-- below `ratio`, or `max_steps` pass. Returns the steps taken and the worst
-- relative stress error.
local function servo_vessel(m, v, target, opts)
  local every, start, worst = 200, m:step(), math.huge
  while m:step() - start < opts.max_steps do
    local areas = v.areas()
    for i, w in ipairs(v.walls) do w:servo{target = target, area = areas[i], alpha = 0.5, max_speed = opts.max_speed} end
    m:cycle(every)
    areas = v.areas()
    worst = 0
    for i, w in ipairs(v.walls) do worst = math.max(worst, math.abs(w:load() / areas[i] / target - 1)) end
    if worst < opts.tol and m:ratio() < opts.ratio then break end
  end
  return m:step() - start, worst
end

-- The volume of the bodies: the balls', or the clumps' own (their pebbles overlap).
local function solid_volume(m, clumps)
  if not clumps then return m:sum("volume") end
  local solid = 0
  for cl in m:clumps() do solid = solid + cl.volume end
  return solid
end

-- Clumps cannot grow as balls do in radius expansion; its geometric
-- equivalent is to shrink the vessel and the clumps' centroids together (an
-- affine compaction about the vessel's centre c), by stages of 2 % of the
-- lengths with 100 steps of cycling between them, as the expansion's. The
-- servo cannot compact them from their random placement: a wall pushing a
-- loose assembly moves at G (sigma - target), G = alpha A / (kn Nc dt) being
-- made for contacts the packing backs, i.e. by half the overlap sigma0 asks
-- of its contacts a step (1e-8 m here), while the clumps it pushes fly off
-- undamped (local damping scales forces, and a free body has none): after
-- 300,000 steps a 2D specimen of 300 clumps was loose, its walls 64 % off
-- sigma0 with one to three contacts each. The compaction goes on until the
-- clumps jam: after a stage every wall carries sigma0 or more and still
-- does, with the walls held, once the motion has died out (ratio 1e-2).
-- Before jamming such loads are transients that fade within a few thousand
-- steps as the clumps rearrange. Returns the stages and steps taken, or nil
-- when the clumps fill 95 % of the vessel unjammed.
local function compact_clumps(m, v, c, sigma0)
  local start, stages, solid = m:step(), 0, solid_volume(m, true)
  local function loaded()
    local areas = v.areas()
    for i, w in ipairs(v.walls) do if w:load() / areas[i] < sigma0 then return false end end
    return true
  end
  while solid / v.volume() < 0.95 do
    stages = stages + 1
    local f = 0.98
    for cl in m:clumps() do cl.pos = scaled(cl.pos, f, c) end
    v.scale(f, c)
    m:cycle(100)
    if loaded() then
      for _ = 1, 20 do
        m:cycle(200)
        if not loaded() then break end
        if m:ratio() < 1e-2 then return stages, m:step() - start end
      end
    end
  end
end

return {make = make_vessel, servo = servo_vessel, solid_volume = solid_volume, compact_clumps = compact_clumps}
