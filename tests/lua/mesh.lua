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

-- The force of a fixed ball of radius 0.01 m with its centre at (x, y, 0.01
-- - depth) on a rigid wall of the triangles given (or, with none, on the
-- plane z = 0), and how many contacts it has.
local function pressed(tris, x, y, depth)
  local m = model(nil, {0, 0, 0})
  if tris then m:wall{kind = "mesh", triangles = tris, rigid = true}
  else m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, rigid = true} end
  local b = m:ball{pos = {x, y, 0.01 - depth}, radius = 0.01, material = "rock"}
  b.fix = "all"
  m:cycle(1)
  return b.force, m:contact_count()
end

-- Whether every listed point of a flat mesh at z = 0 presses the ball as the plane does.
local function as_on_the_plane(tris, points, depth)
  local plane = pressed(nil, 0, 0, depth)
  for _, p in ipairs(points) do
    local f, n = pressed(tris, p[1], p[2], depth)
    local what = string.format("the ball over (%g, %g): force (%.6g, %.6g, %.6g) N in %d contacts, the plane's %.6g N",
                               p[1], p[2], f[1], f[2], f[3], n, plane[3])
    T.check(n == 1, what)
    T.check(math.abs(f[3] / plane[3] - 1) < 1e-12 and math.abs(f[1]) + math.abs(f[2]) < 1e-12 * plane[3], what)
  end
end

