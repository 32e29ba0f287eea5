-- m:generate: random placement, distribute, expand and lattices; regions,
-- radius distributions, reproducibility and errors.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "generate.lua:"

local function volume(dim, r) return dim == 3 and 4 / 3 * math.pi * r ^ 3 or math.pi * r ^ 2 end

local function balls_of(m)
  local list = {}
  for b in m:balls() do list[#list + 1] = {pos = b.pos, r = b.radius, ball = b} end
  return list
end

-- the largest overlap between any two balls, over the smaller radius (O(n^2))
local function worst_overlap(list)
  local worst = 0
  for i = 1, #list do
    for j = i + 1, #list do
      local a, b = list[i], list[j]
      local d2 = 0
      for k = 1, #a.pos do d2 = d2 + (a.pos[k] - b.pos[k]) ^ 2 end
      local over = a.r + b.r - math.sqrt(d2)
      worst = math.max(worst, over / math.min(a.r, b.r))
    end
  end
  return worst
end

-- every ball lies in the region, given as a test function of (pos, r)
local function all_inside(list, inside)
  for _, b in ipairs(list) do
    if not inside(b.pos, b.r) then return false, b.pos end
  end
  return true
end

local function in_box(lo, hi, tol)
  tol = tol or 1e-12
  return function(p, r)
    for k = 1, #lo do
      if p[k] - r < lo[k] - tol or p[k] + r > hi[k] + tol then return false end
    end
    return true
  end
end

test("random in a 3D box: count, inside, no overlap, radii, porosity", function()
  local m = T.model(3)
  local box = {{0, 0, 0}, {0.02, 0.03, 0.04}}
  local n, porosity = m:generate{count = 400, radius = {1e-3, 2e-3}, region = {box = box}, seed = 5}
  eq(n, 400)
  eq(m:ball_count(), 400)
  local list = balls_of(m)
  check(all_inside(list, in_box(box[1], box[2])), "inside the box")
  eq(worst_overlap(list), 0)
  local solid = 0
  for _, b in ipairs(list) do
    check(b.r >= 1e-3 and b.r <= 2e-3, "radius in range")
    solid = solid + volume(3, b.r)
  end
  near(porosity, 1 - solid / (0.02 * 0.03 * 0.04), 1e-12)
end)

test("random in a 2D box, with the box given by min/max, material and group", function()
  local m = T.model(2)
  m:material("glass")
  local n = m:generate{count = 300, radius = 1e-3, region = {box = {min = {0, 0}, max = {0.05, 0.04}}},
                       material = "glass", group = "fill", seed = 2}
  eq(n, 300)
  local list = balls_of(m)
  check(all_inside(list, in_box({0, 0}, {0.05, 0.04})))
  eq(worst_overlap(list), 0)
  for _, b in ipairs(list) do
    eq(b.ball.material, "glass")
    eq(b.ball.group, "fill")
    eq(b.r, 1e-3)
  end
  eq(m:groups().fill, 300)
end)

test("reproducible from the seed", function()
  local function make(seed)
    local m = T.model(3)
    m:generate{count = 200, radius = {1e-3, 2e-3}, region = {box = {{0, 0, 0}, {0.03, 0.03, 0.03}}}, seed = seed}
    return m:hash()
  end
  eq(make(11), make(11))
  check(make(11) ~= make(12), "another seed, another assembly")
end)

test("porosity gives the count", function()
  local m = T.model(2)
  local area = 0.04 * 0.04
  local n, porosity = m:generate{porosity = 0.7, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.04}}}, seed = 3}
  eq(m:ball_count(), n)
  check(porosity <= 0.7 and porosity > 0.7 - 1.5 * volume(2, 1.5e-3) / area, "just past the target: " .. porosity)
end)

