-- Lua-level checks of the lab bindings: cylinder walls, servo control, measurement.
local passed, failed = 0, 0
local function check(name, ok, msg)
  if ok then passed = passed + 1 else failed = failed + 1; print("FAIL " .. name .. ": " .. tostring(msg)) end
end

do
  -- simple cubic block of whole cells: porosity 1 - pi/6, coordination 6 inside, fabric I/3
  local m = seixo.model{dim = 3, timestep = 1e-6}
  m:material("s", {kn = 1e7, ks = 1e7, density = 2500})
  local r, s, n = 1e-3, 2e-3 - 1e-6, 6
  for k = 0, n - 1 do for j = 0, n - 1 do for i = 0, n - 1 do
    m:ball{pos = {i * s, j * s, k * s}, radius = r}.fix = "all" -- held where they are: the lattice's geometry
  end end end
  m:cycle(1)
  local whole = m:measure{box = {min = {-s / 2, -s / 2, -s / 2}, max = {(n - 0.5) * s, (n - 0.5) * s, (n - 0.5) * s}}}
  -- the balls overlap their cells by h: the box's faces cut a cap off each
  -- of the n^2 balls along each of its 6 faces (within, the caps stay in)
  local h = r - s / 2
  local cap = math.pi * h * h * (3 * r - h) / 3
  local expected = 1 - (n ^ 3 * 4 / 3 * math.pi * r ^ 3 - 6 * n ^ 2 * cap) / (n * s) ^ 3
  check("porosity of whole cells", math.abs(whole.porosity - expected) < 1e-12, whole.porosity)
  local inner = m:measure{sphere = {center = {2.5 * s, 2.5 * s, 2.5 * s}, radius = 1.5 * s}}
  check("coordination inside", math.abs(inner.coordination - 6) < 1e-12, inner.coordination)
  check("fabric I/3", math.abs(inner.fabric[1][1] - 1 / 3) < 1e-12 and math.abs(inner.fabric[1][2]) < 1e-12,
        inner.fabric[1][1])
  check("compression positive", inner.stress[1][1] > 0 and inner.stress[3][3] > 0, inner.stress[1][1])
  local ok, err = pcall(m.measure, m, {box = {min = {0, 0, 0}, max = {0, 1, 1}}})
  check("empty box refused", not ok, err)
  ok, err = pcall(m.measure, m, {sphere = {center = {0, 0, 0}, radius = 1}, box = {min = {0, 0, 0}, max = {1, 1, 1}}})
  check("one region only", not ok, err)
end

