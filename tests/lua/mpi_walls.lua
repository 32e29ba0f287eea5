-- Mesh walls under the MPI decomposition (issue 16; test lua_mpi_walls
-- through mpi_same.sh): serially and under mpirun -np 1 ... 4 each scene
-- prints the same lines, to the bit. The ranks cut the balls by count
-- along z, so every mesh below meets the slab of every rank.
--   plough   a bed of 675 balls (an fcc lattice) settled on a floor read
--            from an STL file (tests/data/square.stl) between four planes,
--            ploughed by a 96-facet mesh wedge taller than the bed, moving
--            along x and turning about its vertical axis, the automatic
--            timestep: the state hash, the plough's and the floor's force
--            and moment (the balls' resultants, summed over the wall
--            blocks of every rank) and the contact count at four points;
--            the plough's contacts in every quarter of the bed's height.
--   drum     700 balls in a 108-facet mesh box turning about x (and
--            drifting along it), with rolling resistance: the turning
--            sides drag the balls across the slabs; the box's force and
--            moment and the state hash as above.
--   drum hertz  the same with Hertz-Mindlin grains and Mindlin &
--            Deresiewicz's unloading (laws/mindlin_unloading.h: the
--            previous overlap from each pair's history, on every rank).
local scene = arg and arg[1] or "plough"
local dir = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"

local function vec(v) return string.format("%.17g %.17g %.17g", v[1], v[2], v[3]) end

local function report(m, tag, walls)
  print(string.format("%s step %d contacts %d hash %s", tag, m:step(), m:contact_count(), m:hash()))
  for _, w in ipairs(walls) do
    print(string.format("  %s force %s moment %s", w.name, vec(w.wall.force), vec(w.wall.moment)))
  end
end

-- The contacts of wall w in each quarter of the balls by height (the ranks'
-- slabs cut the balls by count along z: with 4 ranks, about these
-- quarters), as "a b c d"; an error unless each has some, so that the
-- mesh meets the slab of every rank.
local function quarters(m, w)
  local z = {}
  for b in m:balls() do z[#z + 1] = b.pos[3] end
  table.sort(z)
  local cut = {z[#z // 4], z[#z // 2], z[3 * #z // 4]}
  local count = {0, 0, 0, 0}
  for c in m:contacts{wall = w} do
    local q = 1
    while q <= 3 and c.a.pos[3] > cut[q] do q = q + 1 end
    count[q] = count[q] + 1
  end
  for q = 1, 4 do
    if count[q] == 0 then error(string.format("no contact of the mesh in quarter %d of the balls", q)) end
  end
  return table.concat(count, " ")
end

-- The quad a b c d (corners in order) cut into n x n quads of two triangles each.
local function quad(t, a, b, c, d, n)
  local function at(u, v)
    local p = {}
    for k = 1, 3 do
      p[k] = (1 - u) * (1 - v) * a[k] + u * (1 - v) * b[k] + u * v * c[k] + (1 - u) * v * d[k]
    end
    return p
  end
  for i = 0, n - 1 do
    for j = 0, n - 1 do
      local p, q, r, s = at(i / n, j / n), at((i + 1) / n, j / n), at((i + 1) / n, (j + 1) / n), at(i / n, (j + 1) / n)
      t[#t + 1] = {p, q, r}
      t[#t + 1] = {p, r, s}
    end
  end
end

if scene == "plough" then
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("sand", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.4, damping = 0.7, viscous_normal = 0.3})
  local L, W = 0.12, 0.08
  local floor = m:wall{kind = "mesh", file = dir .. "../data/square.stl", kn = 1e5, ks = 1e5}
  for _, p in ipairs{{{0, 0, 0}, {1, 0, 0}}, {{L, 0, 0}, {-1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}}, {{0, W, 0}, {0, -1, 0}}} do
    m:wall{kind = "plane", point = p[1], normal = p[2], kn = 1e5, ks = 1e5}
  end
  -- the wedge: its tip along +x, its faces cut into 4 x 4 quads, from below
  -- the floor to above the bed, turning about its vertical axis through
  -- point; still while the bed settles in front of it
  local x0, y0, half, len, z0, z1 = 0.01, W / 2, 0.012, 0.03, -0.01, 0.09
  local tip, left, right = {x0 + len, y0}, {x0, y0 + half}, {x0, y0 - half}
  local t = {}
  local function side(p, q) quad(t, {p[1], p[2], z0}, {q[1], q[2], z0}, {q[1], q[2], z1}, {p[1], p[2], z1}, 4) end
  side(right, tip)
  side(tip, left)
  side(left, right)
  m:generate{radius = 3.5e-3, packing = "fcc", region = {box = {{x0 + len + 0.002, 0, 0}, {L, W, 0.035}}},
             material = "sand"}
  local plough = m:wall{kind = "mesh", triangles = t, point = {x0 + len / 3, y0, 0}, kn = 1e5, ks = 1e5}
  m:cycle(500)
  plough.vel = {1.5, 0, 0}
  plough.spin = {0, 0, 2}
  print(string.format("%d balls, plough of %d facets", m:ball_count(), plough.facet_count))
  local walls = {{name = "plough", wall = plough}, {name = "floor", wall = floor}}
  for k = 1, 4 do
    m:cycle(750)
    report(m, "at " .. k, walls)
  end
  print("plough contacts by quarter of height " .. quarters(m, plough))
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
elseif scene == "drum" then
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  if arg[2] == "hertz" then
    m:material("grain", {model = "hertz", density = 2650, shear_modulus = 5e7, poisson = 0.25, friction = 0.4,
                         rolling_friction = 0.05, damping = 0.3, viscous_normal = 0.3, mindlin_unloading = 1})
  else
    m:material("grain", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.4, rolling_friction = 0.05, damping = 0.3,
                         viscous_normal = 0.3})
  end
  local S = 0.12
  local t = {}
  local o, x, y, z = {0, 0, 0}, {S, 0, 0}, {0, S, 0}, {0, 0, S}
  local function add(a, b, c)
    local p = {}
    for k = 1, 3 do p[k] = a[k] + b[k] + c[k] end
    return p
  end
  quad(t, o, add(o, z, o), add(y, z, o), y, 3) -- -x
  quad(t, x, add(x, y, o), add(x, y, z), add(x, z, o), 3) -- +x
  quad(t, o, x, add(x, z, o), z, 3) -- -y
  quad(t, y, add(y, z, o), add(x, y, z), add(x, y, o), 3) -- +y
  quad(t, o, y, add(x, y, o), x, 3) -- -z
  quad(t, z, add(x, z, o), add(x, y, z), add(y, z, o), 3) -- +z
  local drum = m:wall{kind = "mesh", triangles = t, point = {S / 2, S / 2, S / 2}, spin = {15, 0, 0},
                      vel = {0.01, 0, 0}, kn = 1e5, ks = 1e5}
  m:generate{count = 700, radius = 3.5e-3, packing = "fcc",
             region = {box = {{0.002, 0.002, 0.002}, {S - 0.002, S - 0.002, 0.04}}},
             material = "grain"}
  print(string.format("%d balls in a drum of %d facets", m:ball_count(), drum.facet_count))
  local walls = {{name = "drum", wall = drum}}
  for k = 1, 4 do
    m:cycle(1000)
    report(m, "at " .. k, walls)
  end
  print("drum contacts by quarter of height " .. quarters(m, drum))
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
else
  error("mpi_walls.lua: scene 'plough' or 'drum' expected, got " .. tostring(scene))
end
