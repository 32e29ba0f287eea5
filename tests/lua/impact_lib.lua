-- Oblique impacts of a Hertz sphere on a rigid plane (Chung & Ooi 2011,
-- tests 4-6), and their references: the rigid-body (gross-sliding) closed
-- form and the no-slip limit of each tangential form, integrated.
--   local impact = dofile(".../tests/lua/impact_lib.lua")
--   local r = impact.run{vn = 3.9 * math.cos(a), vt = 3.9 * math.sin(a), total_shear = 0}
-- Used by tests/lua/chung_ooi.lua and docs/data/chung_ooi.lua.
local M = {}

-- Chung & Ooi's test 4 sphere: aluminium oxide, R = 2.5 mm, E = 380 GPa,
-- nu = 0.23, 4000 kg/m^3, friction 0.092 (Kharaz, Gorham & Salman 2001).
M.sphere = {radius = 0.0025, E = 3.8e11, nu = 0.23, density = 4000, friction = 0.092}

local function shear_modulus(s) return s.E / (2 * (1 + s.nu)) end

-- The contact's constants on a rigid plane: K (Fn = K d^1.5), the shear
-- stiffness factor (ks = S sqrt(d)), the mass, and 1 + m R^2 / I (7/2 for
-- a solid sphere; s.lever another body's, as Maw et al.'s slice).
function M.constants(s)
  s = s or M.sphere
  local m = s.density * 4 / 3 * math.pi * s.radius ^ 3
  return {K = 4 / 3 * s.E / (1 - s.nu ^ 2) * math.sqrt(s.radius),
          S = 8 * shear_modulus(s) / (2 - s.nu) * math.sqrt(s.radius), mass = m,
          lever = s.lever or 1 + m * s.radius ^ 2 / (0.4 * m * s.radius ^ 2)}
end

-- Runs one impact in seixo: normal approach speed vn, tangential velocity
-- vt (along x), spin wy (about y, rad/s), a rigid plane z = 0, Hertz,
-- elastic, no gravity; o.total_shear (0, 1), o.mindlin_unloading (0, 1),
-- o.friction, o.steps_per_contact.
-- Returns the rebound: vx, vz, wy, and the contact point's tangential
-- velocity before (vt - R wy) and after.
function M.run(o)
  local s = o.sphere or M.sphere
  local c = M.constants(s)
  local dm = (5 * c.mass * o.vn ^ 2 / (4 * c.K)) ^ 0.4
  local tc = 2.9432 * dm / o.vn
  local dt = tc / (o.steps_per_contact or 2000)
  local m = seixo.model{dim = 3, timestep = dt}
  m:material("ball", {model = "hertz", density = s.density, shear_modulus = shear_modulus(s), poisson = s.nu,
                      friction = o.friction or s.friction, total_shear = o.total_shear or 0,
                      mindlin_unloading = o.mindlin_unloading or 0})
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, rigid = true, friction = 1e9}
  local r = s.radius
  local b = m:ball{pos = {0, 0, r + 0.5 * o.vn * dt}, radius = r, vel = {o.vt, 0, -o.vn}, material = "ball"}
  b.spin = {0, o.wy or 0, 0}
  local touched = false
  for _ = 1, 100 * (o.steps_per_contact or 2000) do
    m:cycle(1)
    if m:contact_count() > 0 then touched = true elseif touched then break end
  end
  assert(touched, "impact: no contact")
  local v, w = b.vel, b.spin
  return {vx = v[1], vz = v[3], wy = w[2], vt_before = o.vt - r * (o.wy or 0), vt_after = v[1] - r * w[2]}
end

-- Test 8's impact of two spheres of the sphere's material, radii ra (A,
-- above) and rb (B, at rest below), head on along z at vn, A spinning at
-- wy about y; their contact point slips at s = -ra wy. Returns the
-- rebound: A's and B's vx and wy, and the slip before and after.
function M.run_pair(o)
  local s = o.sphere or M.sphere
  local c = M.constants(s)
  local ma, mb = s.density * 4 / 3 * math.pi * o.ra ^ 3, s.density * 4 / 3 * math.pi * o.rb ^ 3
  local mstar, rstar = ma * mb / (ma + mb), o.ra * o.rb / (o.ra + o.rb)
  local K = 4 / 3 * s.E / (2 * (1 - s.nu ^ 2)) * math.sqrt(rstar) -- one material: E* = E / (2 (1 - nu^2))
  local tc = 2.9432 * (5 * mstar * o.vn ^ 2 / (4 * K)) ^ 0.4 / o.vn
  local dt = tc / (o.steps_per_contact or 2000)
  local m = seixo.model{dim = 3, timestep = dt}
  m:material("ball", {model = "hertz", density = s.density, shear_modulus = shear_modulus(s), poisson = s.nu,
                      friction = o.friction or s.friction, total_shear = o.total_shear or 0})
  local b = m:ball{pos = {0, 0, 0}, radius = o.rb, material = "ball"}
  local a = m:ball{pos = {0, 0, o.ra + o.rb + 0.5 * o.vn * dt}, radius = o.ra, vel = {0, 0, -o.vn}, material = "ball"}
  a.spin = {0, o.wy, 0}
  local touched = false
  for _ = 1, 100 * (o.steps_per_contact or 2000) do
    m:cycle(1)
    if m:contact_count() > 0 then touched = true elseif touched then break end
  end
  assert(touched, "impact: no contact")
  local function slip() return a.vel[1] - o.ra * a.spin[2] - b.vel[1] - o.rb * b.spin[2] end
  return {vxa = a.vel[1], vxb = b.vel[1], wya = a.spin[2], wyb = b.spin[2], vza = a.vel[3], vzb = b.vel[3],
          slip_before = -o.ra * o.wy, slip_after = slip(), c = c, mstar = mstar}
