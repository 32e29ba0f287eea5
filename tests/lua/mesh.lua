-- Triangle-mesh walls: contacts across facets as on one surface, a mesh
-- box against six planes, STL files, bad triangles, threads and restarts.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

local function model(threads, gravity)
  local was = seixo.threads
  seixo.threads = threads or 1
  local m = seixo.model{dim = 3, gravity = gravity or {0, 0, -9.81}, timestep = 2e-5}
  seixo.threads = was
  m:material("rock", {density = 2650, kn = 1e6, ks = 1e6, friction = 0.4})
  m:material("rolling", {density = 2650, kn = 1e6, ks = 1e6, friction = 0.4, rolling_friction = 0.05})
  m:material("damped", {density = 2650, kn = 1e6, ks = 1e6, friction = 0.4, viscous_normal = 0.3})
  return m
end

-- the ball's state, bit for bit
local function same_ball(a, b, what)
  for _, f in ipairs{"pos", "vel", "spin"} do
    local u, v = a[f], b[f]
    for k = 1, 3 do
      if u[k] ~= v[k] then
        error(string.format("%s: ball %s[%d] %.17g on the mesh, %.17g on the plane", what, f, k, u[k], v[k]), 2)
      end
    end
  end
end

-- The square [-1, 1]^2 at z = 0 as two triangles meeting on its diagonal
-- y = x, each given by its corners (a triangle soup, as an STL file has it).
local square = {
  {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}},
  {{-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
}

local function rolling_across(material)
  local p, q = model(), model()
  p:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1e6, ks = 1e6}
  local mesh = q:wall{kind = "mesh", triangles = square, kn = 1e6, ks = 1e6}
  T.eq(mesh.facet_count, 2)
  T.eq(mesh.vertex_count, 4) -- the soup's six corners welded into four
  -- sliding at first, then rolling; x - y goes from -0.2 through 0 at t = 0.25 s
  for _, m in ipairs{p, q} do
    -- resting on the surface: the weight's overlap m g / kn is 1.09e-7 m
    m:ball{pos = {-0.5, -0.3, 0.0099999}, radius = 0.01, material = material, vel = {1, 0.2, 0}, spin = {0, 0, 3}}
  end
  local crossed = false
  for _ = 1, 40 do
    p:cycle(500)
    q:cycle(500)
    local a, b = p:ball(1), q:ball(1)
    same_ball(b, a, "step " .. q:step())
    crossed = crossed or b.pos[1] > b.pos[2]
  end
  T.check(crossed, "the ball did not cross the diagonal")
  T.near(q:ball(1).pos[3], p:ball(1).pos[3], 0)
  T.eq(q:contact_count(), 1) -- one contact, not one per facet
end

T.test("a ball rolling across the shared edge of two coplanar facets moves as on the plane, to the bit", function()
  rolling_across("rock")
end)

T.test("with rolling resistance too (the rolling moment passes to the next facet)", function()
  rolling_across("rolling")
end)

-- The box [0, L]^3: each side two triangles, in the order of the box's
-- planes (-x, +x, -y, +y, -z, +z), wound outward (the mesh is two-sided).
local function box_triangles(L)
  local t = {}
  local function quad(a, b, c, d)
    t[#t + 1] = {a, b, c}
    t[#t + 1] = {a, c, d}
  end
  quad({0, 0, 0}, {0, 0, L}, {0, L, L}, {0, L, 0})
  quad({L, 0, 0}, {L, L, 0}, {L, L, L}, {L, 0, L})
  quad({0, 0, 0}, {L, 0, 0}, {L, 0, L}, {0, 0, L})
  quad({0, L, 0}, {0, L, L}, {L, L, L}, {L, L, 0})
  quad({0, 0, 0}, {0, L, 0}, {L, L, 0}, {L, 0, 0})
  quad({0, 0, L}, {L, 0, L}, {L, L, L}, {0, L, L})
  return t
end

T.test("balls in a mesh box and in a box of six planes follow the same trajectories", function()
  local L = 0.1
  -- gravity towards the corner at the origin, where the balls end touching three sides
  local g = {-4, -3, -9.81}
  local p, q = model(nil, g), model(nil, g)
  p:wall{kind = "box", min = {0, 0, 0}, max = {L, L, L}, kn = 1e6, ks = 1e6}
  q:wall{kind = "mesh", triangles = box_triangles(L), kn = 1e6, ks = 1e6}
  for _, m in ipairs{p, q} do
    -- thrown into a corner and across the faces' diagonals, spinning
    m:ball{pos = {0.05, 0.05, 0.05}, radius = 0.008, material = "damped", vel = {-1.3, -0.9, 0.4}, spin = {5, -3, 2}}
    m:ball{pos = {0.02, 0.08, 0.03}, radius = 0.006, material = "damped", vel = {0.7, -1.1, -0.5}}
  end
  local corners = 0
  for _ = 1, 100 do
    p:cycle(500)
    q:cycle(500)
    for id = 1, 2 do same_ball(q:ball(id), p:ball(id), "ball " .. id .. " at step " .. q:step()) end
    corners = math.max(corners, q:contact_count())
  end
  T.check(corners >= 4, "the balls never touched two sides at once: " .. corners .. " contacts at most")
end)

T.test("STL files, ASCII and binary, give the mesh their triangles give", function()
  local dir = os.getenv("SEIXO_TEST_DATA")
  local a = model():wall{kind = "mesh", file = dir .. "/square.stl"}
  T.eq(a.facet_count, 2)
  T.eq(a.vertex_count, 4)
  local b = model():wall{kind = "mesh", file = dir .. "/square_binary.stl"}
  T.eq(b.facet_count, 2)
  T.eq(b.vertex_count, 4)
  local ok, err = pcall(function() return model():wall{kind = "mesh", file = dir .. "/no_such.stl"} end)
  T.check(not ok and err:find("cannot open", 1, true), err)
  ok, err = pcall(function() return model():wall{kind = "mesh", file = dir .. "/broken.stl"} end)
  T.check(not ok and err:find("line 5", 1, true) and err:find("facet 1", 1, true), err)
end)

T.test("degenerate triangles are an error naming them, or dropped when repair is asked", function()
  local dir = os.getenv("SEIXO_TEST_DATA")
  local ok, err = pcall(function() return model():wall{kind = "mesh", file = dir .. "/degenerate.stl"} end)
  T.check(not ok and err:find("triangle 2", 1, true) and err:find("degenerate", 1, true), err)
  local w = model():wall{kind = "mesh", file = dir .. "/degenerate.stl", repair = true}
  T.eq(w.facet_count, 2)
  ok, err = pcall(function()
    return model():wall{kind = "mesh", triangles = {{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}}}
  end)
  T.check(not ok and err:find("no area", 1, true), err)
end)

T.test("a flipped triangle is turned round to wind as its neighbours", function()
  local dir = os.getenv("SEIXO_TEST_DATA")
  local m = model()
  local w = m:wall{kind = "mesh", file = dir .. "/flipped.stl"}
  T.eq(w.facet_count, 2)
  -- both facets face +z now: the corners of each run anticlockwise seen from above
  local v, t = w.vertices, w.triangles
  for f = 1, 2 do
    local a, b, c = v[t[f][1]], v[t[f][2]], v[t[f][3]]
    local nz = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1])
    T.check(nz > 0, "facet " .. f .. " faces down")
  end
end)