do
  -- a region's solid is the balls' part inside it, cut where its boundary
  -- crosses them (it counted every ball whose centre was inside, whole: a
  -- region half a ball's radius across read a porosity of -7)
  for _, dim in ipairs{2, 3} do
    local m = seixo.model{dim = dim}
    m:material("s", {kn = 1e6, ks = 1e6, density = 1000})
    local function v(x, y, z) return dim == 3 and {x, y, z} or {x, y} end
    m:ball{pos = v(0, 0, 0), radius = 1}
    local V = dim == 3 and 4 / 3 * math.pi or math.pi
    local function solid(region) return m:measure(region).solid end
    local function near(name, got, want, tol)
      check(dim .. "D " .. name, math.abs(got - want) <= tol * math.abs(want), got .. " vs " .. want)
    end
    near("a box about the whole ball", solid{box = {min = v(-2, -2, -2), max = v(2, 2, 2)}}, V, 1e-12)
    near("a half", solid{box = {min = v(0, -2, -2), max = v(2, 2, 2)}}, V / 2, 1e-12)
    near("a slab", solid{box = {min = v(-0.5, -2, -2), max = v(0.5, 2, 2)}},
         dim == 3 and math.pi * (1 - 0.25 / 3) or 2 * (0.5 * math.sqrt(0.75) + math.asin(0.5)), 1e-9)
    near("a box inside the ball", solid{box = {min = v(-0.2, -0.3, -0.1), max = v(0.3, 0.1, 0.4)}},
         dim == 3 and 0.1 or 0.2, 1e-12)
    local round = dim == 3 and "sphere" or "disk"
    local inner = m:measure{[round] = {center = v(0, 0, 0), radius = 0.5}}
    near("a region inside the ball: porosity 0", 1 - inner.porosity, 1, 1e-12)
    near("a lens", solid{[round] = {center = v(1, 0, 0), radius = 1}},
         dim == 3 and 5 * math.pi / 12 or 2 * math.pi / 3 - math.sqrt(3) / 2, 1e-12)
    -- a box whose corner lies inside the ball, against counting a grid's points
    local lo, hi = v(0.3, 0.2, -0.4), v(2, 2, 2)
    local nx, count, h = dim == 3 and 100 or 1000, 0, nil
    h = 2 / nx
    for i = 0, nx - 1 do for j = 0, nx - 1 do for k = 0, (dim == 3 and nx - 1 or 0) do
      local x, y, z = -1 + (i + 0.5) * h, -1 + (j + 0.5) * h, dim == 3 and -1 + (k + 0.5) * h or 0
      if x * x + y * y + z * z <= 1 and x >= lo[1] and y >= lo[2] and (dim == 2 or z >= lo[3]) then count = count + 1 end
    end end end
    near("a box's corner in the ball", solid{box = {min = lo, max = hi}}, count * h ^ dim, 1e-2)
  end
end

do
  -- one ball held by a servo-controlled cylinder: the load reaches target * area
  local m = seixo.model{dim = 3, timestep = 1e-5}
  m:material("s", {kn = 1e6, ks = 1e6, density = 2500, damping = 0.7})
  local b = m:ball{pos = {0, 0, 0.005}, radius = 0.005}
  b.fix = "all"
  local c = m:wall{kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}, radius = 0.006, height = 0.01, kn = 1e6, ks = 1e6}
  c:servo{target = 1e4, area = 1e-3, alpha = 0.5, max_speed = 0.05}
  m:cycle(20000)
  local load, contacts = c:load()
  check("servo holds the target", contacts == 1 and math.abs(load / 1e-3 - 1e4) < 1e-3 * 1e4, load)
  local radius = c:radius()
  check("radius moved in", radius < 0.006 and radius > 0.0049, radius)
  c:servo(nil)
  local ok, err = pcall(c.servo, c, {target = 1, area = -1})
  check("bad area refused", not ok and tostring(err):find("area"), err)
  ok, err = pcall(m.wall, m, {kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}})
  check("radius required", not ok and tostring(err):find("radius"), err)
end

