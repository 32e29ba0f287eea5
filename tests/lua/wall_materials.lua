-- Wall materials (issue 12, item 5): a wall of its own material or rigid,
-- the literature's rigid-plane Hertz contact, the literature's mixing of
-- two Hertz materials beside the seed's means (4-27), each against its
-- closed form; a mesh of a material as a plane of it, to the bit; files,
-- hash and errors.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

local function G(E, nu) return E / (2 * (1 + nu)) end

-- The one contact of the model (a table of its fields), or nil.
local function contact(m)
  for c in m:contacts() do return c end
end

-- The integral of (1 - x^(5/2))^(-1/2) over [0, 1] (x = 1 - u^2 takes the
-- end's singularity away), by Simpson's rule: the Hertz impact lasts
-- 2 I dmax / v (I = 1.4716...).
local function hertz_integral()
  local n, s = 20000, 0
  local function f(u)
    if u == 0 then return 2 / math.sqrt(2.5) end
    return 2 * u / math.sqrt(1 - (1 - u * u) ^ 2.5)
  end
  for k = 0, n do
    local w = (k == 0 or k == n) and 1 or (k % 2 == 1 and 4 or 2)
    s = s + w * f(k / n)
  end
  return s / (3 * n)
end

-- A Hertz ball (radius r, density rho, E, nu) dropped at v onto a plane
-- wall given by `wall` (extra keys of m:wall); no gravity, no damping.
-- Returns the largest overlap, the contact's duration and the rebound speed.
local function drop(r, rho, E, nu, v, wall, dt, e)
  local m = seixo.model{dim = 3, timestep = dt}
  m:material("ball", {model = "hertz", density = rho, shear_modulus = G(E, nu), poisson = nu, friction = 0,
                      restitution = e or 0})
  local w = {kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  for k, x in pairs(wall(m)) do w[k] = x end
  m:wall(w)
  local b = m:ball{pos = {0, 0, r + 1e-7}, radius = r, vel = {0, 0, -v}, material = "ball"}
  local steps, dmax, touched = 0, 0, false
  for _ = 1, 1000000 do
    m:cycle(1)
    local c = contact(m)
    if c and c.overlap > 0 then
      touched = true
      steps = steps + 1
      dmax = math.max(dmax, c.overlap)
    elseif touched then
      break
    end
  end
  return dmax, steps * dt, b.vel[3]
end

T.test("a Hertz ball on a rigid plane: the literature's impact (Chung & Ooi test 2) within 1 %", function()
  local I = hertz_integral()
  T.near(I, 1.4716, 1e-4)
  -- test 2: aluminium alloy and magnesium alloy spheres, R = 0.1 m, 0.2 m/s
  for _, mat in ipairs{{"aluminium alloy", 7.0e10, 0.30, 2699}, {"magnesium alloy", 4.0e10, 0.35, 1800}} do
    local name, E, nu, rho = mat[1], mat[2], mat[3], mat[4]
    local r, v = 0.1, 0.2
    local mass = rho * 4 / 3 * math.pi * r ^ 3
    local K = 4 / 3 * E / (1 - nu * nu) * math.sqrt(r) -- Fn = K d^(3/2), E* = E/(1 - nu^2), R* = R
    local dm = (5 * mass * v * v / (4 * K)) ^ 0.4
    local tc = 2 * I * dm / v
    local dt = tc / 4000
    local got_d, got_t, vout = drop(r, rho, E, nu, v, function() return {rigid = true} end, dt)
    print(string.format("rigid plane, %s: max overlap %.6e m (closed form %.6e, relative error %+.1e), duration "
                        .. "%.6e s (%.6e, %+.1e), e = %.8f", name, got_d, dm, got_d / dm - 1, got_t, tc,
                        got_t / tc - 1, vout / v))
    T.near(got_d, dm, 0.01)
    T.near(got_t, tc, 0.01)
    T.near(vout, v, 1e-3) -- elastic
    -- the seed's wall (4-28, a wall with no material) is a softer contact: E* = G/(1 - nu), R* = R/2
    local Ks = 4 / 3 * G(E, nu) / (1 - nu) * math.sqrt(r / 2)
    local seed_d = drop(r, rho, E, nu, v, function() return {} end, dt)
    T.near(seed_d, (5 * mass * v * v / (4 * Ks)) ^ 0.4, 0.01)
    -- Chung & Ooi test 3 on the rigid plane: the damping derived from e gives e (laws/restitution.h)
    for _, e in ipairs{0.1, 0.5, 0.9} do
      local _, _, out = drop(r, rho, E, nu, v, function() return {rigid = true} end, dt, e)
      print(string.format("rigid plane, %s, restitution %.1f: measured %.5f", name, e, out / v))
      T.near(out / v, e, 0.01 / e)
    end
  end
end)

-- Two balls of materials a, b (tables of m:material keys), overlapping by
-- d, at rest: the contact after one step.
local function pair(a, b, ra, rb, d, mixing)
  local m = seixo.model{dim = 3, timestep = 1e-9}
  a.model, b.model, a.hertz_mixing, b.hertz_mixing = "hertz", "hertz", mixing, mixing
  m:material("a", a)
  m:material("b", b)
  m:ball{pos = {0, 0, 0}, radius = ra, material = "a"}
  m:ball{pos = {ra + rb - d, 0, 0}, radius = rb, material = "b"}
  m:cycle(1)
  return contact(m)
end

local steel = {E = 210e9, nu = 0.30}
local glass = {E = 70e9, nu = 0.22}
local function def(x) return {shear_modulus = G(x.E, x.nu), poisson = x.nu, density = 7800} end

T.test("two Hertz materials mix as the literature (hertz_mixing = 1) or by the seed's means (4-27)", function()
  local ra, rb, d = 0.002, 0.003, 1e-6
  local rs = ra * rb / (ra + rb)
  local es = 1 / ((1 - steel.nu ^ 2) / steel.E + (1 - glass.nu ^ 2) / glass.E)
  local gs = 1 / ((2 - steel.nu) / G(steel.E, steel.nu) + (2 - glass.nu) / G(glass.E, glass.nu))
  local c = pair(def(steel), def(glass), ra, rb, d, 1)
  local un = c.overlap
  T.near(un, d, 1e-6)
  T.near(c.fn, 4 / 3 * es * math.sqrt(rs) * un ^ 1.5, 1e-12)
  T.near(c.ks, 8 * gs * math.sqrt(rs * un), 1e-12)
  print(string.format("literature mixing: Fn %.9e N (4/3 E* sqrt(R*) d^1.5 = %.9e), ks %.9e N/m (8 G* a = %.9e)", c.fn,
                      4 / 3 * es * math.sqrt(rs) * un ^ 1.5, c.ks, 8 * gs * math.sqrt(rs * un)))
  -- the seed's means (4-25, 4-27), the default
  local c0 = pair(def(steel), def(glass), ra, rb, d, 0)
  local gm, num = 0.5 * (G(steel.E, steel.nu) + G(glass.E, glass.nu)), 0.5 * (steel.nu + glass.nu)
  local rbar = 2 * ra * rb / (ra + rb)
  T.near(c0.fn, 2 * gm * math.sqrt(2 * rbar) / (3 * (1 - num)) * c0.overlap ^ 1.5, 1e-12)
  T.check(math.abs(c0.fn / c.fn - 1) > 0.01, "the two rules should differ for steel on glass")
  -- one material: both rules are the same law, to the bit
  local c1, c2 = pair(def(steel), def(steel), ra, rb, d, 1), pair(def(steel), def(steel), ra, rb, d, 0)
  T.eq(c1.fn, c2.fn)
  T.eq(c1.ks, c2.ks)
  T.near(c1.fn, 4 / 3 * steel.E / (2 * (1 - steel.nu ^ 2)) * math.sqrt(rs) * c1.overlap ^ 1.5, 1e-12)
end)

T.test("a steel ball meets a glass ball head on: Hertz's impact at the literature's E*, R*, m* within 1 %", function()
  local I = hertz_integral()
  local ra, rb, v = 0.002, 0.003, 0.5 -- closing speed
  local rhoa, rhob = 7800, 2500
  local m = seixo.model{dim = 3, timestep = 1e-9}
  local a, b = def(steel), def(glass)
  a.model, b.model, a.hertz_mixing, b.hertz_mixing, a.density, b.density = "hertz", "hertz", 1, 1, rhoa, rhob
  m:material("steel", a)
  m:material("glass", b)
  local ba = m:ball{pos = {0, 0, 0}, radius = ra, material = "steel", vel = {0.5 * v, 0, 0}}
  local bb = m:ball{pos = {ra + rb + 1e-9, 0, 0}, radius = rb, material = "glass", vel = {-0.5 * v, 0, 0}}
  local ma, mb = rhoa * 4 / 3 * math.pi * ra ^ 3, rhob * 4 / 3 * math.pi * rb ^ 3
  local mstar, rstar = ma * mb / (ma + mb), ra * rb / (ra + rb)
  local es = 1 / ((1 - steel.nu ^ 2) / steel.E + (1 - glass.nu ^ 2) / glass.E)
  local K = 4 / 3 * es * math.sqrt(rstar)
  local dm = (5 * mstar * v * v / (4 * K)) ^ 0.4
  local tc = 2 * I * dm / v
  local dt = tc / 4000
  m:set_timestep(dt)
  local steps, dmax, touched = 0, 0, false
  for _ = 1, 100000 do
    m:cycle(1)
    local c = contact(m)
    if c and c.overlap > 0 then
      touched, steps, dmax = true, steps + 1, math.max(dmax, c.overlap)
    elseif touched then
      break
    end
  end
  print(string.format("steel on glass: max overlap %.6e m (closed form %.6e, %+.1e), duration %.6e s (%.6e, %+.1e)",
                      dmax, dm, dmax / dm - 1, steps * dt, tc, steps * dt / tc - 1))
  T.near(dmax, dm, 0.01)
  T.near(steps * dt, tc, 0.01)
  T.near(bb.vel[1] - ba.vel[1], v, 1e-6) -- elastic: the closing speed comes back
end)

-- A ball of material `ball` resting against a plane with wall keys `w`,
-- overlapping it by d: the contact after one step.
local function on_wall(ball, w, d, walldef)
  local m = seixo.model{dim = 3, timestep = 1e-9}
  m:material("ball", ball)
  if walldef then m:material("wallmat", walldef) end
  local keys = {kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  for k, x in pairs(w) do keys[k] = x end
  m:wall(keys)
  m:ball{pos = {0, 0, 0.002 - d}, radius = 0.002, material = "ball"}
  m:cycle(1)
  return contact(m), m
end

T.test("a ball against a wall of a material: the literature's deformable plane, the seed's means, linear springs", function()
  local r, d = 0.002, 1e-6
  local b, w = def(glass), def(steel)
  b.model, w.model, b.hertz_mixing, w.hertz_mixing = "hertz", "hertz", 1, 1
  local c = on_wall(b, {material = "wallmat"}, d, w)
  local es = 1 / ((1 - steel.nu ^ 2) / steel.E + (1 - glass.nu ^ 2) / glass.E)
  local gs = 1 / ((2 - steel.nu) / G(steel.E, steel.nu) + (2 - glass.nu) / G(glass.E, glass.nu))
  T.near(c.fn, 4 / 3 * es * math.sqrt(r) * c.overlap ^ 1.5, 1e-12)
  T.near(c.ks, 8 * gs * math.sqrt(r * c.overlap), 1e-12)
  -- a rigid plane: E* = E/(1 - nu^2), G* = G/(2 - nu)
  local cr = on_wall(b, {rigid = true}, d)
  T.near(cr.fn, 4 / 3 * glass.E / (1 - glass.nu ^ 2) * math.sqrt(r) * cr.overlap ^ 1.5, 1e-12)
  T.near(cr.ks, 8 * G(glass.E, glass.nu) / (2 - glass.nu) * math.sqrt(r * cr.overlap), 1e-12)
  -- the seed's rule for a wall of a material: the means of G and nu (4-27) with R-bar = R (4-28)
  b.hertz_mixing, w.hertz_mixing = 0, 0
  local cs = on_wall(b, {material = "wallmat"}, d, w)
  local gm, num = 0.5 * (G(steel.E, steel.nu) + G(glass.E, glass.nu)), 0.5 * (steel.nu + glass.nu)
  T.near(cs.fn, 2 * gm * math.sqrt(2 * r) / (3 * (1 - num)) * cs.overlap ^ 1.5, 1e-12)
  -- linear: a wall's material puts its springs in series (4-22/4-23) and its friction in (4-30); rigid: the ball's
  local cl = on_wall({kn = 3e6, ks = 2e6, friction = 0.7}, {material = "wallmat"}, d, {kn = 6e6, ks = 1e6, friction = 0.3})
  T.near(cl.kn, 2e6, 1e-15)
  T.near(cl.ks, 2e6 / 3, 1e-15)
  local cg = on_wall({kn = 3e6, ks = 2e6}, {rigid = true, friction = 0.3}, d)
  T.eq(cg.kn, 3e6)
  T.eq(cg.ks, 2e6)
  -- the BPM modulus mode against a rigid wall: the ball's per-radius spring alone (4-49)
  local cm = on_wall({modulus = 1e9, stiffness_ratio = 2}, {rigid = true}, d)
  T.near(cm.kn, 4 * r * 1e9, 1e-15)
  T.near(cm.ks, 2 * r * 1e9, 1e-15)
end)

-- A Hertz ball thrown onto a floor with a tangential velocity and a spin:
-- it bounces, slides, then rolls. The floor is a plane or the same plane as
-- a mesh of two triangles, both of material "floor".
local function roll(mesh, rigid)
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}, timestep = 2e-7}
  m:material("ball", {model = "hertz", density = 2500, shear_modulus = G(glass.E, glass.nu), poisson = glass.nu,
                      friction = 0.3, restitution = 0.8, hertz_mixing = 1})
  m:material("floor", {model = "hertz", density = 7800, shear_modulus = G(steel.E, steel.nu), poisson = steel.nu,
                       friction = 0.4, restitution = 0.6, hertz_mixing = 1})
  local keys = rigid and {rigid = true, friction = 0.4} or {material = "floor"}
  if mesh then
    keys.kind = "mesh"
    keys.triangles = {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}}, {{-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}}
  else
    keys.kind, keys.point, keys.normal = "plane", {0, 0, 0}, {0, 0, 1}
  end
  m:wall(keys)
  local b = m:ball{pos = {-0.05, 0.02, 0.0021}, radius = 0.002, vel = {0.3, 0.1, -0.2}, material = "ball"}
  b.spin = {5, -20, 3}
  m:cycle(20000)
  return b, m