test("sphere, cylinder, disk and polygon regions", function()
  local m = T.model(3)
  m:generate{count = 150, radius = 1e-3, region = {sphere = {center = {1, 2, 3}, radius = 0.015}}, seed = 1}
  check(all_inside(balls_of(m), function(p, r)
    return math.sqrt((p[1] - 1) ^ 2 + (p[2] - 2) ^ 2 + (p[3] - 3) ^ 2) + r <= 0.015 + 1e-12
  end))
  local c = T.model(3)
  -- an oblique cylinder from p1 to p2
  local p1, p2, R = {0, 0, 0}, {0.03, 0.03, 0.03}, 0.01
  c:generate{count = 120, radius = 1e-3, region = {cylinder = {p1 = p1, p2 = p2, radius = R}}, seed = 1}
  local len = math.sqrt(3) * 0.03
  check(all_inside(balls_of(c), function(p, r)
    local t = (p[1] + p[2] + p[3]) / math.sqrt(3)
    local q2 = p[1] ^ 2 + p[2] ^ 2 + p[3] ^ 2 - t * t
    return t >= r - 1e-12 and t <= len - r + 1e-12 and math.sqrt(math.max(q2, 0)) + r <= R + 1e-12
  end))
  eq(worst_overlap(balls_of(c)), 0)
  local d = T.model(2)
  d:generate{count = 100, radius = {5e-4, 1e-3}, region = {disk = {center = {-1, 1}, radius = 0.02}}, seed = 4}
  check(all_inside(balls_of(d), function(p, r) return math.sqrt((p[1] + 1) ^ 2 + (p[2] - 1) ^ 2) + r <= 0.02 + 1e-12 end))
  local tri = T.model(2)
  -- a triangle: each ball must be inside and clear of the three edges
  local v = {{0, 0}, {0.1, 0}, {0.05, 0.08}}
  tri:generate{count = 150, radius = 2e-3, region = {polygon = v}, seed = 6}
  check(all_inside(balls_of(tri), function(p, r)
    for i = 1, 3 do
      local a, b = v[i], v[i % 3 + 1]
      local ex, ey = b[1] - a[1], b[2] - a[2]
      local cross = ex * (p[2] - a[2]) - ey * (p[1] - a[1])  -- > 0: left of a counter-clockwise edge
      if cross / math.sqrt(ex * ex + ey * ey) < r - 1e-12 then return false end
    end
    return true
  end))
  eq(worst_overlap(balls_of(tri)), 0)
end)

test("truncated normal radii", function()
  local m = T.model(3)
  m:generate{count = 3000, radius = {1e-3, 3e-3}, distribution = "normal", mean = 1.5e-3, std = 4e-4,
             region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}, seed = 9}
  local s, s2, lo, hi = 0, 0, math.huge, 0
  for b in m:balls() do
    local r = b.radius
    s, s2 = s + r, s2 + r * r
    lo, hi = math.min(lo, r), math.max(hi, r)
  end
  local n = m:ball_count()
  local mean = s / n
  local sd = math.sqrt(s2 / n - mean * mean)
  check(lo >= 1e-3 and hi <= 3e-3, "truncated to the range")
  -- the truncation at 1e-3, 1.25 sd below the mean, lifts the mean by
  -- sd phi(1.25) / Phi(1.25) = 0.204 sd and narrows the sd to 0.839 sd
  check(math.abs(mean - (1.5e-3 + 0.204 * 4e-4)) < 4 * 4e-4 / math.sqrt(n), "mean " .. mean)
  check(math.abs(sd - 0.839 * 4e-4) < 0.05 * 4e-4, "sd " .. sd)
  -- uniform: the mean of the range
  local u = T.model(3)
  u:generate{count = 3000, radius = {1e-3, 3e-3}, region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}, seed = 9}
  near(u:mean("radius"), 2e-3, 4 * (2e-3 / math.sqrt(12)) / math.sqrt(3000) / 2e-3)
end)

