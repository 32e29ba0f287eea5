-- Chung & Ooi (2011) tests 4-6: oblique impacts of a Hertz sphere
-- (aluminium oxide, R = 2.5 mm, mu = 0.092) on a rigid plane, and test 8
-- (two spheres of different sizes, one spinning), with the
-- seed's incremental shear force (4-20) and Mindlin's total form
-- (total_shear = 1), against the rigid-body closed form in gross sliding
-- and against each form's no-slip limit integrated as an ODE
-- (tests/lua/impact_lib.lua; docs/lua-api.md, "Oblique impacts").
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local T = dofile(here .. "harness.lua")
local I = dofile(here .. "impact_lib.lua")
local s = I.sphere

local function incidence(deg, form, extra)
  local a = math.rad(deg)
  local o = {vn = 3.9 * math.cos(a), vt = 3.9 * math.sin(a), total_shear = form}
  for k, x in pairs(extra or {}) do o[k] = x end
  return I.run(o), I.rigid_body(o), o
end

T.test("gross sliding (test 4 from 40 degrees, test 6 at -2000 rad/s): the rigid-body closed form within 1 %", function()
  for form = 0, 1 do
    for _, deg in ipairs{40, 60, 80} do
      local r, c, o = incidence(deg, form)
      T.check(o.vt > c.limit, "gross sliding throughout")
      T.near(r.vz, o.vn, 1e-6) -- elastic
      T.near(r.vx / o.vt, c.vx / o.vt, 1e-6) -- the tangential restitution of the centre
      -- the spin: the shear force acts at the contact point, R - Un/2 from the centre (4-4, 4-21),
      -- which takes Un/(2R) = 0.16 % off the rigid body's spin
      T.near(r.wy, c.wy, 0.005)
      T.near(math.atan(r.vx, r.vz), math.atan(c.vx, c.vz), 0.01) -- the rebound angle
      T.near(math.atan(r.vt_after, r.vz), math.atan(c.vt_after, c.vz), 0.01) -- the contact patch's
    end
    -- test 6: no tangential velocity, a backspin whose contact point slides at R |w| = 5 m/s
    local o = {vn = 5, vt = 0, wy = -2000, total_shear = form}
    local r, c = I.run(o), I.rigid_body(o)
    T.near(r.vx, c.vx, 1e-6)
    T.near(r.vt_after, c.vt_after, 0.01)
  end
  -- on the Coulomb cap throughout, both forms are one law: the same bits
  local a, b = incidence(60, 0), incidence(60, 1)
  T.eq(a.vx, b.vx)
  T.eq(a.wy, b.wy)
end)

T.test("the sticking regime: the contact point's tangential velocity reverses (test 4 at 15-25 degrees)", function()
  for form = 0, 1 do
    for _, deg in ipairs{15, 20, 25} do
      local r, c = incidence(deg, form)
      T.check(r.vt_before < c.limit, "within the rigid body's sticking range")
      -- the rigid body ends rolling (vt_after = 0); tangential compliance sends the contact point back
      T.check(r.vt_after / r.vt_before < -0.2,
              string.format("form %d, %g degrees: vt after / before = %.4f", form, deg, r.vt_after / r.vt_before))
    end
    -- at a small incidence the tangential spring returns it forwards
    local r = incidence(2, form)
    T.check(r.vt_after / r.vt_before > 0.8, string.format("form %d, 2 degrees: %.4f", form, r.vt_after / r.vt_before))
  end
  -- at 1 degree (psi1 = 0.165) the total form sticks throughout (its no-slip value 1.0135, as with mu = 1000),
  -- the incremental one slips as Fn falls at the end (its force, built at the stiffer compression, exceeds mu Fn)
  local inc1, tot1 = incidence(1, 0), incidence(1, 1)
  local inc1s, tot1s = incidence(1, 0, {friction = 1e3}), incidence(1, 1, {friction = 1e3})
  T.near(tot1.vt_after / tot1.vt_before, tot1s.vt_after / tot1s.vt_before, 1e-4)
  T.check(inc1.vt_after / inc1.vt_before < 0.95 * inc1s.vt_after / inc1s.vt_before, "the incremental form slips at 1 degree")
  -- the two forms differ where the contact partly slips (psi1 = 0.83 at 5 degrees): 0.642 and 0.839
  local a, b = incidence(5, 0), incidence(5, 1)
  T.check(b.vt_after / b.vt_before - a.vt_after / a.vt_before > 0.1, "incremental and total forms at 5 degrees")
end)