end

T.test("a mesh of a material behaves as a plane of it, to the bit (a bounce, slide and roll)", function()
  for _, rigid in ipairs{false, true} do
    local bp, mp = roll(false, rigid)
    local bm = roll(true, rigid)
    T.vec_eq(bm.pos, bp.pos)
    T.vec_eq(bm.vel, bp.vel)
    T.vec_eq(bm.spin, bp.spin)
    T.check(bp.pos[1] > -0.05 + 1e-4, "the ball should have moved")
    -- and it differs from the plain wall of today (the material is used)
    if not rigid then T.check(mp:hash() ~= select(2, roll(false, true)):hash(), "material and rigid floors differ") end
  end
end)

T.test("2D: a line of a material or rigid, as in 3D; saved and restored", function()
  local m = seixo.model{dim = 2, timestep = 1e-7}
  m:material("ball", {kn = 3e6, ks = 2e6, friction = 0.7})
  m:material("wallmat", {kn = 6e6, ks = 1e6, friction = 0.3})
  m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, material = "wallmat"}
  m:wall{kind = "segment", p1 = {-1, 0.1}, p2 = {1, 0.1}, rigid = true}
  m:ball{pos = {0, 0.002 - 1e-6}, radius = 0.002, material = "ball"}
  m:ball{pos = {0.5, 0.1 - 0.002 + 1e-6}, radius = 0.002, material = "ball"}
  m:cycle(1)
  local kn = {}
  for c in m:contacts() do kn[#kn + 1] = c.kn end
  table.sort(kn)
  T.near(kn[1], 2e6, 1e-15) -- in series
  T.eq(kn[2], 3e6) -- rigid: the ball's
  local path = os.tmpname()
  m:save(path)
  local l = seixo.load(path)
  os.remove(path)
  T.eq(l:hash(), m:hash())
  m:cycle(100)
  l:cycle(100)
  T.eq(l:hash(), m:hash())
end)