-- The volume fraction of the balls up to radius x, and its standard error
-- by the delta method (a ratio of two sample means), so that the bound is
-- the sampling's own and not a tolerance picked to pass.
local function passing(m, dim, x)
  local n, sv, sa = 0, 0, 0
  for b in m:balls() do
    local v = b.radius ^ dim
    n, sv = n + 1, sv + v
    if b.radius <= x then sa = sa + v end
  end
  local frac = sa / sv
  local var = 0
  for b in m:balls() do
    local v = b.radius ^ dim
    var = var + (v * ((b.radius <= x and 1 or 0) - frac)) ^ 2
  end
  return frac, math.sqrt(var / n) / (sv / n) / math.sqrt(n)
end

test("a grading curve (psd): the balls' volume passing each point", function()
  local curve = {{0.5e-3, 0}, {0.8e-3, 0.1}, {1.2e-3, 0.5}, {1.3e-3, 0.5}, {2e-3, 0.9}, {3e-3, 1}}
  for _, dim in ipairs{2, 3} do
    local m = T.model(dim)
    local region = dim == 3 and {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}} or {box = {{0, 0}, {0.6, 0.6}}}
    m:generate{count = 20000, psd = curve, region = region, seed = 3}
    local lo, hi, gap = math.huge, 0, 0
    for b in m:balls() do
      lo, hi = math.min(lo, b.radius), math.max(hi, b.radius)
      if b.radius > 1.2e-3 and b.radius < 1.3e-3 then gap = gap + 1 end
    end
    check(lo >= 0.5e-3 and hi <= 3e-3, "within the curve's radii")
    eq(gap, 0)  -- a flat stretch of the curve holds no balls
    for i = 2, #curve - 1 do
      local frac, se = passing(m, dim, curve[i][1])
      check(math.abs(frac - curve[i][2]) < 4 * se, string.format("%dD passing %g: %g (se %g), curve %g", dim, curve[i][1], frac,
                                                                 se, curve[i][2]))
    end
    -- by porosity: balls are drawn until their volume reaches the target
    local p = T.model(dim)
    local _, porosity = p:generate{porosity = 0.9, psd = curve, region = region, seed = 4}
    check(porosity <= 0.9 and porosity > 0.89, "porosity " .. porosity)
  end
  -- one bin: the count's density goes as r^-dim (3D: the mean radius of
  -- r^-3 on [a, b] is 2ab/(a + b))
  local m = T.model(3)
  m:generate{count = 5000, psd = {{1e-3, 0}, {3e-3, 1}}, region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}, seed = 5}
  local s, s2 = 0, 0
  for b in m:balls() do s, s2 = s + b.radius, s2 + b.radius ^ 2 end
  local mean = s / 5000
  local sd = math.sqrt(s2 / 5000 - mean * mean)
  check(math.abs(mean - 2 * 1e-3 * 3e-3 / 4e-3) < 4 * sd / math.sqrt(5000), "mean radius " .. mean)
end)

test("lognormal radii: the truncated distribution's mean and sd", function()
  local mu_r, sd_r, a, b = 1e-3, 0.4e-3, 0.5e-3, 3e-3
  local m = T.model(3)
  m:generate{count = 20000, radius = {a, b}, distribution = "lognormal", mean = mu_r, std = sd_r,
             region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}, seed = 9}
  -- the moments of ln r for r's mean and sd, and the truncated moments by quadrature
  local s2 = math.log(1 + (sd_r / mu_r) ^ 2)
  local mu = math.log(mu_r) - s2 / 2
  local z, m1, m2 = 0, 0, 0
  local steps = 20000
  for i = 0, steps - 1 do
    local r = a + (b - a) * (i + 0.5) / steps
    local f = math.exp(-(math.log(r) - mu) ^ 2 / (2 * s2)) / r
    z, m1, m2 = z + f, m1 + f * r, m2 + f * r * r
  end
  local want_mean, want_sd = m1 / z, math.sqrt(m2 / z - (m1 / z) ^ 2)
  local n, s, q, lo, hi = 0, 0, 0, math.huge, 0
  for ball in m:balls() do
    local r = ball.radius
    n, s, q, lo, hi = n + 1, s + r, q + r * r, math.min(lo, r), math.max(hi, r)
  end
  local mean = s / n
  local sd = math.sqrt(q / n - mean * mean)
  check(lo >= a and hi <= b, "truncated to the range")
  check(math.abs(mean - want_mean) < 4 * want_sd / math.sqrt(n), string.format("mean %g, expected %g", mean, want_mean))
  check(math.abs(sd - want_sd) < 0.05 * want_sd, string.format("sd %g, expected %g", sd, want_sd))
  -- a skewed law: the median is below the mean, at exp(mu) untruncated
  check(want_mean > math.exp(mu), "lognormal's mean above its median")