T.test("test 8, two spheres (2.5 and 5 mm): the rigid-body closed form in gross sliding, the reversal when sticking", function()
  for form = 0, 1 do
    local o = {ra = 0.0025, rb = 0.005, vn = 5, wy = -3000, total_shear = form}
    local r, c = I.run_pair(o), I.rigid_pair(o)
    T.check(r.slip_before > c.limit, "gross sliding throughout")
    -- the normal turns as the centres pass each other (by about 1e-3 rad over the contact), which the
    -- rigid body ignores: 0.12 % on the centres' tangential velocities
    T.near(r.vxa, c.vxa, 0.01)
    T.near(r.vxb, c.vxb, 0.01)
    T.near(r.wya, c.wya, 0.01)
    T.near(r.wyb, c.wyb, 0.01)
    T.near(r.slip_after, c.slip_after, 0.01)
    local q = I.run_pair{ra = 0.0025, rb = 0.005, vn = 5, wy = -800, total_shear = form}
    T.check(q.slip_after / q.slip_before < -0.2, string.format("form %d: slip after / before %.4f", form,
                                                               q.slip_after / q.slip_before))
  end
end)

T.test("no slip: both forms give their ODE's rebound, the same one (1.0135), to 0.5 %", function()
  local inc, tot, md = I.no_slip("incremental", nil, 100000), I.no_slip("total", nil, 100000), I.no_slip("md", nil, 100000)
  -- y'' = -k ks(t) y with ks(t) symmetric in time: the incremental form follows y(0) = 1, y'(0) = 0 to y(tc),
  -- the total form y(0) = 0, y'(0) = 1 to y'(tc), which are equal (a time-reversible Hill equation)
  T.near(tot, inc, 1e-8)
  T.near(inc, 1.013513, 1e-5)
  T.near(md, 0.588154, 1e-5)
  for form = 0, 1 do
    local r = I.run{vn = 3.9, vt = 0.2, total_shear = form, friction = 1e3}
    local got = r.vt_after / r.vt_before
    print(string.format("no slip, form %d: vt after / before %.6f (ODE %.6f, %+.3f %%)", form, got, inc,
                        100 * (got / inc - 1)))
    T.near(got, inc, 0.005)
  end
  -- with Mindlin & Deresiewicz's unloading (the force shrinking with the
  -- contact radius as the overlap falls) the incremental form is their ODE's
  local r = I.run{vn = 3.9, vt = 0.2, mindlin_unloading = 1, friction = 1e3}
  local got = r.vt_after / r.vt_before
  print(string.format("no slip, Mindlin-Deresiewicz unloading: vt after / before %.6f (ODE %.6f, %+.3f %%)", got, md,
                      100 * (got / md - 1)))
  T.near(got, md, 0.005)
  -- and between two balls (the ball-ball pass), the lower one fixed: the
  -- same dimensionless problem (ks and kn both halved over R* = R/2), the same rebound
  local s = I.sphere
  local dt = 2e-10
  local m = seixo.model{dim = 3, timestep = dt}
  m:material("ball", {model = "hertz", density = s.density, shear_modulus = s.E / (2 * (1 + s.nu)), poisson = s.nu,
                      friction = 1e3, mindlin_unloading = 1})
  m:ball{pos = {0, 0, 0}, radius = s.radius, material = "ball"}.fix = "all"
  local b = m:ball{pos = {0, 0, 2 * s.radius + 1e-9}, radius = s.radius, vel = {0.2, 0, -3.9}, material = "ball"}
  local touched = false
  for _ = 1, 100000 do
    m:cycle(1)
    if m:contact_count() > 0 then touched = true elseif touched then break end
  end
  T.check(touched and m:contact_count() == 0, "the balls did not part")
  got = (b.vel[1] - s.radius * b.spin[2]) / 0.2
  print(string.format("no slip, two balls, Mindlin-Deresiewicz unloading: %.6f (ODE %.6f, %+.3f %%)", got, md,
                      100 * (got / md - 1)))
  T.near(got, md, 0.005)