T.test("a ball pressed near a vertex six facets share feels one contact, the plane's force", function()
  -- four cells of 20 mm about the origin, each cut by its diagonal: six of
  -- the eight facets meet at the origin, two of them only there (they share
  -- no edge with the facet under the ball, and each was counted: 1.9 times
  -- the plane's force 0.5 mm from the vertex)
  local L, tris = 0.02, {}
  for i = -1, 0 do
    for j = -1, 0 do
      local x0, y0, x1, y1 = i * L, j * L, (i + 1) * L, (j + 1) * L
      tris[#tris + 1] = {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}}
      tris[#tris + 1] = {{x0, y0, 0}, {x1, y1, 0}, {x0, y1, 0}}
    end
  end
  local points = {{0, 0}, {0.0005, 0}, {0.0005, 0.0001}, {-0.0003, 0.0007}, {0.0004, 0.0004}, {-0.001, -0.0002}}
  as_on_the_plane(tris, points, 1e-4)
  as_on_the_plane(tris, points, 1e-3) -- pressed in 10 % of its radius, the overlap reaching 4.4 mm round
end)

T.test("a fan of facets closed by trigonometry is welded at its seam: one contact there", function()
  -- sin(2 pi) is -2.4e-16, not 0: the last facet's edge missed the first's
  -- by that, and a ball on the seam had a contact on each side's edge
  local n, R, tris = 8, 0.06, {}
  for k = 0, n - 1 do
    local a0, a1 = 2 * math.pi * k / n, 2 * math.pi * (k + 1) / n
    tris[#tris + 1] = {{0, 0, 0}, {R * math.cos(a0), R * math.sin(a0), 0}, {R * math.cos(a1), R * math.sin(a1), 0}}
  end
  T.eq(model():wall{kind = "mesh", triangles = tris}.vertex_count, n + 1)
  as_on_the_plane(tris, {{0.01, 0}, {0.01, 0.001}, {0.02, -0.0005}, {0.0002, 0}}, 1e-4)
end)

-- Six facets from a hexagon of radius L at z = 0 to its centre at height h
-- (a pyramid rising, or a bowl sinking when h < 0).
local function hexagon_fan(L, h)
  local tris = {}
  for k = 0, 5 do
    local a0, a1 = math.pi / 3 * k, math.pi / 3 * (k + 1)
    tris[#tris + 1] = {{0, 0, h}, {L * math.cos(a0), L * math.sin(a0), 0}, {L * math.cos(a1), L * math.sin(a1), 0}}
  end
  return tris
end

T.test("on a shallow pyramid the apex is one contact, and near it the face under the ball is the only one", function()
  -- six facets rising 5 degrees to an apex 2.6 mm above a hexagon 30 mm round
  local L, h, r, depth = 0.03, 0.03 * math.tan(math.rad(5)), 0.01, 1e-4
  local tris = hexagon_fan(L, h)
  -- straight above the apex: one vertex contact, its overlap the depth
  local f, n = pressed(tris, 0, 0, depth - h)
  T.eq(n, 1)
  T.near(f[3], 1e6 * depth, 1e-9)
  -- over the first facet, down its line of steepest slope (30 degrees round)
  -- from the apex, pressed along its normal: that face alone, as the plane
  -- through it (the other facets' nearest points, on their edges and the
  -- apex, were kept too: 3.3 times the force 1.8 mm from the apex)
  local tilt = math.atan(math.tan(math.rad(5)) / math.cos(math.rad(30)))
  local c, s = math.cos(math.rad(30)), math.sin(math.rad(30))
  local nrm = {math.sin(tilt) * c, math.sin(tilt) * s, math.cos(tilt)}
  for _, from_apex in ipairs{0.0003, 0.001, 0.0018} do
    local q = {from_apex * math.cos(tilt) * c, from_apex * math.cos(tilt) * s, h - from_apex * math.sin(tilt)}
    local m = model(nil, {0, 0, 0})
    m:wall{kind = "mesh", triangles = tris, rigid = true}
    local b = m:ball{pos = {q[1] + (r - depth) * nrm[1], q[2] + (r - depth) * nrm[2], q[3] + (r - depth) * nrm[3]},
                     radius = r, material = "rock"}
    b.fix = "all"
    m:cycle(1)
    local F = b.force
    local what = string.format("%g m from the apex: force (%.6g, %.6g, %.6g) N in %d contacts", from_apex, F[1], F[2],
                               F[3], m:contact_count())
    T.check(m:contact_count() == 1, what)
    for k = 1, 3 do T.check(math.abs(F[k] - 1e6 * depth * nrm[k]) < 1e-9, what) end
  end
end)

T.test("a shallow bowl of facets is one smooth surface: one contact, the nearest face's", function()
  -- six facets sinking 0.5 degrees to a low vertex (each face's own tilt,
  -- down its line of steepest slope, is atan(tan 0.5 / cos 30)): a ball
  -- pressed in over the vertex had a contact on each face, six times the force
  local L, r, depth = 0.03, 0.01, 1e-4
  local h = -L * math.tan(math.rad(0.5))
  local tris = hexagon_fan(L, h)
  local f, n = pressed(tris, 0, 0, depth - h)
  T.eq(n, 1)
  local tilt = math.atan(math.tan(math.rad(0.5)) / math.cos(math.rad(30)))
  local overlap = r - (r - depth) * math.cos(tilt)
  T.near(math.sqrt(f[1] ^ 2 + f[2] ^ 2 + f[3] ^ 2), 1e6 * overlap, 1e-9)
  -- a crease sharper than 20 degrees is a corner: a ball in a 90-degree
  -- trough of two facets has a contact on each side
  local trough = {{{-1, -1, 1}, {0, -1, 0}, {0, 1, 0}}, {{-1, -1, 1}, {0, 1, 0}, {-1, 1, 1}},
                  {{0, -1, 0}, {1, -1, 1}, {1, 1, 1}}, {{0, -1, 0}, {1, 1, 1}, {0, 1, 0}}}
  local _, corner = pressed(trough, 0, 0, 0.01 - 0.0099 * math.sqrt(2))
  T.eq(corner, 2)
end)

-- A valley along y: two strips of facets rising at `deg` degrees each side of x = 0.
local function valley(deg)
  local L, s = 0.05, math.tan(math.rad(deg))
  return {{{-L, -L, L * s}, {0, -L, 0}, {0, L, 0}}, {{-L, -L, L * s}, {0, L, 0}, {-L, L, L * s}},
          {{0, -L, 0}, {L, -L, L * s}, {L, L, L * s}}, {{0, -L, 0}, {L, L, L * s}, {0, L, 0}}}
end

T.test("across a shallow concave crease the force turns smoothly, and a 20-degree crease is merged whatever the rounding", function()
  -- a 10-degree valley (5 each side): one contact along the faces' normals
  -- weighted by their overlaps; the nearest face's normal alone flipped the
  -- sideways force from +12 to -12 N (of 137 N) between x = -1e-9 and 1e-9 m
  local tris, depth = valley(5), 1e-4
  local up = pressed(tris, 0, 0, depth)
  for _, x in ipairs{-1e-9, 1e-9, -1e-6, 1e-6} do
    local f, n = pressed(tris, x, 0, depth)
    T.eq(n, 1)
    T.check(math.abs(f[1]) < 1e-3 * up[3], string.format("x = %g: sideways %g N of %g", x, f[1], f[3]))
  end
  -- 20 degrees between the faces (a drum of 18 strips): one contact at every offset
  tris = valley(10)
  for k = -5, 5 do
    local _, n = pressed(tris, k * 1e-4, 0.004 * k, depth)
    T.eq(n, 1)
  end
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

T.test("a mesh's coordinates scaled (a file in mm), and a corner that is not a number named with its file", function()
  local dir = os.getenv("SEIXO_TEST_DATA")
  local a = model():wall{kind = "mesh", file = dir .. "/square.stl"}
  local b = model():wall{kind = "mesh", file = dir .. "/square.stl", scale = 0.001}
  for v = 1, 4 do
    for k = 1, 3 do T.near(b.vertices[v][k], 0.001 * a.vertices[v][k], 1e-15) end
  end
  local ok, err = pcall(function() return model():wall{kind = "mesh", file = dir .. "/square.stl", scale = 0} end)
  T.check(not ok and err:find("scale", 1, true), err)
  local path = T.tmpname(".stl")
  local f = assert(io.open(path, "w"))
  f:write("solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex nan 1 0\n endloop\nendfacet\nendsolid x\n")
  f:close()
  ok, err = pcall(function() return model():wall{kind = "mesh", file = path} end)
  os.remove(path)
  T.check(not ok and err:find(path, 1, true) and err:find("facet 1, corner 3", 1, true), err)
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