end)

test("existing balls are avoided", function()
  local m = T.model(2)
  local region = {box = {{0, 0}, {0.06, 0.06}}}
  m:generate{count = 100, radius = 1e-3, region = region, seed = 1}
  m:generate{count = 100, radius = 1.5e-3, region = region, seed = 2}
  eq(m:ball_count(), 200)
  eq(worst_overlap(balls_of(m)), 0)
end)

test("no room: a clear error, and nothing added", function()
  local m = T.model(3)
  local before = m:ball_count()
  local err = raises(function()
    m:generate{count = 5000, radius = 2e-3, region = {box = {{0, 0, 0}, {0.02, 0.02, 0.02}}}, tries = 200}
  end, HERE, "m:generate: placed", "of 5000 balls", "no room", "after 200 tries", "distribute")
  eq(m:ball_count(), before)
  raises(function() m:generate{count = 1, radius = 0.5, region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}} end,
         HERE, "does not fit in the region")
  check(err:find("^.-generate.lua:%d+:"), "the script's position first: " .. err)
end)

test("100k balls are placed in seconds", function()
  local m = T.model(3)
  local t0 = os.clock()
  local n = m:generate{count = 100000, radius = {0.8e-3, 1.2e-3}, region = {box = {{0, 0, 0}, {0.12, 0.12, 0.12}}}, seed = 1}
  local elapsed = os.clock() - t0
  eq(n, 100000)
  check(elapsed < 10, "took " .. elapsed .. " s")
end)

-- after distribute or expand: porosity, balls in the walls' box, small overlaps, gravity restored
-- (exact: count and porosity given, the radii scaled to it; else just past the target)
local function check_relaxed(m, dim, n, porosity, target, lo, hi, exact)
  eq(m:ball_count(), n)
  local list = balls_of(m)
  local solid = 0
  for _, b in ipairs(list) do solid = solid + volume(dim, b.r) end
  local v = 1
  for k = 1, dim do v = v * (hi[k] - lo[k]) end
  near(porosity, 1 - solid / v, 1e-12)  -- relaxation moves centres only
  if exact then
    near(porosity, target, 1e-9)
  else
    check(porosity <= target and porosity > target - volume(dim, m:max("radius")) / v, "porosity " .. porosity)
  end
  check(worst_overlap(list) < 0.05, "overlaps relaxed: " .. worst_overlap(list))
  check(all_inside(list, in_box(lo, hi, 0.05 * m:max("radius"))), "inside the walls")
  T.vec_eq(m:gravity(), dim == 3 and {0, 0, -9.81} or {0, -9.81})
  check(m:step() > 0, "it cycled")
end

-- porosities well above random close packing (2D 0.16, 3D 0.36), as a box
-- of ten diameters packs looser than an unbounded assembly
local loose = {[2] = 0.3, [3] = 0.55}
for _, dim in ipairs({2, 3}) do
  test(dim .. "D distribute to a porosity, then relaxed", function()
    local m = T.model(dim, {gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}})
    local lo, hi = T.zero(dim), dim == 3 and {0.02, 0.02, 0.02} or {0.04, 0.04}
    m:wall{kind = "box", min = lo, max = hi}
    local n, porosity = m:generate{method = "distribute", porosity = loose[dim], radius = {0.8e-3, 1.2e-3},
                                   region = {box = {lo, hi}}, seed = 4}
    check_relaxed(m, dim, n, porosity, loose[dim], lo, hi, false)
  end)

  test(dim .. "D radius expansion to a porosity", function()
    local m = T.model(dim, {gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}})
    local lo, hi = T.zero(dim), dim == 3 and {0.02, 0.02, 0.02} or {0.04, 0.04}
    m:wall{kind = "box", min = lo, max = hi}
    local n, porosity = m:generate{method = "expand", porosity = loose[dim], count = dim == 2 and 250 or 900, radius = {0.8e-3, 1.2e-3},
                                   region = {box = {lo, hi}}, seed = 4}
    check_relaxed(m, dim, n, porosity, loose[dim], lo, hi, true)
    -- the radii keep the drawn distribution's spread: one common factor
    check(m:max("radius") / m:min("radius") <= 1.5 + 1e-9, "ratio of extremes within 1.2/0.8")
  end)