end)

T.test("Mindlin-Deresiewicz unloading: at small angles no tangential energy is made, and gross sliding is unchanged", function()
  for _, deg in ipairs{1, 3, 5} do
    local a = math.rad(deg)
    local o = {vn = 3.9 * math.cos(a), vt = 3.9 * math.sin(a), mindlin_unloading = 1}
    local r = I.run(o)
    print(string.format("%d deg, Mindlin-Deresiewicz unloading: vx after / before %.4f, psi2 / psi1 %.4f", deg,
                        r.vx / o.vt, r.vt_after / r.vt_before))
    T.check(r.vx / o.vt < 1, deg .. " deg: the centre left faster along the plane than it came")
    T.check(r.vt_after / r.vt_before < 0.9, deg .. " deg: the contact point kept " .. r.vt_after / r.vt_before)
  end
  -- sliding throughout, the force sits on the Coulomb cap: the same rebound
  local a = math.rad(60)
  local o = {vn = 3.9 * math.cos(a), vt = 3.9 * math.sin(a)}
  local plain = I.run(o)
  o.mindlin_unloading = 1
  local md = I.run(o)
  T.near(md.vx, plain.vx, 1e-9)
  T.near(md.wy, plain.wy, 1e-9)
end)

T.test("Mindlin-Deresiewicz unloading: a contact pressed, sheared and withdrawn books the spring's energy as slip", function()
  -- a fixed Hertz ball, a rigid plane pushed 0.1 mm into it, moved 2 um
  -- sideways (no Coulomb slip: friction 1e9), then withdrawn: the work done
  -- on the shear spring comes back as slip as the contact shrinks (the
  -- energy was booked twice, 99 % of the shear work too much; without the
  -- rule the spring's energy grew tenfold as ks fell, then vanished)
  local m = seixo.model{dim = 3, timestep = 1e-7, gravity = {0, 0, 0}}
  m:material("ball", {model = "hertz", density = 2500, shear_modulus = 1e9, poisson = 0.3, friction = 1e9,
                      mindlin_unloading = 1})
  local w = m:wall{kind = "plane", point = {0, 0, -1e-6}, normal = {0, 0, 1}, rigid = true, friction = 1e9}
  m:ball{pos = {0, 0, 0.01}, radius = 0.01, material = "ball"}.fix = "all"
  m:track_energy(true)
  w.vel = {0, 0, 0.01}
  m:cycle(10100)
  local pressed = m:energy().boundary_work
  w.vel = {0.01, 0, 0}
  m:cycle(2000)
  local sheared = m:energy().boundary_work - pressed
  w.vel = {0, 0, -0.01}
  m:cycle(12000)
  T.eq(m:contact_count(), 0)
  local e = m:energy()
  T.check(sheared > 2e-6, "the shear spring took " .. sheared .. " J")
  local balance = e.strain + e.slip + e.kinetic - e.boundary_work
  T.check(math.abs(balance) < 0.02 * sheared, string.format("slip %.5g J for the shear work %.5g J: balance %.3g J",
                                                            e.slip, sheared, balance))
end)

T.done()