end

-- The rigid-body closed form of test 8 while the pair slides throughout
-- (slip > 7 mu vn): the normal impulse 2 m* vn, the tangential one mu times
-- it, against the slip on A and with it on B.
function M.rigid_pair(o)
  local s = o.sphere or M.sphere
  local mu = o.friction or s.friction
  local ma, mb = s.density * 4 / 3 * math.pi * o.ra ^ 3, s.density * 4 / 3 * math.pi * o.rb ^ 3
  local J = mu * 2 * ma * mb / (ma + mb) * o.vn
  return {vxa = -J / ma, vxb = J / mb, wya = o.wy + o.ra * J / (0.4 * ma * o.ra ^ 2), wyb = o.rb * J / (0.4 * mb * o.rb ^ 2),
          slip_after = -o.ra * o.wy - 7 * mu * o.vn, limit = 7 * mu * o.vn}
end

-- The rigid-body closed form (Coulomb, e = 1). While the contact point's
-- slip s = vt - R wy exceeds 7 mu vn it slides throughout: the tangential
-- impulse is mu (1 + e) m vn, so the centre loses 2 mu vn, the spin gains
-- 5 mu vn / R (solid sphere) and the contact point loses 2 mu vn (1 + m R^2/I)
-- = 7 mu vn. Below that it sticks and the contact ends rolling: the centre
-- loses s/(1 + m R^2/I) = 2 s/7 and the contact point's velocity is 0.
function M.rigid_body(o)
  local s = o.sphere or M.sphere
  local mu = o.friction or s.friction
  local wy, slip = o.wy or 0, o.vt - s.radius * (o.wy or 0)
  local limit = 7 * mu * o.vn
  local dv = slip > limit and 2 * mu * o.vn or slip / 3.5
  return {vx = o.vt - dv, vz = o.vn, wy = wy + 2.5 * dv / s.radius, vt_after = slip - 3.5 * dv, limit = limit}
end

-- The no-slip limit (friction without bound) of one tangential form, as
-- an ODE in time, integrated with RK4 (n steps over the contact): the
-- normal motion m d'' = -K d^1.5; the contact point's tangential velocity
-- u' changes by -T (1 + m R^2/I) / m under the shear force T with ks = S sqrt(d):
--   "incremental" (the seed's 4-20):   T' = ks u',
--   "total" (Mindlin's total form):    T = ks x, x' = u',
--   "md" (Mindlin-Deresiewicz as Thornton and co-workers apply it: on loading
--     T' = ks u'; on unloading the force also shrinks with the contact
--     radius a ~ sqrt(d):  T' = ks u' + T a'/a, a'/a = d'/(2 d)).
-- Returns u_after / u_before (the same for every speed: the problem is linear in u).
function M.no_slip(form, sphere, n)
  local c = M.constants(sphere)
  local vn = 1
  local dm = (5 * c.mass * vn ^ 2 / (4 * c.K)) ^ 0.4
  local h = 2.9432 * dm / vn / (n or 200000)
  local k = c.lever / c.mass
  -- state: d, d', u', q (T for incremental and md, x for total)
  local function rate(d, dd, u, q)
    local dp = math.max(d, 0)
    local ks = c.S * math.sqrt(dp)
    local acc = -c.K * dp ^ 1.5 / c.mass
    local T = form == "total" and ks * q or q
    local qdot
    if form == "total" then qdot = u
    elseif form == "incremental" or dd >= 0 or dp == 0 then qdot = ks * u
    else qdot = ks * u + q * dd / (2 * dp) end
    return dd, acc, -k * T, qdot
  end
  local d, dd, u, q = 0, vn, 1, 0
  for _ = 1, 10 * (n or 200000) do
    local a1, b1, c1, d1 = rate(d, dd, u, q)
    local a2, b2, c2, d2 = rate(d + 0.5 * h * a1, dd + 0.5 * h * b1, u + 0.5 * h * c1, q + 0.5 * h * d1)
    local a3, b3, c3, d3 = rate(d + 0.5 * h * a2, dd + 0.5 * h * b2, u + 0.5 * h * c2, q + 0.5 * h * d2)
    local a4, b4, c4, d4 = rate(d + h * a3, dd + h * b3, u + h * c3, q + h * d3)
    local dn = d + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    local un = u + h / 6 * (c1 + 2 * c2 + 2 * c3 + c4)
    if dn <= 0 and dd < 0 then -- the contact ends between the steps: interpolate u
      return u + (un - u) * (d / (d - dn))
    end
    d, dd, u, q = dn, dd + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4), un, q + h / 6 * (d1 + 2 * d2 + 2 * d3 + d4)
  end
  error("impact.no_slip: the contact did not end")
end

return M