end

test("distribute without relaxation leaves the model uncycled", function()
  local m = T.model(3)
  local n = m:generate{method = "distribute", porosity = 0.5, radius = 1e-3, region = {box = {{0, 0, 0}, {0.01, 0.01, 0.01}}},
                       relax = false}
  check(n > 0)
  eq(m:step(), 0)
  raises(function() m:generate{method = "distribute", porosity = 0.5, radius = 1e-3, region = {box = {{0, 0, 0}, {0.01, 0.01, 0.01}}},
                               relax = {stepz = 1}} end, HERE, "field 'relax'", "unknown key 'stepz'")
end)

test("lattices: square, hex, cubic, fcc", function()
  local r = 1e-3
  -- square: 10 x 5 sites in a 0.02 x 0.01 box
  local m = T.model(2)
  local n, porosity = m:generate{packing = "square", radius = r, region = {box = {{0, 0}, {0.02, 0.01}}}}
  eq(n, 50)
  near(porosity, 1 - 50 * math.pi * r * r / 2e-4, 1e-12)
  -- hex: rows sqrt(3) r apart, 10 then 9 sites (odd rows shifted by r)
  local h = T.model(2)
  n = h:generate{method = "lattice", packing = "hex", radius = r, region = {box = {{0, 0}, {0.02, 0.01}}}}
  local rows = math.floor((0.01 - 2 * r) / (math.sqrt(3) * r)) + 1
  eq(n, math.ceil(rows / 2) * 10 + math.floor(rows / 2) * 9)
  check(worst_overlap(balls_of(h)) < 1e-9, "touching, not overlapping")
  -- every hex ball has neighbours at exactly 2r
  local list = balls_of(h)
  local touching = 0
  for i = 2, #list do
    local d = math.sqrt((list[i].pos[1] - list[1].pos[1]) ^ 2 + (list[i].pos[2] - list[1].pos[2]) ^ 2)
    if math.abs(d - 2 * r) < 1e-12 then touching = touching + 1 end
  end
  eq(touching, 2, "the corner ball of a hex lattice touches two")
  local c = T.model(3)
  eq(c:generate{packing = "cubic", radius = r, region = {box = {{0, 0, 0}, {0.01, 0.006, 0.004}}}}, 5 * 3 * 2)
  local f = T.model(3)
  -- fcc: cell 2 sqrt(2) r; in a cube of 4 cells per side exactly, corner and face sites that fit
  local a = 2 * math.sqrt(2) * r
  n = f:generate{packing = "fcc", radius = r, region = {box = {{0, 0, 0}, {4 * a + 2 * r, 4 * a + 2 * r, 4 * a + 2 * r}}}}
  eq(n, 5 ^ 3 + 3 * 4 * 4 * 5)
  check(worst_overlap(balls_of(f)) < 1e-9)
  near(1 - n * volume(3, r) / (4 * a + 2 * r) ^ 3, select(2, T.model(3):generate{packing = "fcc", radius = r,
       region = {box = {{0, 0, 0}, {4 * a + 2 * r, 4 * a + 2 * r, 4 * a + 2 * r}}}}), 1e-12)
  -- a count takes the first sites; too many is an error
  eq(T.model(2):generate{packing = "square", radius = r, count = 7, region = {box = {{0, 0}, {0.02, 0.01}}}}, 7)
  raises(function() T.model(2):generate{packing = "square", radius = r, count = 51, region = {box = {{0, 0}, {0.02, 0.01}}}} end,
         HERE, "only 50 lattice sites")
  -- a lattice in a disk keeps only the sites whose balls are inside
  local d = T.model(2)
  d:generate{packing = "hex", radius = r, region = {disk = {center = {0, 0}, radius = 0.01}}}
  check(all_inside(balls_of(d), function(p, rr) return math.sqrt(p[1] ^ 2 + p[2] ^ 2) + rr <= 0.01 + 1e-9 end))
end)