-- A drum-like scene: balls in a mesh box spinning about the x axis (and
-- drifting along it), enough
-- of them (more than 256) for the per-ball passes to run in two blocks.
local function spinning(threads)
  local m = model(threads)
  m:set_timestep(1.5e-5)
  m:wall{kind = "mesh", triangles = box_triangles(0.2), point = {0.1, 0.1, 0.1}, spin = {2, 0, 0}, vel = {0.02, 0, 0},
         kn = 1e6, ks = 1e6}
  m:generate{count = 300, radius = {0.004, 0.005}, region = {box = {{0.01, 0.01, 0.005}, {0.19, 0.19, 0.04}}},
             material = "damped", seed = 3}
  return m
end

T.test("a spinning mesh gives the same bits on 1 and 2 threads", function()
  local a, b = spinning(1), spinning(2)
  a:cycle(8000)
  b:cycle(8000)
  T.check(a:contact_count() > 100, "too few contacts to test: " .. a:contact_count())
  T.eq(a:hash(), b:hash())
end)

T.test("a run restarted from a snapshot with a spinning mesh goes on to the bit", function()
  local a = spinning()
  a:cycle(7000)
  a:save("mesh_restart.h5")
  a:cycle(1000)
  local b = seixo.load("mesh_restart.h5")
  b:cycle(1000)
  T.eq(b:hash(), a:hash())
  local w = b:walls()()
  T.eq(w.kind, "mesh")
  T.eq(w.facet_count, 12)
  T.vec_eq(w.spin, {2, 0, 0})
  T.vec_eq(w.point, a:walls()().point) -- the pose as the run left it
  T.vec_eq(w.vertices[5], a:walls()().vertices[5])
end)

T.test("a mesh wall reports force and moment, and refuses bad input", function()
  local m = model()
  local w = m:wall{kind = "mesh", triangles = square}
  m:ball{pos = {0.3, 0.2, 0.0099}, radius = 0.01, material = "rock"}
  m:cycle(1)
  local f, mo = w.force, w.moment
  T.check(f[3] < 0, "the ball pushes the mesh down")
  -- about the mesh's point (the origin): r x F with r = (0.3, 0.2, ~0)
  T.near(mo[1], 0.2 * f[3], 1e-6)
  T.near(mo[2], -0.3 * f[3], 1e-6)
  local ok, err = pcall(function() return m:wall{kind = "mesh"} end)
  T.check(not ok and err:find("'file'", 1, true), err)
  ok, err = pcall(function() return m:wall{kind = "mesh", triangles = {{{0, 0, 0}, {1, 0, 0}}}} end)
  T.check(not ok and err:find("three", 1, true), err)
  ok, err = pcall(function() return m:wall{kind = "mesh", vertices = {{0, 0, 0}}, triangles = {{1, 2, 3}}} end)
  T.check(not ok and err:find("vertex number", 1, true), err)
  ok, err = pcall(function() w:servo{target = 1e5} end)
  T.check(not ok and err:find("is a mesh", 1, true), err)
  local m2 = seixo.model{dim = 2}
  ok, err = pcall(function() return m2:wall{kind = "mesh", triangles = square} end)
  T.check(not ok and err:find("3D", 1, true), err)
end)

T.done()