do
  -- lab.write_csv: names quoted as needed, NaN and infinities spelt alike,
  -- ragged rows and cells that are no numbers refused with their place
  local lab = require("seixo.lab")
  local util = require("seixo.util")
  local path = os.tmpname()
  lab.write_csv(path, {"a,b", "c"}, {{1, 0 / 0}, {math.huge}, {nil, -math.huge}})
  local t = util.read_csv(path)
  check("csv: a name with a comma is one column", #t.header == 2 and t.header[1] == "a,b", table.concat(t.header, "|"))
  local c1 = t.columns.c[1]
  check("csv: nan, inf, -inf read back as numbers", c1 ~= c1 and t.columns["a,b"][2] == math.huge and
        t.columns.c[3] == -math.huge, tostring(c1))
  check("csv: spelt nan, inf, -inf", io.open(path):read("a"):find("1,nan\ninf,\n,-inf\n", 1, true), "text")
  local ok, err = pcall(lab.write_csv, path, {"a"}, {{1}, {1, 2}})
  check("csv: a row longer than the header", not ok and err:find("row 2 has 2 cells, the header 1 names", 1, true), err)
  ok, err = pcall(lab.write_csv, path, {"a", "b"}, {{1, "x"}})
  check("csv: a cell that is no number", not ok and err:find("row 1, column 'b': a number expected, got string", 1, true), err)
  os.remove(path)
end

do
  -- a servo sets its wall's normal velocity only: a velocity along the wall
  -- (a shear box's top plate riding with its upper half) goes on, 2D and 3D,
  -- and a tilted wall's too
  for _, dim in ipairs{2, 3} do
    local m = seixo.model{dim = dim, timestep = 1e-5}
    m:material("s", {kn = 1e6, ks = 1e6, density = 2500, damping = 0.7})
    local zero = dim == 3 and {0, 0, 0} or {0, 0}
    local b = m:ball{pos = zero, radius = 0.005}
    b.fix = "all"
    local n = dim == 3 and {0, 0.6, -0.8} or {0.6, -0.8}
    local w = m:wall{kind = dim == 3 and "plane" or "line", point = dim == 3 and {0, -0.0036, 0.0048} or {-0.0036, 0.0048},
                     normal = n, kn = 1e6, ks = 0}
    w:servo{target = 1e4, area = 1e-3, max_speed = 0.05}
    local t = dim == 3 and {1, 0, 0} or {0.8, 0.6} -- along the wall
    w.vel = {0.01 * t[1], 0.01 * t[2], dim == 3 and 0.01 * t[3] or nil}
    m:cycle(20000)
    local v, along = w.vel, 0
    for k = 1, dim do along = along + v[k] * t[k] end
    check(dim .. "D servo keeps the velocity along the wall", math.abs(along - 0.01) < 1e-12, along)
    local load, contacts = w:load()
    check(dim .. "D servo holds its target meanwhile", contacts == 1 and math.abs(load / 1e-3 - 1e4) < 1e-2 * 1e4, load)
  end
end

do
  -- issue 18: errors raised inside seixo.lab point at the caller's line,
  -- and a test that would cycle nothing forever (every = 0) is refused
  local lab = require("seixo.lab")
  -- a specimen table with every field the tests read, of no file: the options fail first
  local rect = {dim = 2, shape = "rect", path = "none.h5", wall_kn = 1e9, material = lab.rock(), radius = {1e-3, 2e-3}}
  local disk = {dim = 2, shape = "disk", path = "none.h5", wall_kn = 1e9, material = lab.rock()}
  local here = "lab.lua:" .. (debug.getinfo(1, "l").currentline + 2) .. ": "
  local cases = {
    {"ucs every = 0", function() lab.ucs(rect, {every = 0}) end, "every must be a whole number"},
    {"ucs every = NaN", function() lab.ucs(rect, {every = 0 / 0}) end, "every must be"},
    {"ucs max_steps = 0.5", function() lab.ucs(rect, {max_steps = 0.5}) end, "max_steps must be"},
    {"brazilian every = 0", function() lab.brazilian(disk, {every = 0}) end, "every must be"},
    {"triaxial unknown option", function() lab.triaxial(rect, {bogus = 1}) end, "unknown option"},
    {"mohr_coulomb", function() lab.mohr_coulomb(5) end, "two failure states"},
    {"a number for a specimen", function() lab.ucs(5) end, "a specimen (from lab.specimen or lab.open) expected"},
    {"write_csv to a table", function() lab.write_csv({}, {"a"}, {}) end, "its path must be a string, not a table"},
    {"write_csv to a long name", function() lab.write_csv(string.rep("z", 300), {"a"}, {}) end, "File name too long"},
  }
  for i, c in ipairs(cases) do
    local ok, err = pcall(c[2])
    -- every case's function is on its own line of the table above
    local line = tonumber(here:match(":(%d+): ")) + i - 1
    local at = "lab.lua:" .. line .. ": "
    check(c[1], not ok and tostring(err):find(at, 1, true) and tostring(err):find(c[3], 1, true)
          and not tostring(err):find("seixo/", 1, true), err)
  end
end

print(string.format("%d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