test("argument errors name the function, the field and the position", function()
  local m3, m2 = T.model(3), T.model(2)
  local box3 = {box = {{0, 0, 0}, {1, 1, 1}}}
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, sead = 1} end, HERE,
         "bad argument #1 to 'generate'", "unknown key 'sead'")
  raises(function() m3:generate{count = 1, radius = 0.1} end, HERE, "field 'region' is required")
  raises(function() m3:generate{count = 1, region = box3} end, HERE, "field 'radius'", "required")
  raises(function() m3:generate{count = 1, radius = -1, region = box3} end, HERE, "field 'radius'")
  raises(function() m3:generate{count = 1, radius = {2, 1}, region = box3} end, HERE, "field 'radius'")
  raises(function() m3:generate{count = 1, radius = {0.1, "x"}, region = box3} end, HERE, "field 'radius'")
  raises(function() m3:generate{count = -1, radius = 0.1, region = box3} end, HERE, "field 'count'")
  raises(function() m3:generate{count = 1e9, radius = 0.1, region = box3} end, HERE, "field 'count'")
  raises(function() m3:generate{count = 1, porosity = 0.5, radius = 0.1, region = box3} end, HERE, "'count' or 'porosity'")
  raises(function() m3:generate{radius = 0.1, region = box3} end, HERE, "'count' or 'porosity'")
  raises(function() m3:generate{porosity = 1.5, radius = 0.1, region = box3} end, HERE, "field 'porosity'")
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, method = "pour"} end, HERE,
         "field 'method'", "unknown 'pour'", "random, distribute, expand, lattice")
  raises(function() m3:generate{method = "distribute", count = 5, radius = 0.1, region = box3} end, HERE,
         "'porosity' is required")
  raises(function() m3:generate{packing = "hex", radius = 0.1, region = box3} end, HERE, "'cubic' or 'fcc' in 3D")
  raises(function() m2:generate{packing = "fcc", radius = 0.1, region = {box = {{0, 0}, {1, 1}}}} end, HERE, "in 2D")
  raises(function() m3:generate{packing = "fcc", radius = {0.1, 0.2}, region = box3} end, HERE, "one radius")
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, mean = 0.1} end, HERE, "field 'mean'", "'normal' or 'lognormal'")
  raises(function() m3:generate{count = 1, radius = {0.1, 0.2}, region = box3, distribution = "normal", mean = 0.5} end,
         HERE, "field 'mean'")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 100}}, region = box3} end, HERE, "field 'psd'",
         "point 2", "a percentage? divide by 100")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0.2}, {0.2, 1}}, region = box3} end, HERE, "field 'psd'", "start at fraction 0")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 0.9}}, region = box3} end, HERE, "end at 1")
  raises(function() m3:generate{count = 1, psd = {{0.2, 0}, {0.1, 1}}, region = box3} end, HERE, "point 2", "increasing")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 0.6}, {0.3, 0.5}, {0.4, 1}}, region = box3} end, HERE,
         "point 3", "must not decrease")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2}}, region = box3} end, HERE, "point 2", "two numbers")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}}, region = box3} end, HERE, "2 to 100 points")
  raises(function() m3:generate{count = 1, psd = 0.1, region = box3} end, HERE, "field 'psd'", "got number")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 1}}, radius = 0.1, region = box3} end, HERE, "field 'radius'",
         "leave this out")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 1}}, distribution = "normal", region = box3} end, HERE,
         "field 'distribution'")
  raises(function() m3:generate{count = 1, psd = {{0.1, 0}, {0.2, 1}}, mean = 0.15, region = box3} end, HERE, "field 'mean'")
  raises(function() m3:generate{packing = "fcc", psd = {{0.1, 0}, {0.2, 1}}, region = box3} end, HERE, "field 'psd'", "one radius")
  raises(function() m3:generate{count = 1, radius = {0.1, 0.2}, distribution = "lognormal", mean = 0.05, region = box3} end,
         HERE, "field 'mean'", "[rmin, rmax]")
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, material = "glass"} end, HERE, "no material named 'glass'")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {disk = {center = {0, 0}, radius = 1}}} end, HERE,
         "field 'region'", "a disk is a 2D region")
  raises(function() m2:generate{count = 1, radius = 0.1, region = {sphere = {center = {0, 0, 0}, radius = 1}}} end, HERE,
         "a sphere is a 3D region")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {box = {{0, 0, 0}, {1, 0, 1}}}} end, HERE, "max must exceed min")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {box = box3.box, sphere = {}}} end, HERE, "one shape")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {cube = 1}} end, HERE, "unknown key 'cube'")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {sphere = {center = {0, 0, 0}}}} end, HERE, "'radius' is required")
  raises(function() m3:generate{count = 1, radius = 0.1, region = {cylinder = {p1 = {0, 0, 0}, p2 = {0, 0, 0}, radius = 1}}} end,
         HERE, "p1 and p2 must differ")
  raises(function() m2:generate{count = 1, radius = 0.1, region = {polygon = {{0, 0}, {1, 0}}}} end, HERE, "3 to 1e6 vertices")
  raises(function() m2:generate{count = 1, radius = 0.1, region = {polygon = {{0, 0}, {1, 0}, {2, 0}}}} end, HERE, "area is zero")
  raises(function() m2:generate{count = 1, radius = 0.1, region = {polygon = {{0, 0}, {1, 0}, {0, 1}, x = 1}}} end, HERE,
         "an array expected")
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, seed = -3} end, HERE, "field 'seed'")
  raises(function() m3:generate{count = 1, radius = 0.1, region = box3, tries = 0} end, HERE, "field 'tries'")
  eq(m3:ball_count(), 0)
  eq(m2:ball_count(), 0)