T.test("wall materials: Lua fields, files, hash, errors", function()
  local m = seixo.model{dim = 3}
  m:material("b", {model = "hertz"})
  m:material("w", {model = "hertz", shear_modulus = 80e9, poisson = 0.3, hertz_mixing = 1})
  local p = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, material = "w"}
  local q = m:wall{kind = "plane", point = {0, 0, 1}, normal = {0, 0, -1}, rigid = true, friction = 0.2}
  local s = m:wall{kind = "plane", point = {0, 0, 0}, normal = {1, 0, 0}}
  T.eq(p.material, "w")
  T.eq(p.rigid, false)
  T.eq(q.rigid, true)
  T.eq(q.material, nil)
  T.eq(s.material, nil)
  T.eq(s.rigid, false)
  T.eq(m:materials().w.hertz_mixing, 1)
  -- the springs and friction the contacts use: the material's, a rigid wall's infinite stiffness
  m:material("lw", {kn = 3e7, ks = 2e7, friction = 0.25})
  local lw = m:wall{kind = "plane", point = {0, 0, -5}, normal = {0, 0, 1}, material = "lw"}
  T.eq(lw.kn, 3e7)
  T.eq(lw.ks, 2e7)
  T.eq(lw.friction, 0.25)
  T.eq(q.kn, math.huge)
  T.eq(q.ks, math.huge)
  T.eq(q.friction, 0.2)
  lw:remove()
  m:ball{pos = {0.5, 0, 0.5}, radius = 0.1, material = "b", vel = {0, 0, -1}}
  m:cycle(10)
  s.rigid = true -- (a wall's change makes the automatic timestep due again, which the hash covers)
  s.rigid = false
  local h = m:hash()
  -- the hash covers a wall's material and rigidity
  s.rigid = true
  T.check(m:hash() ~= h, "rigid is hashed")
  s.rigid = false
  T.eq(m:hash(), h)
  s.material = "w"
  T.check(m:hash() ~= h, "a wall's material is hashed")
  s.material = nil
  T.eq(m:hash(), h)
  -- save and load: the same state, and it continues to the same bits
  local path = os.tmpname()
  m:save(path)
  local l = seixo.load(path)
  os.remove(path)
  T.eq(l:hash(), h)
  local lw = {}
  for w in l:walls() do lw[#lw + 1] = w end
  T.eq(lw[1].material, "w")
  T.eq(lw[2].rigid, true)
  T.eq(lw[2].friction, 0.2)
  m:cycle(200)
  l:cycle(200)
  T.eq(l:hash(), m:hash())
  -- errors
  T.raises(function() m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, material = "steel"} end,
           "'material'", "not a material of the model")
  T.raises(function() m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, material = "w", rigid = true} end,
           "either rigid or of a material")
  T.raises(function() m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, material = "w", kn = 1e6} end,
           "takes kn, ks and friction from it")
  T.raises(function() m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, rigid = true, ks = 1e6} end,
           "rigid wall has no kn or ks")
  T.raises(function() m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, rigid = 1} end,
           "'rigid': true or false")
  T.raises(function() p.kn = 1e7 end, "of a material")
  T.raises(function() p.friction = 0.1 end, "its material's ('w')")
  T.raises(function() q.ks = 1e7 end, "is rigid")
  q.material = "w" -- a rigid wall given a material is of that material
  T.eq(q.rigid, false)
  T.raises(function() q.rigid = true end, "either rigid or of a material")
  q.material = nil
  q.rigid = true
  T.raises(function() p.material = "nothing" end, "not a material of the model")
  T.raises(function() m:material("x", {hertz_mixing = 0.5}) end, "hertz_mixing must be 0")
  -- a wall's material of another law than the balls'
  m:material("lin", {model = "linear"})
  p.material = "lin"
  T.raises(function() m:cycle(1) end, "wall 1 is of material 'lin' (linear)", "use one model for both")
  p.material = "w"
  m:cycle(1)
  -- a BPM-modulus material has no stiffness without a radius
  m:material("bpm", {model = "hertz", modulus = 1e9})
  T.raises(function() p.material = "bpm" end, "BPM modulus")
end)

T.done()