end)

-- issue 18: a count of 0 (or -0.0) once sized the placement grid by a NaN
-- and never returned; radii whose volume overflows are refused
test("nothing to generate returns at once, in every method, clumps included", function()
  for _, dim in ipairs({2, 3}) do
    local z, one = T.zero(dim), dim == 3 and {1, 1, 1} or {1, 1}
    for _, method in ipairs({"random", "distribute", "expand", "lattice"}) do
      for _, count in ipairs({0, -0.0}) do
        local m = seixo.model{dim = dim}
        m:material("rock")
        local spec = {count = count, radius = 0.01, method = method, region = {box = {z, one}}}
        if method == "distribute" or method == "expand" then spec.porosity = 0.5 end
        local n, porosity = m:generate(spec)
        eq(n, 0)
        eq(porosity, 1)
        m:clump_template("pair", dim == 3 and {{0, 0, 0, 0.01}, {0.01, 0, 0, 0.01}} or {{0, 0, 0.01}, {0.01, 0, 0.01}})
        if method == "random" then
          eq(m:generate{template = "pair", count = count, region = {box = {z, one}}}, 0)
        end
        eq(m:ball_count(), 0)
      end
    end
    local m = seixo.model{dim = dim}
    m:material("rock")
    raises(function() m:generate{count = 3, radius = 1e300, method = "expand", porosity = 0.5, region = {box = {z, one}}} end,
           HERE, "cannot be scaled")
    raises(function() m:generate{count = 3, radius = 1e300, region = {box = {z, one}}} end, HERE, "does not fit")
  end
end)

T.done()
